// NONLINEAR_FILTER: the velocity/acceleration-limited discrete-time nonlinear
// filter of paper 004 (C. Guarino Lo Bianco, "An efficient algorithm for the
// real-time generation of synchronous reference signals"), Section II,
// eqs. (1)-(22) — the filter of the paper's reference [21] — with the
// transient-time prediction of its Table I. The controller C, which the paper
// does not print, and the corrections of Table I are derived in
// docs/motion/nonlinear-filter.md; the math lives in nonlinear_filter_math.*.
//
// Per scan k (T = the task period, the filter's sampling time):
//   outputs   x_k, xdot_k (the filter state at sample k), xddot = u_k,
//             tracking = state within the tracking tolerance of (r_k, rdot_k),
//             steps_to_go = Table I prediction from sample k (-1: never);
//   then      state_{k+1} = plant_step(state_k, u_k, T) (eqs. 1-2).
// A change of r at scan k shows in xddot at scan k and in x from scan k+1.
// After skipped releases (an overrun), the scan first advances the missed
// samples so that x stays the trajectory at the scan's planned release time.
#include <cmath>

#include "fblocks/motion/motion.hpp"
#include "fblocks/motion/nonlinear_filter_math.hpp"
#include "runtime/core/pin_decl.hpp"

namespace syncplc::motion {
namespace {

enum : int {
  kR = 0,
  kRDot,
  kVMin,
  kVMax,
  kAMin,
  kAMax,
  kReset,
  kX0,
  kV0,
  kX,
  kXDot,
  kXDDot,
  kTracking,
  kStepsToGo,
  kError,
};

class NonlinearFilter final : public Block {
 public:
  explicit NonlinearFilter(BlockSetup& s)
      : derive_r_dot_(!s.connected(kRDot)),
        start_at_r_(s.param<bool>("start_at_r")),
        period_s_(static_cast<double>(s.task_period_ns()) * 1e-9) {}

  // r_prev_ is kept whichever way r_dot comes, so a derived r_dot is right
  // from the first scan after an online change unwires it.
  // And the sampling time of a re-timed task: the state (x, x_dot) goes on
  // at the new period (the next scan's dt is the time since the last one).
  void rewire_from(const Block& fresh) noexcept override {
    const auto& f = static_cast<const NonlinearFilter&>(fresh);
    derive_r_dot_ = f.derive_r_dot_;
    period_s_ = f.period_s_;
  }

  void execute(ScanContext& ctx) noexcept override {
    const double T = period_s_;
    const double dt = ctx.dt_ns > 0 ? static_cast<double>(ctx.dt_ns) * 1e-9 : T;
    const double r = in<double>(kR);
    double r_dot = 0;
    if (!derive_r_dot_) r_dot = in<double>(kRDot);
    else if (have_r_prev_) r_dot = (r - r_prev_) / dt;
    r_prev_ = r;
    have_r_prev_ = true;
    const Reference ref{r, r_dot};
    const FilterBounds b{in<double>(kVMin), in<double>(kVMax), in<double>(kAMin), in<double>(kAMax)};
    const bool ref_ok = std::isfinite(r) && std::isfinite(r_dot);
    const bool bounds_ok = bounds_valid(b);
    const bool valid = ref_ok && bounds_ok;
    const bool hold = in<bool>(kReset);
    if (valid) {
      faulting_ = false;
      last_ = b;
      have_last_ = true;
    } else if (!faulting_) {  // one event per series of invalid scans
      if (!bounds_ok) ctx.fault("NONLINEAR_FILTER: invalid bounds (need finite v_min < v_max, a_min < 0 < a_max)");
      else ctx.fault("NONLINEAR_FILTER: non-finite r or r_dot", r);
      faulting_ = true;
    }

    if (first_) {
      first_ = false;
      if (start_at_r_ && ref_ok) state_ = {r, r_dot};
      else start_from_inputs(ctx);
    } else if (!hold) {
      // Skipped releases (dt = n periods): advance the n - 1 missed samples
      // with this scan's inputs, r taken as a ramp backwards, so that x stays
      // on the time grid and every sample keeps the bounds.
      const double n = std::round(dt / T);
      const int missed = n > 1 ? static_cast<int>(std::fmin(n - 1, double{kMaxCatchUp})) : 0;
      for (int j = missed; j >= 1; --j) {
        const Reference past{r - j * T * r_dot, r_dot};
        state_ = plant_step(state_, acceleration(past, b, valid, T), T);
      }
    }
    if (hold) start_from_inputs(ctx);

    if (!valid) {
      const double u = hold ? 0.0 : acceleration(ref, b, false, T);
      publish(u, false, kNever, true);
      if (!hold) state_ = plant_step(state_, u, T);
      return;
    }
    const ZBounds zb = z_bounds(b, r_dot, T);
    const ZState z = to_z(state_, ref, T);
    const double u = hold ? 0.0 : control(z, zb);
    publish(u, is_tracking(z, zb), transient_steps(z, zb), false);
    if (!hold) state_ = plant_step(state_, u, T);
  }

 private:
  void start_from_inputs(ScanContext& ctx) {
    const double x0 = in<double>(kX0);
    const double v0 = in<double>(kV0);
    if (std::isfinite(x0) && std::isfinite(v0)) {
      state_ = {x0, v0};
    } else if (!init_fault_) {
      ctx.fault("NONLINEAR_FILTER: non-finite x0 or v0, state kept");
      init_fault_ = true;
      return;
    }
    init_fault_ = false;
  }

  // The filter's acceleration from the present state: controller C, or with
  // invalid inputs a stop with the last valid acceleration bounds (at once if
  // there never were any).
  double acceleration(const Reference& ref, const FilterBounds& b, bool valid, double T) const noexcept {
    if (valid) return control(to_z(state_, ref, T), z_bounds(b, ref.v, T));
    double u = -state_.v / T;
    if (have_last_) u = u > last_.a_max ? last_.a_max : (u < last_.a_min ? last_.a_min : u);
    return u;
  }

  void publish(double u, bool tracking, std::int64_t steps, bool error) {
    out<double>(kX, state_.x);
    out<double>(kXDot, state_.v);
    out<double>(kXDDot, u);
    out<bool>(kTracking, tracking);
    out<std::int64_t>(kStepsToGo, steps);
    out<bool>(kError, error);
  }

  bool derive_r_dot_;  // r_dot unconnected (rewire_from: an online change may connect it)
  const bool start_at_r_;
  double period_s_;  // the task period (rewire_from: a re-timed task)
  FilterState state_{};
  FilterBounds last_{};
  double r_prev_ = 0;
  bool have_r_prev_ = false;
  bool have_last_ = false;
  bool first_ = true;
  bool faulting_ = false;
  bool init_fault_ = false;
};

}  // namespace

void register_nonlinear_filter(BlockRegistry& r) {
  BlockTypeInfo t;
  t.name = "NONLINEAR_FILTER";
  t.category = kCategory;
  t.doc =
      "Velocity- and acceleration-limited discrete-time nonlinear filter (paper 004, Section II): turns a "
      "rough reference r (steps and ramps) into a smooth x with v_min <= x_dot <= v_max and "
      "a_min <= x_ddot <= a_max, reaching r in minimum time (a step without overshoot), and predicts how many scans "
      "that takes (Table I). Bounds are inputs and may change at any scan; asymmetric bounds are allowed.\n\n"
      "Plant (eqs. 1-2), T the task period: x' = x + T x_dot + T^2/2 u, x_dot' = x_dot + T u. "
      "Coordinates (eqs. 5-8): y = x - r, z1 = y1/T^2 + y2/(2T), z2 = y2/T, so z1' = z1 + z2 + u, z2' = z2 + u "
      "while r is a ramp. Velocity bounds in z: z2+ = (v_max - r_dot)/T, z2- = (v_min - r_dot)/T. "
      "Controller C (derived; the paper does not print it): for z1 < 0, Ub = -a_min, a = -z1/Ub, "
      "m = smallest N >= 2 with N(N-1)/2 >= a (eq. 11), target w = Ub (a/(m-1) + (m-2)/2); for z1 > 0 the "
      "mirror image with Ub = a_max and w negative; w = 0 at z1 = 0. Then w_t = clamp(w, z2-, z2+) and "
      "u = clamp(w_t - z2, a_min, a_max), a value beyond a bound by at most 1e-7 max(a_max, -a_min) being "
      "applied as is. Inside the boundary layer the velocity falls by Ub per scan and z reaches 0 after m "
      "scans; where w is cut by a velocity bound the filter cruises on the bound.\n\n"
      "Outputs at scan k are the filter state at sample k and the acceleration u_k applied from it; a change "
      "of r therefore moves x from the next scan on. tracking: abs(z1), abs(z2) <= 1e-6 max(a_max, -a_min). "
      "steps_to_go: scans until tracking with the present bounds and r continuing as a ramp of slope r_dot "
      "(Table I with the corrections of docs/motion/nonlinear-filter.md; it counts down by one per scan); "
      "-1 when r_dot is outside [v_min, v_max], where the output runs at the velocity bound and never tracks. "
      "r_dot, when not connected, is (r_k - r_(k-1)) divided by the time between the scans, 0 on the first "
      "scan: a step of r then looks like a one-scan ramp and may overshoot, so give r_dot: 0 for a reference made of "
      "steps only. A velocity beyond a newly reduced bound is braked at "
      "the full acceleration bound first. A scan that follows skipped releases (an overrun) first advances the "
      "missed samples (up to 10000) with its inputs, r taken as a ramp backwards, so x stays on the time grid. "
      "Start: at x = r, x_dot = r_dot (start_at_r TRUE) or at (x0, v0); reset TRUE holds the filter at "
      "(x0, v0) with x_ddot = 0. A NaN or infinite input is the finite-input rule's (see ENO): the filter "
      "does not execute and its outputs hold. Inconsistent bounds (v_min >= v_max, a_min >= 0 or a_max <= 0) "
      "raise one block-fault event per series of invalid scans, set error, tracking FALSE "
      "and steps_to_go -1, and stop the output with the last valid acceleration bounds (at once if there "
      "never were valid bounds), holding position once stopped.";
  t.reference =
      "C. Guarino Lo Bianco, \"An efficient algorithm for the real-time generation of synchronous reference "
      "signals\" (paper 004), Section II, eqs. (1)-(22), Fig. 3, Table I; filter of its ref. [21] "
      "(Guarino Lo Bianco and Wahl, ICRA 2011); controller and Table I corrections in "
      "docs/motion/nonlinear-filter.md";
  t.pins = {
      input("r", IecType::LREAL).unit("m").required().doc("reference position (steps and ramps)"),
      input("r_dot", IecType::LREAL).unit("m/s")
          .doc("reference velocity; when not connected, derived as (r_k - r_(k-1))/T (0 on the first scan); give 0 for "
               "steps only"),
      input("v_min", IecType::LREAL).unit("m/s").required().doc("lower velocity bound (xdot-), below v_max"),
      input("v_max", IecType::LREAL).unit("m/s").required().doc("upper velocity bound (xdot+), above v_min"),
      input("a_min", IecType::LREAL).unit("m/s^2").required().doc("lower acceleration bound (U-), negative"),
      input("a_max", IecType::LREAL).unit("m/s^2").required().doc("upper acceleration bound (U+), positive"),
      input("reset", IecType::BOOL).doc("while TRUE the filter is held at x = x0, x_dot = v0 (x_ddot = 0)"),
      input("x0", IecType::LREAL).unit("m")
          .doc("start position for reset (and the first scan when start_at_r is FALSE)"),
      input("v0", IecType::LREAL).unit("m/s")
          .doc("start velocity for reset (and the first scan when start_at_r is FALSE)"),
      output("x", IecType::LREAL).unit("m").doc("filtered position at this scan"),
      output("x_dot", IecType::LREAL).unit("m/s").doc("filtered velocity at this scan"),
      output("x_ddot", IecType::LREAL).unit("m/s^2").doc("acceleration applied from this scan to the next"),
      output("tracking", IecType::BOOL).doc("TRUE when x and x_dot equal r and r_dot (within the tolerance)"),
      output("steps_to_go", IecType::LINT)
          .doc("scans until tracking with the present bounds and r as a ramp (0 when tracking, -1 never)"),
      output("error", IecType::BOOL).doc("TRUE while the bounds or the reference are invalid"),
  };
  t.params = {
      parameter("start_at_r", IecType::BOOL).init("TRUE")
          .doc("TRUE: the first scan starts at x = r, x_dot = r_dot (tracking at once); FALSE: at (x0, v0)"),
  };
  t.rewire = true;  // NonlinearFilter::rewire_from: r_dot connected or disconnected online
  t.create = [](BlockSetup& s) -> std::unique_ptr<Block> { return std::make_unique<NonlinearFilter>(s); };
  r.add(std::move(t));
}

}  // namespace syncplc::motion
