// PD_CONTROLLER: the uncoupled baseline of paper 000 (section 5, "an uncoupled
// controller with only a standard PD position loop"), τ = K_P e + K_D ė, with
// the gain conventions and SI units of SYNC_CONTROLLER, so a comparison of the
// two changes only the controller.
//
// PID: a general standard-form PID (in the manner of CODESYS PID and TwinCAT
// FB_CTRL_PID), discretized as in Åström & Hägglund, "Advanced PID Control"
// (2006), section 3.6 / 13.4 (backward-difference derivative with a
// first-order filter, integral updated after the output, anti-windup by
// conditional integration or by back-calculation with tracking time Tt).
// See docs/motion/pid.md.
#include <cmath>
#include <memory>

#include "fblocks/motion/motion.hpp"
#include "fblocks/motion/param_read.hpp"
#include "fblocks/motion/sync_control_math.hpp"
#include "runtime/core/pin_decl.hpp"

namespace syncplc::motion {
namespace {

// ---- PD_CONTROLLER ----------------------------------------------------------

enum : int { kPdXd = 0, kPdVd, kPdX, kPdV, kPdTau, kPdE, kPdEdot, kPdSat };

// Parameter indices (declaration order in register_pid_controllers).
enum : int { kPdKp = 0, kPdKd, kPdOutMin, kPdOutMax };

class PdController final : public Block {
 public:
  PdController(double kp, double kd, double lo, double hi, bool use_v)
      : kp_(kp), kd_(kd), lo_(lo), hi_(hi), use_v_(use_v) {}

  // Memoryless in its gains (the state is e(j-1) only): a new gain or limit
  // acts from the next scan, nothing to rescale.
  void retune_from(const Block& fresh) noexcept override {
    const auto& f = static_cast<const PdController&>(fresh);
    kp_ = f.kp_, kd_ = f.kd_, lo_ = f.lo_, hi_ = f.hi_;
  }
  // v connected or disconnected by an online change (e(j-1) is kept either way).
  void rewire_from(const Block& fresh) noexcept override { use_v_ = static_cast<const PdController&>(fresh).use_v_; }
  bool tune(int param, double v) noexcept override {
    switch (param) {
      case kPdKp: kp_ = v; return true;
      case kPdKd: kd_ = v; return true;
      case kPdOutMin: if (!(v < hi_)) return false; lo_ = v; return true;
      case kPdOutMax: if (!(lo_ < v)) return false; hi_ = v; return true;
    }
    return false;
  }

  void execute(ScanContext& ctx) noexcept override {
    const double e = in<double>(kPdXd) - in<double>(kPdX);
    double ed;
    if (use_v_) {
      ed = in<double>(kPdVd) - in<double>(kPdV);
    } else {
      ed = first_ ? 0.0 : backward_difference(e, e_prev_, ctx.dt_ns);
    }
    e_prev_ = e;  // also with v: an online change that unwires v differentiates from the right e(j-1)
    first_ = false;
    bool clipped = false;
    const double tau = limit(kp_ * e + kd_ * ed, lo_, hi_, &clipped);
    out<double>(kPdTau, tau);
    out<double>(kPdE, e);
    out<double>(kPdEdot, ed);
    out<bool>(kPdSat, clipped);
  }

 private:
  double kp_, kd_, lo_, hi_;
  bool use_v_;
  bool first_ = true;
  double e_prev_ = 0;
};

std::unique_ptr<Block> make_pd(BlockSetup& s) {
  bool ok = true;
  const double kp = ctl::real_param(s, "K_P", &ok);
  const double kd = ctl::real_param(s, "K_D", &ok);
  const double lo = ctl::real_param(s, "out_min", &ok);
  const double hi = ctl::real_param(s, "out_max", &ok);
  if (ok && !(lo < hi)) {
    s.error(s.type().name + ": out_min must be less than out_max");
    ok = false;
  }
  if (!ok) return nullptr;
  return std::make_unique<PdController>(kp, kd, lo, hi, s.connected(kPdV));
}

// ---- PID --------------------------------------------------------------------

enum : int {
  kSp = 0, kPv, kFf, kManual, kManualValue, kPidReset,  // inputs
  kY, kErr, kSat,                                     // outputs
};

enum class AntiWindup : int { None = 0, Clamping = 1, BackCalculation = 2 };

// Parameter indices (declaration order in register_pid_controllers).
enum : int { kPKp = 0, kPTi, kPTd, kPTf, kPTt, kPAntiWindup, kPDOnError, kPOutMin, kPOutMax };

struct PidConfig {
  double kp = 1, ti = 0, td = 0, tf = 0, tt = 0, lo = -1, hi = 1;
  double tt_param = 0;  // Tt as given (0: derived from Ti and Td, see effective_tt)
  AntiWindup aw = AntiWindup::Clamping;
  bool d_on_error = false;
};

// Tt = 0 means sqrt(Ti Td) if Td > 0, else Ti (Astrom & Hagglund 3.5).
inline double effective_tt(const PidConfig& c) {
  return c.tt_param > 0 ? c.tt_param : (c.td > 0 ? std::sqrt(c.ti * c.td) : c.ti);
}

class Pid final : public Block {
 public:
  explicit Pid(const PidConfig& c) : c_(c) {}

  // Bumpless parameter change (Astrom & Hagglund, Advanced PID Control, 3.5
  // "Bumpless parameter changes"): the integral part is stored as the
  // integral of Kp/Ti e (integral_, in output units) and the filtered
  // derivative as its output D (d_), so a new Kp, Ti, Td or Tf leaves both as
  // they are and y does not jump; only the P part follows Kp e, which is 0 in
  // steady state. Limits act from the next scan.
  void retune_from(const Block& fresh) noexcept override { apply(static_cast<const Pid&>(fresh).c_); }
  bool tune(int param, double v) noexcept override {
    PidConfig n = c_;
    switch (param) {
      case kPKp: n.kp = v; break;
      case kPTi: n.ti = v; break;
      case kPTd: n.td = v; break;
      case kPTf: n.tf = v; break;
      case kPTt: n.tt_param = v; break;
      case kPOutMin: n.lo = v; break;
      case kPOutMax: n.hi = v; break;
      default: return false;
    }
    if (!(n.lo < n.hi)) return false;
    apply(n);
    return true;
  }

  void execute(ScanContext& ctx) noexcept override {
    const double h = ctx.dt_ns > 0 ? static_cast<double>(ctx.dt_ns) * 1e-9 : 0.0;
    const double e = in<double>(kSp) - in<double>(kPv);
    const double s = c_.d_on_error ? e : -in<double>(kPv);  // the signal the D term differentiates
    const double ff = in<double>(kFf);
    if (first_) {
      s_prev_ = s;  // no derivative kick on the first scan
      first_ = false;
    }
    bool clipped = false;
    if (in<bool>(kPidReset)) {
      integral_ = 0;
      d_ = 0;
      s_prev_ = s;
      out<double>(kY, limit(0.0, c_.lo, c_.hi, &clipped));
      out<double>(kErr, e);
      out<bool>(kSat, clipped);
      return;
    }
    // D: Kp·Td·s / (Tf·s + 1) on `s`, backward difference.
    if (h > 0) {
      d_ = (c_.tf * d_ + c_.kp * c_.td * (s - s_prev_)) / (c_.tf + h);
    }
    s_prev_ = s;
    const double p = c_.kp * e;
    if (in<bool>(kManual)) {
      const double y = limit(in<double>(kManualValue), c_.lo, c_.hi, &clipped);
      integral_ = y - p - d_ - ff;  // tracking: the first automatic scan continues from y
      out<double>(kY, y);
      out<double>(kErr, e);
      out<bool>(kSat, clipped);
      return;
    }
    const double v = p + integral_ + d_ + ff;
    const double y = limit(v, c_.lo, c_.hi, &clipped);
    if (c_.ti > 0 && h > 0) {
      const double inc = c_.kp * h / c_.ti * e;
      switch (c_.aw) {
        case AntiWindup::None: integral_ += inc; break;
        case AntiWindup::Clamping:
          // Conditional integration: hold the integral while the output is
          // beyond a limit and integrating would push it further out.
          if (!((v > c_.hi && inc > 0) || (v < c_.lo && inc < 0))) integral_ += inc;
          break;
        case AntiWindup::BackCalculation: integral_ += inc + h / c_.tt * (y - v); break;
      }
    }
    out<double>(kY, y);
    out<double>(kErr, e);
    out<bool>(kSat, clipped);
  }

  // Retained (docs/store.md, "Retained block instances"): the integral part,
  // in output units, so a loop restarted at its operating point continues
  // from the bias it had learnt instead of winding up again from 0 (the
  // bumpless restart of Astrom & Hagglund 3.5). The derivative filter is not
  // kept: it describes a signal of a run that ended, and the first scan
  // after the start takes no derivative (first_).
  std::uint32_t retain_cells() const noexcept override { return 1; }
  void save_retain(Cell* out) const noexcept override { out[0].set<double>(integral_); }
  void load_retain(const Cell* in) noexcept override {
    const double i = in[0].get<double>();
    if (std::isfinite(i)) integral_ = i;
  }

 private:
  // The tunable values of `n`; the structure (anti_windup, d_on_error) stays.
  void apply(const PidConfig& n) noexcept {
    c_.kp = n.kp, c_.ti = n.ti, c_.td = n.td, c_.tf = n.tf, c_.tt_param = n.tt_param;
    c_.lo = n.lo, c_.hi = n.hi;
    c_.tt = effective_tt(c_);
  }

  PidConfig c_;
  bool first_ = true;
  double integral_ = 0;  // integral part (or, with Ti = 0, a bias set by manual tracking)
  double d_ = 0;         // filtered derivative part
  double s_prev_ = 0;
};

std::unique_ptr<Block> make_pid(BlockSetup& s) {
  bool ok = true;
  PidConfig c;
  c.kp = ctl::real_param(s, "Kp", &ok);
  c.ti = ctl::real_param(s, "Ti", &ok);
  c.td = ctl::real_param(s, "Td", &ok);
  c.tf = ctl::real_param(s, "Tf", &ok);
  c.tt_param = ctl::real_param(s, "Tt", &ok);
  c.lo = ctl::real_param(s, "out_min", &ok);
  c.hi = ctl::real_param(s, "out_max", &ok);
  c.aw = static_cast<AntiWindup>(ctl::int_param(s, "anti_windup", &ok));
  c.d_on_error = ctl::bool_param(s, "d_on_error");
  if (ok && !(c.lo < c.hi)) {
    s.error(s.type().name + ": out_min must be less than out_max");
    ok = false;
  }
  if (!ok) return nullptr;
  c.tt = effective_tt(c);
  return std::make_unique<Pid>(c);
}

}  // namespace

void register_pid_controllers(BlockRegistry& r) {
  {
    BlockTypeInfo t;
    t.name = "PD_CONTROLLER";
    t.category = kCategory;
    t.doc =
        "Uncoupled PD position controller, the baseline of paper 000: e = x_d - x, e_dot = v_d - v when v is "
        "connected, else the backward difference (e(j) - e(j-1))/T_s (0 on the first scan), "
        "tau = LIMIT(out_min, K_P e + K_D e_dot, out_max); saturated is TRUE when the limit cut tau. Same pins, "
        "gain conventions and SI units as SYNC_CONTROLLER, so swapping the two changes only the controller. "
        "Defaults are the paper's section 5 gains in SI (K_D printed 0.6221 PWM.ms/rad = 0.0006221 PWM.s/rad). "
        "Gains and limits are tunable while running (online change or the <param>_in inputs); the law holds no "
        "integral, so a new gain acts from the next scan.";
    t.reference = "Xu et al., ISA Transactions 2017 (paper 000), section 5: standard PD baseline";
    t.pins = {
        input("x_d", IecType::LREAL).unit("rad").required().doc("desired position"),
        input("v_d", IecType::LREAL).unit("rad/s").doc("desired velocity (used with v)"),
        input("x", IecType::LREAL).unit("rad").required().doc("measured position"),
        input("v", IecType::LREAL).unit("rad/s")
            .doc("measured velocity; unconnected: e_dot is the backward difference of e"),
        output("tau", IecType::LREAL).unit("PWM").doc("command, limited to out_min..out_max"),
        output("e", IecType::LREAL).unit("rad").doc("position error x_d - x"),
        output("e_dot", IecType::LREAL).unit("rad/s").doc("error rate used"),
        output("saturated", IecType::BOOL).doc("TRUE when the output limit cut tau"),
    };
    t.params = {
        parameter("K_P", IecType::LREAL).init("0.6221").min(0.0).unit("PWM/rad").tunable().doc("proportional gain"),
        parameter("K_D", IecType::LREAL).init("0.0006221").min(0.0).unit("PWM.s/rad").tunable().doc("derivative gain"),
        parameter("out_min", IecType::LREAL).init("-1").unit("PWM").tunable().doc("lower output limit"),
        parameter("out_max", IecType::LREAL).init("1").unit("PWM").tunable().doc("upper output limit"),
    };
    t.create = make_pd;
    t.rewire = true;  // PdController::rewire_from
    r.add(std::move(t));
  }
  {
    BlockTypeInfo t;
    t.name = "PID";
    t.category = kCategory;
    t.doc =
        "Standard-form PID with output limits, anti-windup, feed-forward, manual mode with bumpless transfer and "
        "reset. Per scan (h = time since the previous scan): error = setpoint - actual; P = Kp error; "
        "D = (Tf D + Kp Td (s - s_prev)) / (Tf + h), the backward difference of Kp Td s/(Tf s + 1), where "
        "s = -actual (derivative on measurement, default: no setpoint kick) or s = error (d_on_error); "
        "v = P + I + D + ff; y = LIMIT(out_min, v, out_max). The integral part I is updated after the output: "
        "I += Kp h/Ti error (Ti = 0: no integral action, I stays a constant bias), with anti_windup 0 = none, "
        "1 = clamping (conditional integration: no increment while v is beyond a limit and the increment points "
        "further out), 2 = back-calculation (I += Kp h/Ti error + h/Tt (y - v)). manual: y = "
        "LIMIT(out_min, manual_value, out_max) and I tracks y - P - D - ff, so the return to automatic is "
        "bumpless. reset (priority over manual): I = D = 0, y = LIMIT(out_min, 0, out_max). Gains, times and "
        "limits are tunable while running (online change or the <param>_in inputs): I is kept as the "
        "integral of Kp/Ti error and D as its filtered output, so a change does not bump y (in steady state "
        "not at all; otherwise only P follows Kp error). A retain or persistent instance keeps I over a restart "
        "(the derivative filter starts afresh, with no derivative on the first scan).";
    t.reference =
        "Astrom & Hagglund, Advanced PID Control (ISA 2006), sections 3.5-3.6 and 13.4; behaviour as CODESYS "
        "PID / TwinCAT FB_CTRL_PID";
    t.pins = {
        input("setpoint", IecType::LREAL).required().doc("setpoint"),
        input("actual", IecType::LREAL).required().doc("actual (measured) value"),
        input("ff", IecType::LREAL).doc("feed-forward, added to the controller output before the limit"),
        input("manual", IecType::BOOL).doc("TRUE: manual mode, y = manual_value"),
        input("manual_value", IecType::LREAL).doc("output in manual mode"),
        input("reset", IecType::BOOL).doc("TRUE: clear the integral and derivative parts, y = 0 (limited)"),
        output("y", IecType::LREAL).doc("controller output, limited to out_min..out_max"),
        output("error", IecType::LREAL).doc("setpoint - actual"),
        output("saturated", IecType::BOOL).doc("TRUE when the output limit cut y"),
    };
    t.params = {
        parameter("Kp", IecType::LREAL).init("1").tunable().doc("proportional gain (negative for reverse action)"),
        parameter("Ti", IecType::LREAL).init("0").min(0.0).unit("s").tunable()
            .doc("integral time; 0 = no integral action"),
        parameter("Td", IecType::LREAL).init("0").min(0.0).unit("s").tunable()
            .doc("derivative time; 0 = no derivative action"),
        parameter("Tf", IecType::LREAL).init("0").min(0.0).unit("s").tunable()
            .doc("derivative filter time constant (typically Td/10); 0 = unfiltered"),
        parameter("Tt", IecType::LREAL).init("0").min(0.0).unit("s").tunable()
            .doc("back-calculation tracking time; 0 = sqrt(Ti Td) if Td > 0, else Ti"),
        parameter("anti_windup", IecType::INT).init("1").min(0.0).max(2.0)
            .doc("0 = none, 1 = clamping (conditional integration), 2 = back-calculation"),
        parameter("d_on_error", IecType::BOOL).init("FALSE")
            .doc("FALSE: derivative of -actual (no kick on setpoint steps); TRUE: derivative of the error"),
        parameter("out_min", IecType::LREAL).init("-100").tunable().doc("lower output limit"),
        parameter("out_max", IecType::LREAL).init("100").tunable().doc("upper output limit"),
    };
    t.create = make_pid;
    r.add(std::move(t));
  }
}

}  // namespace syncplc::motion
