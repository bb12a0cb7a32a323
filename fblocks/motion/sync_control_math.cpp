#include "fblocks/motion/sync_control_math.hpp"

#include <stdexcept>

namespace syncplc::motion {

Eigen::MatrixXd sync_transform(int n) {
  if (n < 1) throw std::invalid_argument("sync_transform: n must be >= 1");
  Eigen::MatrixXd T = Eigen::MatrixXd::Zero(n, n);
  for (int k = 1; k < n; ++k) {  // 0-based row k is the paper's row k+1
    T.row(k).head(k).setConstant(-1.0 / k);
    T(k, k) = 1.0;
  }
  return T;
}

SyncMatrices sync_matrices(int n, double kappa, double m) {
  SyncMatrices s;
  s.T = sync_transform(n);
  const Eigen::MatrixXd I = Eigen::MatrixXd::Identity(n, n);
  s.IaT = I + kappa * s.T;
  s.P = s.IaT.diagonal();
  s.Q = s.IaT.triangularView<Eigen::StrictlyLower>();
  s.K_e = m * (I + kappa * s.T.transpose());
  return s;
}

CentralizedSyncController::CentralizedSyncController(int n, double kappa, const SyncGains& gains)
    : n_(n), g_(gains), mat_(sync_matrices(n, kappa, gains.m)) {
  E_.setZero(n);
  Ed_.setZero(n);
  eps_.setZero(n);
  tau_.setZero(n);
  sat_.setZero(n);
}

void CentralizedSyncController::compute(const Eigen::VectorXd& a_d, const Eigen::VectorXd& v_d,
                                        const Eigen::VectorXd& e, const Eigen::VectorXd& e_dot) noexcept {
  E_.noalias() = mat_.IaT * e;       // eq. (5)
  Ed_.noalias() = mat_.IaT * e_dot;  // Ė = (I + αT) ė
  eps_.noalias() = mat_.T * e;       // eq. (3)
  // eq. (11); per-axis gains are the scalar multiples of I the paper uses.
  tau_ = g_.K_H * a_d + g_.K_C * v_d + g_.K_P * E_ + g_.K_D * Ed_ + g_.m * e_dot;
  for (int k = 0; k < n_; ++k) {
    bool clipped = false;
    tau_[k] = limit(tau_[k] + robust_term(g_, Ed_[k], a_d[k], v_d[k]), g_.out_min, g_.out_max, &clipped);
    sat_[k] = clipped ? 1 : 0;
  }
}

}  // namespace syncplc::motion
