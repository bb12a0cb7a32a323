#include "fblocks/motion/optimal_compensator_math.hpp"

#include <Eigen/Dense>
#include <cmath>
#include <string>

namespace syncplc::motion {
namespace optimal_compensator_math {

Eigen::MatrixXd toeplitz(std::span<const double> r, int n) {
  Eigen::MatrixXd R(n, n);
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) R(i, j) = r[static_cast<std::size_t>(std::abs(i - j))];
  return R;
}

}  // namespace optimal_compensator_math

double optimal_dropout_cost(std::span<const double> r, std::span<const double> a, double loading) {
  const int n = static_cast<int>(a.size());
  const Eigen::MatrixXd R = optimal_compensator_math::toeplitz(r, n);
  const Eigen::Map<const Eigen::VectorXd> av(a.data(), n);
  const Eigen::Map<const Eigen::VectorXd> rv(r.data() + 1, n);
  return r[0] - 2.0 * av.dot(rv) + av.dot((R + loading * Eigen::MatrixXd::Identity(n, n)) * av);
}

OptimalDropoutPredictor optimal_dropout_predictor(std::span<const double> r, int order, double eps) {
  using optimal_compensator_math::toeplitz;
  if (order < 1 || order > kOptimalMaxOrder)
    throw std::invalid_argument("order must be 1.." + std::to_string(kOptimalMaxOrder) + ", got " + std::to_string(order));
  if (!(eps >= 0.0 && eps < 1.0)) throw std::invalid_argument("dropout rate must be in [0, 1), got " + std::to_string(eps));
  if (r.size() < static_cast<std::size_t>(order) + 1)
    throw std::invalid_argument("autocorrelation needs lags 0.." + std::to_string(order));
  for (int j = 0; j <= order; ++j)
    if (!std::isfinite(r[static_cast<std::size_t>(j)])) throw std::invalid_argument("autocorrelation lag " + std::to_string(j) + " is not finite");
  if (!(r[0] > 0.0)) throw std::invalid_argument("autocorrelation at lag 0 (the signal's power) must be > 0");
  // A valid autocorrelation has a positive definite Toeplitz matrix (strictly:
  // semidefinite; a singular one is a sum of sinusoids, perfectly predictable
  // and numerically useless here). Checked on lags 0..order, which also
  // makes the one-step error variance r0 - a'r positive at eps = 0.
  const Eigen::LLT<Eigen::MatrixXd> full(toeplitz(r, order + 1));
  if (full.info() != Eigen::Success || full.matrixL().toDenseMatrix().diagonal().minCoeff() <= 1e-9 * std::sqrt(r[0]))
    throw std::invalid_argument("lags 0.." + std::to_string(order) +
                                " are not an autocorrelation (their Toeplitz matrix is not positive definite)");
  const int n = order;
  const Eigen::MatrixXd R = toeplitz(r, n);
  const Eigen::Map<const Eigen::VectorXd> rv(r.data() + 1, n);
  const Eigen::MatrixXd I = Eigen::MatrixXd::Identity(n, n);
  OptimalDropoutPredictor p;
  p.order = n;
  double lambda = 0.0;
  Eigen::VectorXd a = R.llt().solve(rv);
  // Monotone iteration: s2(lambda) rises with lambda and is bounded by r0, so
  // lambda_k rises to the smallest fixed point. 1e-13 relative is far below
  // any effect on the coefficients; 10000 steps bound the load time.
  for (int it = 0; it < 10000; ++it) {
    const double s2 = r[0] - a.dot(rv);
    const double next = eps * s2;
    p.iterations = it + 1;
    if (std::abs(next - lambda) <= 1e-13 * r[0]) {
      lambda = next;
      break;
    }
    lambda = next;
    a = (R + lambda * I).llt().solve(rv);
  }
  a = (R + lambda * I).llt().solve(rv);
  for (int j = 0; j < n; ++j) p.a[j] = a(j);
  p.loading = lambda;
  p.error_variance = r[0] - a.dot(rv);
  return p;
}

}  // namespace syncplc::motion
