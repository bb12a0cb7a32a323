// The output power of a networked loop with Bernoulli dropouts and a linear
// dropout compensator, computed exactly (docs/motion/dropout-compensators.md,
// "The loop's output power"). This is the objective of Ling & Lemmon's
// optimal dropout compensator, the one paper 003 §4 (Figs. 3, 7, 8) compares
// the Taylor estimator against.
//
// The loop of paper 003 Fig. 3: a white reference r (variance sigma2) and the
// compensated feedback ybar give e = r - ybar; the controller C(z) makes u;
// the plant P(z) makes y; the controller receives y `delay` frames late. A
// frame is lost with probability eps, independently of everything else; the
// compensator then puts
//   ybar[k] = a_1 ybar[k-1] + ... + a_N ybar[k-N]
// in its place (its own history holds the values it used, received or
// estimated). Zero fill is a = 0, hold a = (1, 0, ...), the recursive
// 3rd-order Taylor estimator of paper 003 eq. (6) a = (4, -6, 4, -1).
//
// With the loop's state z (plant, controller, delay line, history) this is a
// jump-linear system z[k+1] = A_d z[k] + B_d r[k], y[k] = c_d z[k] + g_d r[k],
// d ~ Bernoulli(eps) i.i.d.; its stationary second moment P solves
//   P = (1-eps) (A_0 P A_0' + sigma2 B_0 B_0') + eps (A_1 P A_1' + sigma2 B_1 B_1')
// and the output power is E[y^2] = sum_d p_d (c_d P c_d' + sigma2 g_d^2).
// It exists (the loop is mean-square stable) iff the same equation with the
// identity in place of the input term has a positive definite solution.
#pragma once

#include <Eigen/Dense>
#include <span>
#include <string>
#include <vector>

namespace syncplc::motion {

// A discrete transfer function in powers of z^-1: num[0] + num[1] z^-1 + ...
// over den[0] + den[1] z^-1 + ... (den[0] != 0).
struct TransferFunction {
  std::vector<double> num{1.0};
  std::vector<double> den{1.0};
};

// The state (plant order + controller order + delay + taps) is at most this:
// the second-moment equation has n^2 unknowns and its LU takes n^6 work, so
// 24 states are a 576 x 576 system (2.6 MB, milliseconds).
inline constexpr int kDropoutLoopMaxStates = 24;

struct DropoutLoop {
  TransferFunction plant;
  TransferFunction controller;  // default: unit gain (paper 003 Fig. 3 closes the loop directly)
  int delay = 1;                // frames from the plant output to the controller, >= 1
  double input_variance = 1.0;  // of the white reference r
};

// Empty when the loop can be analysed; otherwise why not (den[0] == 0, a
// non-finite coefficient, delay < 1, a negative or non-finite variance, more
// than kDropoutLoopMaxStates states without the taps).
std::string dropout_loop_error(const DropoutLoop& loop);

struct LoopPower {
  bool ms_stable = false;     // mean-square stable under this eps and these taps
  double output_power = 0;    // E[y^2], stationary; meaningful only when ms_stable
  std::vector<double> gradient;  // dE[y^2]/da_j, j = 1..N (when asked for and ms_stable)
};

// The jump-linear system itself, per mode d (0 received, 1 lost):
// z[k+1] = A[d] z + B[d] r, y = c[d] z + g[d] r. The state is the plant's
// and the controller's (transposed direct form II), the delay line
// y[k-1..k-delay] and the history ybar[k-1..k-N].
struct DropoutLoopSystem {
  Eigen::MatrixXd A[2];
  Eigen::VectorXd B[2];
  Eigen::RowVectorXd c[2];
  double g[2] = {0, 0};
};
DropoutLoopSystem dropout_loop_system(const DropoutLoop& loop, std::span<const double> a);

// The stationary output power of `loop` with the compensator taps a (N = a.size(),
// 0..16) at dropout rate eps in [0, 1]. With `with_gradient`, also its exact
// gradient in a (adjoint of the second-moment equation). Throws
// std::invalid_argument with the reason for a loop dropout_loop_error rejects
// or an eps out of range.
LoopPower dropout_loop_power(const DropoutLoop& loop, std::span<const double> a, double eps, bool with_gradient = false);

}  // namespace syncplc::motion
