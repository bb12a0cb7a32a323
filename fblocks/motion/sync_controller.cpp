// SYNC_CONTROLLER: the decentralized synchronous controller of paper 000
// (Xu et al., ISA Transactions 2017), one instance per axis k of n, as the
// paper's networked nodes.
//
// Axis k at scan j (T_s = the time since the previous scan):
//   e_k = x_d − x, ė_k = v_d − v (v connected) or (e_k(j) − e_k(j−1))/T_s.
//   The preceding axes i < k send their errors over the network; e_rx[i]
//   holds e_i(j−1), one scan late (eq. 13), with e_valid[i] FALSE for a lost
//   sample. Per preceding axis, a MessageEstimator (paper 003 / fblocks/motion
//   message_estimator.hpp, order 3, Robust history) returns the received value
//   or, on a loss, its estimate; the ė_i history is the backward difference of
//   consecutive received values (valid only when both were received) through
//   a second estimator. With compensation, the current values are the
//   one-step predictions of eq. (15) (predict_next()):
//     ê_i(j) = 21/8 e_i(j−1) − 19/8 e_i(j−2) + 7/8 e_i(j−3) − 1/8 e_i(j−4),
//   and likewise ê̇_i(j) on the ė_i history; without, ê_i(j) = e_i(j−1).
//   With rx_delay = 0, e_rx holds the current e_i(j) (same-task wiring, or the
//   centralized reference) and is used as received.
//   E_k = Σ_{i<k} Q_ki ê_i + P_kk e_k,  Ė_k = Σ_{i<k} Q_ki ê̇_i + P_kk ė_k
//   (I + αT = P + Q, eqs. 5, 6, 16),
//   τ_k = K_H ẍ_d + K_C ẋ_d + K_P E_k + K_D Ė_k + m ė_k + robust(Ė_k)   (eq. 16)
//   limited to [out_min, out_max]; ε_k = e_k − mean(ê_1..ê_{k−1}) (eq. 7).
// The robust term: K_N sign(Ė) (paper), K_N(t) sign(Ė) with
// K_N(t) = Δ_H|ẍ_d| + Δ_C|ẋ_d| (eq. 9 as corrected, eq. 23), or K_N sat(Ė/φ).
//
// Matrices are built with Eigen at construction (sync_control_math.hpp); the
// scan path reads one row of them from plain arrays and never allocates.
// See docs/motion/sync-controller.md.
#include <memory>
#include <vector>

#include "fblocks/motion/message_estimator.hpp"
#include "fblocks/motion/motion.hpp"
#include "fblocks/motion/param_read.hpp"
#include "fblocks/motion/sync_control_math.hpp"
#include "runtime/core/pin_decl.hpp"

namespace syncplc::motion {
namespace {

enum : int {
  kXd = 0, kVd, kAd, kX, kV, kRx, kValid,            // inputs
  kTau, kE, kEdot, kECoupled, kEps, kSat, kEstimated  // outputs
};

struct SyncConfig {
  int axis = 1;  // k, 1-based
  int n = 1;
  double kappa = 0;
  SyncGains g;
  bool compensation = true;
  int rx_delay = 1;
  bool use_v = false;
};

// Indices of the tunable parameters (declaration order in register_sync_controller).
enum : int { kPKP = 3, kPKD = 4, kPKH = 5, kPKC = 6, kPKN = 9, kPDeltaH, kPDeltaC, kPPhi, kPOutMin, kPOutMax };

// Whether the gains are usable together (the factory's checks).
bool gains_valid(const SyncGains& g) {
  return g.out_min < g.out_max && (g.robust != RobustTerm::Sat || g.phi > 0);
}

class SyncController final : public Block {
 public:
  explicit SyncController(const SyncConfig& c) : c_(c) {
    const SyncMatrices mat = sync_matrices(c.n, c.kappa, c.g.m);
    const int k0 = c.axis - 1;
    p_kk_ = mat.P[k0];
    t_kk_ = mat.T(k0, k0);
    pre_.resize(static_cast<std::size_t>(k0));
    for (int i = 0; i < k0; ++i) {
      pre_[static_cast<std::size_t>(i)].q = mat.Q(k0, i);
      pre_[static_cast<std::size_t>(i)].t = mat.T(k0, i);
    }
  }

  // Eq. (16) is memoryless in its gains (the state is the error history and
  // the estimators), so a new gain acts from the next scan; alpha and m shape
  // the coupling matrices and are structure (a change starts the instance fresh).
  void retune_from(const Block& fresh) noexcept override {
    apply(static_cast<const SyncController&>(fresh).c_.g);
  }
  bool tune(int param, double v) noexcept override {
    SyncGains g = c_.g;
    switch (param) {
      case kPKP: g.K_P = v; break;
      case kPKD: g.K_D = v; break;
      case kPKH: g.K_H = v; break;
      case kPKC: g.K_C = v; break;
      case kPKN: g.K_N = v; break;
      case kPDeltaH: g.Delta_H = v; break;
      case kPDeltaC: g.Delta_C = v; break;
      case kPPhi: g.phi = v; break;
      case kPOutMin: g.out_min = v; break;
      case kPOutMax: g.out_max = v; break;
      default: return false;
    }
    if (!gains_valid(g)) return false;
    apply(g);
    return true;
  }

  // v connected or disconnected by an online change (e(j-1) is kept either way).
  void rewire_from(const Block& fresh) noexcept override { c_.use_v = static_cast<const SyncController&>(fresh).c_.use_v; }

  void execute(ScanContext& ctx) noexcept override {
    const double a_d = in<double>(kAd);
    const double v_d = in<double>(kVd);
    const double e = in<double>(kXd) - in<double>(kX);
    double ed;
    if (c_.use_v) {
      ed = v_d - in<double>(kV);
    } else {
      ed = first_ ? 0.0 : backward_difference(e, e_prev_, ctx.dt_ns);
    }
    e_prev_ = e;  // also with v: an online change that unwires v differentiates from the right e(j-1)
    first_ = false;

    const bool predict = c_.rx_delay == 1 && c_.compensation;
    double E = 0, Ed = 0, eps = 0;
    for (std::uint32_t i = 0; i < pre_.size(); ++i) {
      Preceding& p = pre_[i];
      const bool valid = in<bool>(kValid, i);
      const double ef = p.e_est.update(valid, in<double>(kRx, i));
      const bool received = !p.e_est.estimated();
      if (!received) ++estimated_;
      const bool d_valid = p.have_prev && received && p.prev_received;
      const double edf = p.ed_est.update(d_valid, d_valid ? backward_difference(ef, p.prev, ctx.dt_ns) : 0.0);
      p.prev = ef;
      p.prev_received = received;
      p.have_prev = true;
      const double eh = predict ? p.e_est.predict_next() : ef;
      const double edh = predict ? p.ed_est.predict_next() : edf;
      E += p.q * eh;
      Ed += p.q * edh;
      eps += p.t * eh;
    }
    E += p_kk_ * e;
    Ed += p_kk_ * ed;
    eps += t_kk_ * e;

    const SyncGains& g = c_.g;
    const double u = g.K_H * a_d + g.K_C * v_d + g.K_P * E + g.K_D * Ed + g.m * ed;
    bool clipped = false;
    const double tau = limit(u + robust_term(g, Ed, a_d, v_d), g.out_min, g.out_max, &clipped);
    out<double>(kTau, tau);
    out<double>(kE, e);
    out<double>(kEdot, ed);
    out<double>(kECoupled, E);
    out<double>(kEps, eps);
    out<bool>(kSat, clipped);
    out<std::uint32_t>(kEstimated, estimated_);
  }

 private:
  struct Preceding {
    MessageEstimator e_est{3, EstimatorHistory::Robust};   // e_i
    MessageEstimator ed_est{3, EstimatorHistory::Robust};  // ė_i
    double q = 0;  // Q[k,i]
    double t = 0;  // T[k,i]
    double prev = 0;
    bool prev_received = false;
    bool have_prev = false;
  };

  // The tunable gains of `g` (robust and m are structure and stay).
  void apply(const SyncGains& g) noexcept {
    SyncGains& c = c_.g;
    c.K_P = g.K_P, c.K_D = g.K_D, c.K_H = g.K_H, c.K_C = g.K_C, c.K_N = g.K_N;
    c.Delta_H = g.Delta_H, c.Delta_C = g.Delta_C, c.phi = g.phi, c.out_min = g.out_min, c.out_max = g.out_max;
  }

  SyncConfig c_;
  double p_kk_ = 1;
  double t_kk_ = 0;
  std::vector<Preceding> pre_;  // sized at construction, one per preceding axis
  bool first_ = true;
  double e_prev_ = 0;
  std::uint32_t estimated_ = 0;
};

std::unique_ptr<Block> make_sync(BlockSetup& s) {
  bool ok = true;
  SyncConfig c;
  c.n = static_cast<int>(ctl::int_param(s, "n", &ok));
  c.axis = static_cast<int>(ctl::int_param(s, "axis", &ok));
  c.kappa = ctl::real_param(s, "alpha", &ok);
  SyncGains& g = c.g;
  g.K_P = ctl::real_param(s, "K_P", &ok);
  g.K_D = ctl::real_param(s, "K_D", &ok);
  g.K_H = ctl::real_param(s, "K_H", &ok);
  g.K_C = ctl::real_param(s, "K_C", &ok);
  g.m = ctl::real_param(s, "m", &ok);
  g.robust = static_cast<RobustTerm>(ctl::int_param(s, "robust", &ok));
  g.K_N = ctl::real_param(s, "K_N", &ok);
  g.Delta_H = ctl::real_param(s, "Delta_H", &ok);
  g.Delta_C = ctl::real_param(s, "Delta_C", &ok);
  g.phi = ctl::real_param(s, "phi", &ok);
  g.out_min = ctl::real_param(s, "out_min", &ok);
  g.out_max = ctl::real_param(s, "out_max", &ok);
  c.compensation = ctl::bool_param(s, "compensation");
  c.rx_delay = static_cast<int>(ctl::int_param(s, "rx_delay", &ok));
  const std::string& name = s.type().name;
  if (ok && c.axis > c.n) {
    s.error(name + ": axis " + std::to_string(c.axis) + " is not one of the n = " + std::to_string(c.n) + " axes");
    ok = false;
  }
  if (ok && !(g.out_min < g.out_max)) {
    s.error(name + ": out_min must be less than out_max");
    ok = false;
  }
  if (ok && g.robust == RobustTerm::Sat && !(g.phi > 0)) {
    s.error(name + ": robust = 2 (sat) needs a boundary-layer width phi > 0");
    ok = false;
  }
  if (!ok) return nullptr;
  c.use_v = s.connected(kV);
  return std::make_unique<SyncController>(c);
}

}  // namespace

void register_sync_controller(BlockRegistry& r) {
  BlockTypeInfo t;
  t.name = "SYNC_CONTROLLER";
  t.category = kCategory;
  t.doc =
      "Decentralized synchronous position controller of paper 000, one instance per axis k (param axis) of n. "
      "e = x_d - x; e_dot = v_d - v if v is connected, else (e(j) - e(j-1))/T_s (0 on the first scan). "
      "e_rx[i] (i < k) is the error of preceding axis i as received over the network: e_i(j-1), one scan late "
      "(eq. 13; rx_delay = 0: the current e_i(j)); e_valid[i] FALSE marks a lost sample, which a Taylor message "
      "estimator fills (counted in estimated). The preceding error rates are the backward differences of the "
      "received errors. With compensation, the preceding values are predicted one scan ahead by eq. (15): "
      "e^_i(j) = 21/8 e_i(j-1) - 19/8 e_i(j-2) + 7/8 e_i(j-3) - 1/8 e_i(j-4), likewise for the rates. "
      "T of eq. (6) (row k: -1/(k-1) left of the diagonal, 1 on it; row 1 zero), I + alpha T = P + Q with "
      "P = diag(1, 1+alpha, ...) and Q[k,i] = -alpha/(k-1): E = P_kk e + sum_i Q_ki e^_i, "
      "E_dot = P_kk e_dot + sum_i Q_ki e^dot_i, eps = e - mean(e^_1..e^_(k-1)) (eqs. 3-7), and (eq. 16) "
      "tau = LIMIT(out_min, K_H a_d + K_C v_d + K_P E + K_D E_dot + m e_dot + R, out_max) with the robust term "
      "R = K_N sign(E_dot) (robust 0, the paper), (Delta_H |a_d| + Delta_C |v_d|) sign(E_dot) (robust 1, "
      "eq. 9 corrected as eq. 23 uses it) or K_N sat(E_dot/phi) (robust 2, boundary layer, default: no chatter). "
      "Units SI; the defaults are the paper's section 5 gains converted to SI (K_D and m were printed per ms). "
      "The gains of eq. (16) and the limits are tunable while running (online change or the <param>_in inputs): "
      "eq. (16) holds no integral, so a new gain acts from the next scan; alpha and m shape the coupling "
      "matrices and are structure.";
  t.reference =
      "Xu, Sheng, Xiong, Zhu: Development of a decentralized multi-axis synchronous control approach for "
      "real-time networks, ISA Transactions 2017 (paper 000), eqs. (3)-(16), (23), Theorem 1; eq. (15) after "
      "Hsieh & Hsu (paper 003 eq. 5)";
  t.pins = {
      input("x_d", IecType::LREAL).unit("rad").required().doc("desired position"),
      input("v_d", IecType::LREAL).unit("rad/s").doc("desired velocity (feed-forward K_C, and e_dot with v)"),
      input("a_d", IecType::LREAL).unit("rad/s^2").doc("desired acceleration (feed-forward K_H)"),
      input("x", IecType::LREAL).unit("rad").required().doc("measured position"),
      input("v", IecType::LREAL).unit("rad/s")
          .doc("measured velocity; unconnected: e_dot is the backward difference of e"),
      input("e_rx", IecType::LREAL).unit("rad").array("n")
          .doc("errors of the other axes as received, one scan late: element i holds e_i(j-1); only elements 1..axis-1 "
               "are read"),
      input("e_valid", IecType::BOOL).array("n").init("TRUE")
          .doc("FALSE marks a lost e_rx element (estimated instead)"),
      output("tau", IecType::LREAL).unit("PWM").doc("command (eq. 16), limited to out_min..out_max"),
      output("e", IecType::LREAL).unit("rad").doc("own position error x_d - x (send this to the following axes)"),
      output("e_dot", IecType::LREAL).unit("rad/s").doc("own error rate used"),
      output("E", IecType::LREAL).unit("rad").doc("coupled error E_k (eq. 5)"),
      output("eps", IecType::LREAL).unit("rad")
          .doc("synchronization error eps_k = e_k - mean of the preceding errors (eq. 7)"),
      output("saturated", IecType::BOOL).doc("TRUE when the output limit cut tau"),
      output("estimated", IecType::UDINT).doc("preceding-axis samples filled by the estimator since start"),
  };
  t.params = {
      parameter("axis", IecType::DINT).min(1.0).max(kMaxSyncAxes).doc("this axis, k (1-based)"),
      parameter("n", IecType::DINT).min(1.0).max(kMaxSyncAxes)
          .doc("number of synchronized axes (length of e_rx, e_valid)"),
      parameter("alpha", IecType::LREAL).init("1.3").min(0.0).doc("coupling gain kappa (alpha = kappa I)"),
      parameter("K_P", IecType::LREAL).init("0.6221").min(0.0).unit("PWM/rad").tunable().doc("proportional gain"),
      parameter("K_D", IecType::LREAL).init("0.0006221").min(0.0).unit("PWM.s/rad").tunable()
          .doc("derivative gain on E_dot (paper: 0.6221 PWM.ms/rad)"),
      parameter("K_H", IecType::LREAL).init("0.001544").min(0.0).unit("PWM.s^2/rad").tunable()
          .doc("acceleration feed-forward (paper's value, printed with ms^2, is SI: tau_1/k_1)"),
      parameter("K_C", IecType::LREAL).init("0.02807").min(0.0).unit("PWM.s/rad").tunable()
          .doc("velocity feed-forward (paper's value, printed with ms, is SI: 1/k_1)"),
      parameter("m", IecType::LREAL).init("0.2586268").min(0.0).unit("PWM.s/rad")
          .doc("own-error damping m (K_e = m(I + alpha T'), eq. 10; paper: 258.6268 PWM.ms/rad)"),
      parameter("robust", IecType::INT).init("2").min(0.0).max(2.0)
          .doc("robust term: 0 = K_N sign(E_dot) (paper), 1 = eq. (9) K_N(t) sign(E_dot), 2 = K_N sat(E_dot/phi)"),
      parameter("K_N", IecType::LREAL).init("10").min(0.0).unit("PWM").tunable().doc("robust gain (robust 0 and 2)"),
      parameter("Delta_H", IecType::LREAL).init("0").min(0.0).unit("PWM.s^2/rad").tunable()
          .doc("eq. (9) bound on the model error: Delta_H >= norm(K_H - H) (robust 1)"),
      parameter("Delta_C", IecType::LREAL).init("0").min(0.0).unit("PWM.s/rad").tunable()
          .doc("eq. (9) bound on the model error: Delta_C >= norm(K_C - C) (robust 1)"),
      parameter("phi", IecType::LREAL).init("100").min(0.0).unit("rad/s").tunable()
          .doc("boundary-layer width on E_dot (robust 2)"),
      parameter("out_min", IecType::LREAL).init("-1").unit("PWM").tunable().doc("lower output limit"),
      parameter("out_max", IecType::LREAL).init("1").unit("PWM").tunable().doc("upper output limit"),
      parameter("compensation", IecType::BOOL).init("TRUE")
          .doc("predict the preceding errors one scan ahead (eq. 15); FALSE: use e_i(j-1) as is"),
      parameter("rx_delay", IecType::INT).init("1").min(0.0).max(1.0)
          .doc("scans by which e_rx lags: 1 = network (eq. 13), 0 = current values (no prediction)"),
  };
  t.create = make_sync;
  t.rewire = true;  // SyncController::rewire_from
  r.add(std::move(t));
}

}  // namespace syncplc::motion
