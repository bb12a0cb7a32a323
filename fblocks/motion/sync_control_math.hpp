// Paper 000 (Xu et al., "Development of a decentralized multi-axis synchronous
// control approach for real-time networks", ISA Transactions 2017): the
// matrices of the synchronous controller and its centralized all-axes form.
//
//   e = x_d − x (per axis), ε = T e (eq. 3), T of eq. (6): row 1 zero, row k
//   (k ≥ 2) T[k,i] = −1/(k−1) for i < k and T[k,k] = 1, so ε_1 = 0,
//   ε_k = e_k − mean(e_1..e_{k−1}) (eq. 7).
//   E = e + αε = (I + αT) e (eqs. 4–5), α = κI.
//   I + αT = P + Q (before eq. 16): P diagonal = diag(1, 1+κ, …, 1+κ), Q strictly
//   lower triangular, Q[k,i] = −κ/(k−1) for i < k.
//   K_e = m (I + αT′) (eq. 10); (I + αT′)^−1 K_e = mI is why the law can use m ė.
//   τ = K_H ẍ_d + K_C ẋ_d + K_P E + K_D Ė + m ė + K_N sign(Ė)   (eq. 11, with the
//   eq. (8) misprint corrected: the first term is K_H ẍ_d).
//
// CentralizedSyncController computes eq. (11) for all n axes at once from the
// full e and ė vectors with Eigen. It is the reference the decentralized
// SYNC_CONTROLLER block (one instance per axis, eq. 16) is tested against; it
// is not a block. Matrices are built at construction; compute() reuses
// preallocated storage and does not allocate.
//
// The robust term is shared by both forms (robust_term()): the paper's
// K_N sign(Ė), K_N(t) = Δ_H|ẍ_d| + Δ_C|ẋ_d| from eq. (9) as eq. (23) uses it
// (the printed eq. (9) has ẋ_d twice), or a boundary layer K_N sat(Ė/φ).
//
// Units (SI): positions rad, time s, command PWM. K_P PWM/rad, K_D, K_C and m
// PWM·s/rad, K_H PWM·s²/rad, K_N PWM, Δ_H PWM·s²/rad, Δ_C PWM·s/rad, φ rad/s.
#pragma once

#include <Eigen/Dense>
#include <cstdint>

namespace syncplc::motion {

// Largest n (axes of one synchronized group) the blocks accept.
inline constexpr int kMaxSyncAxes = 256;  // as the sim_table driver

enum class RobustTerm : std::uint8_t {
  Sign = 0,  // K_N sign(Ė)                      paper eqs. (11), (16)
  Eq9 = 1,   // (Δ_H|ẍ_d| + Δ_C|ẋ_d|) sign(Ė)    paper eqs. (9), (23)
  Sat = 2,   // K_N sat(Ė/φ)                     boundary layer, no chatter
};

struct SyncGains {
  double K_P = 0;      // PWM/rad
  double K_D = 0;      // PWM·s/rad
  double K_H = 0;      // PWM·s²/rad
  double K_C = 0;      // PWM·s/rad
  double m = 0;        // PWM·s/rad
  double K_N = 0;      // PWM
  double Delta_H = 0;  // PWM·s²/rad
  double Delta_C = 0;  // PWM·s/rad
  double phi = 1;      // rad/s, boundary-layer width (Sat)
  RobustTerm robust = RobustTerm::Sat;
  double out_min = -1;  // PWM
  double out_max = 1;   // PWM
};

// T of eq. (6), n × n.
Eigen::MatrixXd sync_transform(int n);

// I + αT, its P + Q split and K_e of eq. (10), for α = κI.
struct SyncMatrices {
  Eigen::MatrixXd T;     // eq. (6)
  Eigen::MatrixXd IaT;   // I + αT (eq. 5)
  Eigen::VectorXd P;     // diagonal of P
  Eigen::MatrixXd Q;     // strictly lower part of I + αT
  Eigen::MatrixXd K_e;   // m (I + αT′) (eq. 10)
};
SyncMatrices sync_matrices(int n, double kappa, double m);

// sign() with sign(0) = 0.
inline double sgn(double v) noexcept { return v > 0 ? 1.0 : (v < 0 ? -1.0 : 0.0); }

// The robust term of eq. (11)/(16) for one axis: Ė_k, ẍ_d,k, ẋ_d,k → PWM.
inline double robust_term(const SyncGains& g, double Edot, double a_d, double v_d) noexcept {
  switch (g.robust) {
    case RobustTerm::Sign: return g.K_N * sgn(Edot);
    case RobustTerm::Eq9: return (g.Delta_H * (a_d < 0 ? -a_d : a_d) + g.Delta_C * (v_d < 0 ? -v_d : v_d)) * sgn(Edot);
    case RobustTerm::Sat: {
      const double s = Edot / g.phi;
      return g.K_N * (s > 1 ? 1.0 : (s < -1 ? -1.0 : s));
    }
  }
  return 0;
}

// Backward difference (now − prev)/T_s with T_s = dt_ns·1e−9 s; 0 if dt_ns ≤ 0.
inline double backward_difference(double now, double prev, std::int64_t dt_ns) noexcept {
  return dt_ns > 0 ? (now - prev) / (static_cast<double>(dt_ns) * 1e-9) : 0.0;
}

// Limits v to [lo, hi]; *clipped tells whether it did.
inline double limit(double v, double lo, double hi, bool* clipped) noexcept {
  if (v > hi) { *clipped = true; return hi; }
  if (v < lo) { *clipped = true; return lo; }
  *clipped = false;
  return v;
}

class CentralizedSyncController {
 public:
  CentralizedSyncController(int n, double kappa, const SyncGains& gains);

  // One scan of eq. (11) for all axes: per-axis ẍ_d, ẋ_d, e, ė → τ (limited).
  void compute(const Eigen::VectorXd& a_d, const Eigen::VectorXd& v_d, const Eigen::VectorXd& e,
               const Eigen::VectorXd& e_dot) noexcept;

  int n() const { return n_; }
  const SyncMatrices& matrices() const { return mat_; }
  const Eigen::VectorXd& tau() const { return tau_; }
  const Eigen::VectorXd& E() const { return E_; }
  const Eigen::VectorXd& E_dot() const { return Ed_; }
  const Eigen::VectorXd& eps() const { return eps_; }
  bool saturated(int axis0) const { return sat_[axis0] != 0; }

 private:
  int n_;
  SyncGains g_;
  SyncMatrices mat_;
  Eigen::VectorXd E_, Ed_, eps_, tau_;
  Eigen::Matrix<std::uint8_t, Eigen::Dynamic, 1> sat_;
};

}  // namespace syncplc::motion
