// Paper 000 matrices (eqs. 3–10) and the centralized form of eq. (11),
// checked against the paper's definitions element by element.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "fblocks/motion/sync_control_math.hpp"

namespace syncplc::motion {
namespace {

TEST(SyncMath, TransformMatchesEq6) {
  for (int n = 1; n <= 8; ++n) {
    const Eigen::MatrixXd T = sync_transform(n);
    ASSERT_EQ(T.rows(), n);
    ASSERT_EQ(T.cols(), n);
    for (int r = 1; r <= n; ++r)      // paper's 1-based row
      for (int c = 1; c <= n; ++c) {  // and column
        double want = 0;
        if (r >= 2 && c < r) want = -1.0 / (r - 1);
        if (r >= 2 && c == r) want = 1.0;
        EXPECT_EQ(T(r - 1, c - 1), want) << "n=" << n << " T[" << r << "," << c << "]";
      }
    // Remark 1: lower triangular; every row sums to zero (equal errors are synchronous).
    EXPECT_TRUE(T.isLowerTriangular());
    EXPECT_LT(T.rowwise().sum().cwiseAbs().maxCoeff(), 1e-15) << n;
  }
}

TEST(SyncMath, EpsIsEq7) {
  std::mt19937 rng(1234);
  std::uniform_real_distribution<double> u(-2, 2);
  for (int n = 1; n <= 8; ++n) {
    Eigen::VectorXd e(n);
    for (int i = 0; i < n; ++i) e[i] = u(rng);
    const Eigen::VectorXd eps = sync_transform(n) * e;
    EXPECT_EQ(eps[0], 0.0);
    if (n >= 2) {
      EXPECT_NEAR(eps[1], e[1] - e[0], 1e-15);
    }
    for (int k = 2; k < n; ++k) {  // 0-based k: paper's k+1
      const double mean = e.head(k).mean();
      EXPECT_NEAR(eps[k], e[k] - mean, 1e-14) << "n=" << n << " k=" << k + 1;
    }
    // ε = 0 when all errors are equal (eq. 1).
    const Eigen::VectorXd same = sync_transform(n) * Eigen::VectorXd::Constant(n, 0.37);
    EXPECT_LT(same.cwiseAbs().maxCoeff(), 1e-15);
  }
}

TEST(SyncMath, PQSplitAndKe) {
  for (const double kappa : {0.0, 0.5, 1.3}) {
    for (int n = 1; n <= 8; ++n) {
      const double m = 0.2586268;
      const SyncMatrices s = sync_matrices(n, kappa, m);
      // E = (I + αT) e (eq. 5) with α = κI
      EXPECT_TRUE(s.IaT.isApprox(Eigen::MatrixXd::Identity(n, n) + kappa * s.T));
      // P = diag(1, 1+κ, …, 1+κ): row 1 of T is zero, so axis 1 gets no κ.
      ASSERT_EQ(s.P.size(), n);
      EXPECT_EQ(s.P[0], 1.0);
      for (int k = 1; k < n; ++k) EXPECT_EQ(s.P[k], 1.0 + kappa) << n;
      // Q strictly lower: Q[k,i] = −κ/(k−1), i < k (1-based).
      for (int r = 1; r <= n; ++r)
        for (int c = 1; c <= n; ++c) {
          const double want = c < r ? -kappa / (r - 1) : 0.0;
          EXPECT_NEAR(s.Q(r - 1, c - 1), want, 1e-15) << "n=" << n << " Q[" << r << "," << c << "]";
        }
      // P + Q = I + αT exactly.
      Eigen::MatrixXd pq = s.Q;
      pq.diagonal() += s.P;
      EXPECT_EQ((pq - s.IaT).cwiseAbs().maxCoeff(), 0.0);
      // K_e = m(I + αT′) (eq. 10): first row m, −mκ, −mκ/2, …; diagonal m, m(κ+1), …
      for (int r = 1; r <= n; ++r)
        for (int c = 1; c <= n; ++c) {
          double want = 0;
          if (r == c) want = r == 1 ? m : m * (kappa + 1);
          else if (c > r) want = -m * kappa / (c - 1);
          EXPECT_NEAR(s.K_e(r - 1, c - 1), want, 1e-15) << "n=" << n << " K_e[" << r << "," << c << "]";
        }
      // (I + αT′)^{-1} K_e = mI (K_M of Remark 2): why the law uses m ė.
      const Eigen::MatrixXd It = Eigen::MatrixXd::Identity(n, n) + kappa * s.T.transpose();
      EXPECT_TRUE((It.inverse() * s.K_e).isApprox(m * Eigen::MatrixXd::Identity(n, n), 1e-12));
      // λ_min{K_e} = m (Theorem 1, condition 1): K_e is triangular with diagonal ≥ m.
      EXPECT_EQ(s.K_e.diagonal().minCoeff(), m);
      // I + αT is invertible (eq. 5: E → 0 implies e → 0).
      EXPECT_GT(std::abs(s.IaT.determinant()), 0.0);
    }
  }
}

TEST(SyncMath, RobustTermForms) {
  SyncGains g;
  g.K_N = 10;
  g.robust = RobustTerm::Sign;
  EXPECT_EQ(robust_term(g, 1e-9, 0, 0), 10.0);
  EXPECT_EQ(robust_term(g, -3, 0, 0), -10.0);
  EXPECT_EQ(robust_term(g, 0, 0, 0), 0.0);
  g.robust = RobustTerm::Eq9;  // K_N(t) = Δ_H|ẍ_d| + Δ_C|ẋ_d|; K_N unused
  g.Delta_H = 0.5;
  g.Delta_C = 0.25;
  EXPECT_DOUBLE_EQ(robust_term(g, 2.0, -4.0, 8.0), 0.5 * 4 + 0.25 * 8);
  EXPECT_DOUBLE_EQ(robust_term(g, -2.0, 4.0, -8.0), -(0.5 * 4 + 0.25 * 8));
  EXPECT_EQ(robust_term(g, 1.0, 0.0, 0.0), 0.0);
  g.robust = RobustTerm::Sat;
  g.phi = 4;
  EXPECT_DOUBLE_EQ(robust_term(g, 1.0, 0, 0), 10 * 0.25);
  EXPECT_DOUBLE_EQ(robust_term(g, -2.0, 0, 0), -10 * 0.5);
  EXPECT_EQ(robust_term(g, 4.0, 0, 0), 10.0);
  EXPECT_EQ(robust_term(g, -400.0, 0, 0), -10.0);
}

TEST(SyncMath, CentralizedLawIsEq11) {
  std::mt19937 rng(99);
  std::uniform_real_distribution<double> u(-1, 1);
  const int n = 5;
  SyncGains g;
  g.K_P = 0.7;
  g.K_D = 0.01;
  g.K_H = 0.002;
  g.K_C = 0.03;
  g.m = 0.25;
  g.K_N = 0.1;
  g.robust = RobustTerm::Sign;
  g.out_min = -1e9;
  g.out_max = 1e9;
  const double kappa = 1.3;
  CentralizedSyncController c(n, kappa, g);
  Eigen::VectorXd a(n), v(n), e(n), ed(n);
  for (int i = 0; i < n; ++i) {
    a[i] = u(rng);
    v[i] = u(rng);
    e[i] = u(rng);
    ed[i] = u(rng);
  }
  c.compute(a, v, e, ed);
  const Eigen::MatrixXd T = sync_transform(n);
  const Eigen::MatrixXd IaT = Eigen::MatrixXd::Identity(n, n) + kappa * T;
  const Eigen::VectorXd E = IaT * e, Ed = IaT * ed;
  for (int k = 0; k < n; ++k) {
    const double want = g.K_H * a[k] + g.K_C * v[k] + g.K_P * E[k] + g.K_D * Ed[k] + g.m * ed[k] +
                        g.K_N * (Ed[k] > 0 ? 1 : -1);
    EXPECT_NEAR(c.tau()[k], want, 1e-14) << k;
    EXPECT_NEAR(c.eps()[k], (T * e)[k], 1e-15);
    EXPECT_FALSE(c.saturated(k));
  }
  // The output limit.
  g.out_min = -0.05;
  g.out_max = 0.05;
  CentralizedSyncController lim(n, kappa, g);
  lim.compute(a, v, e, ed);
  for (int k = 0; k < n; ++k) {
    EXPECT_LE(std::abs(lim.tau()[k]), 0.05);
    EXPECT_EQ(lim.saturated(k), std::abs(c.tau()[k]) > 0.05);
  }
}

}  // namespace
}  // namespace syncplc::motion
