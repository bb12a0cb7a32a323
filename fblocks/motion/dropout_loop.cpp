// The loop of dropout_loop.hpp as a jump-linear system, and its stationary
// second moment. Derivation: docs/motion/dropout-compensators.md, "The loop's
// output power".
#include "fblocks/motion/dropout_loop.hpp"

#include <Eigen/Dense>
#include <cmath>
#include <stdexcept>

namespace syncplc::motion {
namespace dropout_loop_impl {

using Eigen::MatrixXd;
using Eigen::RowVectorXd;
using Eigen::VectorXd;

// A transfer function normalised to den[0] = 1 and padded to one length:
// order n, b[0..n], a[0..n] (a[0] = 1).
struct Normalised {
  int order = 0;
  std::vector<double> b, a;
};

Normalised normalise(const TransferFunction& h) {
  Normalised n;
  const std::size_t len = std::max(h.num.size(), h.den.size());
  n.order = static_cast<int>(len) - 1;
  n.b.assign(len, 0.0);
  n.a.assign(len, 0.0);
  for (std::size_t i = 0; i < h.num.size(); ++i) n.b[i] = h.num[i] / h.den[0];
  for (std::size_t i = 0; i < h.den.size(); ++i) n.a[i] = h.den[i] / h.den[0];
  return n;
}

std::string tf_error(const TransferFunction& h, const char* what) {
  if (h.num.empty() || h.den.empty()) return std::string(what) + ": numerator and denominator need a coefficient each";
  if (h.num.size() > 32 || h.den.size() > 32) return std::string(what) + ": at most 32 coefficients";
  for (double v : h.num)
    if (!std::isfinite(v)) return std::string(what) + ": a numerator coefficient is not finite";
  for (double v : h.den)
    if (!std::isfinite(v)) return std::string(what) + ": a denominator coefficient is not finite";
  if (h.den[0] == 0.0) return std::string(what) + ": the denominator's first coefficient (z^0) is 0";
  return {};
}

// Rows are built over [z; r] (last column: r) by running one scan on linear forms.
using JumpLinear = DropoutLoopSystem;

JumpLinear build(const DropoutLoop& loop, std::span<const double> taps) {
  const Normalised p = normalise(loop.plant), k = normalise(loop.controller);
  const int np = p.order, nc = k.order, nd = loop.delay, nh = static_cast<int>(taps.size());
  const int n = np + nc + nd + nh;
  const int sp = 0, sc = np, sd = np + nc, sh = np + nc + nd;  // offsets of plant, controller, delay, history
  auto unit = [&](int i) {
    RowVectorXd v = RowVectorXd::Zero(n + 1);
    v(i) = 1.0;
    return v;
  };
  JumpLinear j;
  for (int d = 0; d < 2; ++d) {
    RowVectorXd ybar = RowVectorXd::Zero(n + 1);
    if (d == 0) {
      ybar = unit(sd + nd - 1);  // y[k - delay]
    } else {
      for (int i = 0; i < nh; ++i) ybar += taps[static_cast<std::size_t>(i)] * unit(sh + i);
    }
    const RowVectorXd e = unit(n) - ybar;
    // Controller and plant in transposed direct form II: out = b0 in + s[0].
    RowVectorXd u = k.b[0] * e;
    if (nc > 0) u += unit(sc);
    RowVectorXd y = p.b[0] * u;
    if (np > 0) y += unit(sp);
    MatrixXd next = MatrixXd::Zero(n, n + 1);
    for (int i = 0; i < nc; ++i) {
      next.row(sc + i) = k.b[static_cast<std::size_t>(i) + 1] * e - k.a[static_cast<std::size_t>(i) + 1] * u;
      if (i + 1 < nc) next.row(sc + i) += unit(sc + i + 1);
    }
    for (int i = 0; i < np; ++i) {
      next.row(sp + i) = p.b[static_cast<std::size_t>(i) + 1] * u - p.a[static_cast<std::size_t>(i) + 1] * y;
      if (i + 1 < np) next.row(sp + i) += unit(sp + i + 1);
    }
    // Delay line y[k-1..k-delay] and history ybar[k-1..k-N], newest first.
    next.row(sd) = y;
    for (int i = 1; i < nd; ++i) next.row(sd + i) = unit(sd + i - 1);
    if (nh > 0) next.row(sh) = ybar;
    for (int i = 1; i < nh; ++i) next.row(sh + i) = unit(sh + i - 1);
    j.A[d] = next.leftCols(n);
    j.B[d] = next.col(n);
    j.c[d] = y.head(n);
    j.g[d] = y(n);
  }
  return j;
}

// vec(P) row-major: index i*n + j. The matrix of P -> P - sum_d p_d A_d P A_d'.
MatrixXd second_moment_operator(const JumpLinear& s, const double p[2]) {
  const auto n = s.A[0].rows();
  MatrixXd m = MatrixXd::Identity(n * n, n * n);
  for (int d = 0; d < 2; ++d) {
    if (p[d] == 0.0) continue;
    const MatrixXd& a = s.A[d];
    for (Eigen::Index i = 0; i < n; ++i)
      for (Eigen::Index jj = 0; jj < n; ++jj)
        for (Eigen::Index k = 0; k < n; ++k) {
          const double aik = p[d] * a(i, k);
          if (aik == 0.0) continue;
          for (Eigen::Index l = 0; l < n; ++l) m(i * n + jj, k * n + l) -= aik * a(jj, l);
        }
  }
  return m;
}

VectorXd vec(const MatrixXd& x) {
  VectorXd v(x.size());
  for (Eigen::Index i = 0; i < x.rows(); ++i)
    for (Eigen::Index j = 0; j < x.cols(); ++j) v(i * x.cols() + j) = x(i, j);
  return v;
}

MatrixXd unvec(const VectorXd& v, Eigen::Index n) {
  MatrixXd x(n, n);
  for (Eigen::Index i = 0; i < n; ++i)
    for (Eigen::Index j = 0; j < n; ++j) x(i, j) = v(i * n + j);
  return 0.5 * (x + x.transpose());
}

}  // namespace dropout_loop_impl

DropoutLoopSystem dropout_loop_system(const DropoutLoop& loop, std::span<const double> a) {
  if (auto e = dropout_loop_error(loop); !e.empty()) throw std::invalid_argument(e);
  return dropout_loop_impl::build(loop, a);
}

std::string dropout_loop_error(const DropoutLoop& loop) {
  using namespace dropout_loop_impl;
  if (auto e = tf_error(loop.plant, "plant"); !e.empty()) return e;
  if (auto e = tf_error(loop.controller, "controller"); !e.empty()) return e;
  if (loop.delay < 1 || loop.delay > kDropoutLoopMaxStates) return "delay must be 1.." + std::to_string(kDropoutLoopMaxStates) + " frames";
  if (!std::isfinite(loop.input_variance) || loop.input_variance < 0) return "input variance must be finite and >= 0";
  const auto states = dropout_loop_impl::normalise(loop.plant).order + dropout_loop_impl::normalise(loop.controller).order + loop.delay;
  if (states > kDropoutLoopMaxStates)
    return "the loop has " + std::to_string(states) + " states (plant order + controller order + delay); at most " +
           std::to_string(kDropoutLoopMaxStates) + " with the taps";
  return {};
}

LoopPower dropout_loop_power(const DropoutLoop& loop, std::span<const double> a, double eps, bool with_gradient) {
  using namespace dropout_loop_impl;
  if (auto e = dropout_loop_error(loop); !e.empty()) throw std::invalid_argument(e);
  if (!(eps >= 0.0 && eps <= 1.0)) throw std::invalid_argument("dropout rate must be in [0, 1]");
  if (a.size() > 16) throw std::invalid_argument("at most 16 compensator taps");
  {
    using namespace dropout_loop_impl;
    const auto states = static_cast<std::size_t>(normalise(loop.plant).order + normalise(loop.controller).order + loop.delay) + a.size();
    if (states > static_cast<std::size_t>(kDropoutLoopMaxStates))
      throw std::invalid_argument("the loop and its " + std::to_string(a.size()) + " taps have " + std::to_string(states) +
                                  " states; at most " + std::to_string(kDropoutLoopMaxStates));
  }
  for (double v : a)
    if (!std::isfinite(v)) throw std::invalid_argument("a compensator tap is not finite");

  const JumpLinear s = build(loop, a);
  const double p[2] = {1.0 - eps, eps};
  const double sigma2 = loop.input_variance;
  const auto n = s.A[0].rows();
  const Eigen::PartialPivLU<MatrixXd> lu(second_moment_operator(s, p));

  LoopPower out;
  // Mean-square stability: the second-moment operator T is positive, so
  // rho(T) < 1 iff X = T(X) + I has a positive definite solution.
  const MatrixXd x = unvec(lu.solve(vec(MatrixXd::Identity(n, n))), n);
  if (!x.allFinite() || x.llt().info() != Eigen::Success) return out;
  // Also refuse a nearly singular operator: X's size is the sum of T^k(I).
  if (x.trace() > 1e12 * static_cast<double>(n)) return out;

  MatrixXd q = MatrixXd::Zero(n, n);
  for (int d = 0; d < 2; ++d) q += p[d] * sigma2 * s.B[d] * s.B[d].transpose();
  const MatrixXd pm = unvec(lu.solve(vec(q)), n);
  double power = 0;
  for (int d = 0; d < 2; ++d) power += p[d] * ((s.c[d] * pm * s.c[d].transpose())(0, 0) + sigma2 * s.g[d] * s.g[d]);
  out.ms_stable = true;
  out.output_power = power;
  if (!with_gradient) return out;

  // Adjoint: S = T*(S) + W, W = sum_d p_d c_d' c_d; then
  // dJ/da_i = <S, dT_i(P) + dQ_i> + <dW_i, P> + 2 eps sigma2 g_1 dg_1,i,
  // with dT_i(P) = eps (dA P A_1' + A_1 P dA'), dQ_i = eps sigma2 (dB B_1' + B_1 dB'),
  // dW_i = eps (dc' c_1 + c_1' dc). The system is affine in a, so the
  // derivatives are differences of two builds.
  MatrixXd w = MatrixXd::Zero(n, n);
  for (int d = 0; d < 2; ++d) w += p[d] * s.c[d].transpose() * s.c[d];
  const MatrixXd sm = unvec(lu.transpose().solve(vec(w)), n);
  std::vector<double> zero(a.size(), 0.0);
  const JumpLinear s0 = build(loop, zero);
  out.gradient.resize(a.size());
  for (std::size_t i = 0; i < a.size(); ++i) {
    std::vector<double> ei(a.size(), 0.0);
    ei[i] = 1.0;
    const JumpLinear si = build(loop, ei);
    const MatrixXd da = si.A[1] - s0.A[1];
    const VectorXd db = si.B[1] - s0.B[1];
    const RowVectorXd dc = si.c[1] - s0.c[1];
    const double dg = si.g[1] - s0.g[1];
    const MatrixXd dt = eps * (da * pm * s.A[1].transpose() + s.A[1] * pm * da.transpose());
    const MatrixXd dq = eps * sigma2 * (db * s.B[1].transpose() + s.B[1] * db.transpose());
    const MatrixXd dw = eps * (dc.transpose() * s.c[1] + s.c[1].transpose() * dc);
    out.gradient[i] = (sm.cwiseProduct(dt + dq)).sum() + (dw.cwiseProduct(pm)).sum() + 2.0 * eps * sigma2 * s.g[1] * dg;
  }
  return out;
}

}  // namespace syncplc::motion
