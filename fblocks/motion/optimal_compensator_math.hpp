// The "optimal" dropout compensator that paper 003 (§4, Figs. 7-8) compares
// its Taylor estimator against (Ling & Lemmon 2003, 2004), in the form this
// project computes it; the derivation is docs/motion/dropout-compensators.md.
//
// A lost sample x[k] of a zero-mean wide-sense stationary signal with
// autocorrelation r[0..N] is replaced by
//   x^[k] = a_1 h[k-1] + ... + a_N h[k-N],
// where h is the compensated stream (received samples, and the compensator's
// own estimates where samples were lost: the structure of paper 003 Fig. 3).
// Under i.i.d. (Bernoulli) dropout with rate eps, each history entry is the
// true sample plus, with probability eps, an estimation error of variance
// s2. Modelling those errors as uncorrelated with the signal and with each
// other, the mean-square error of the estimate is
//   J(a) = r0 - 2 a'r + a'(R + lambda I) a,   lambda = eps * s2,
// (R the N x N Toeplitz autocorrelation matrix, r = r[1..N]), minimised by
// the loaded Wiener / Yule-Walker equations
//   (R + lambda I) a = r,   with   s2 = J(a) = r0 - a'r.
// lambda solves lambda = eps * s2(lambda): a fixed point found by monotone
// iteration from 0 (s2 rises with lambda and is at most r0). At eps = 0 this
// is the order-N MMSE (Yule-Walker) one-step predictor; for an AR(1) signal
// (r[j] = rho^j) a = [rho, 0, ...].
//
// Computed once, at load (Eigen); the scan only takes the dot product.
#pragma once

#include <span>
#include <stdexcept>

namespace syncplc::motion {

inline constexpr int kOptimalMaxOrder = 8;

struct OptimalDropoutPredictor {
  int order = 0;
  double a[kOptimalMaxOrder] = {};  // a[j-1] multiplies h[k-j]
  double error_variance = 0;        // s2 at the fixed point (the model's mean-square estimation error)
  double loading = 0;               // lambda = eps * s2
  int iterations = 0;               // fixed-point iterations used
};

// r[0..order] (r[0] > 0; any scale), order 1..kOptimalMaxOrder, dropout rate
// eps in [0, 1). Throws std::invalid_argument, with the reason, when r is not
// an autocorrelation (its (order+1) x (order+1) Toeplitz matrix not positive
// definite), or order/eps is out of range.
OptimalDropoutPredictor optimal_dropout_predictor(std::span<const double> r, int order, double dropout_rate);

// Mean-square estimation error J(a) of the model above, for any coefficients
// (used by tests to check optimality).
double optimal_dropout_cost(std::span<const double> r, std::span<const double> a, double loading);

}  // namespace syncplc::motion
