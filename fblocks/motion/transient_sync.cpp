// TRANSIENT_SYNC: n velocity/acceleration-limited nonlinear filters whose
// velocity bounds are rescaled every scan so that all transients end on the
// same scan, and the energy index E of their transients. Paper 004
// (C. Guarino Lo Bianco, "An efficient algorithm for the real-time generation
// of synchronous reference signals"), Section III, eqs. (23)-(34), with the
// corrections and the "unified" rule derived in docs/motion/transient-sync.md
// (sections 1 and 2, "Every scan").
//
// The filters are those of NONLINEAR_FILTER (nonlinear_filter_math.hpp: the
// controller C and the Table I transient-time prediction); the bound scaling is
// in transient_sync_math.hpp. Per scan k, T = the task period (the filters'
// sampling time), for every axis i:
//   1. n_i = Table I steps from sample k with the nominal bounds (-1: never);
//      t_M = the largest finite n_i.
//   2. nominal bounds if: rule off, tracking, cannot track, n_i = t_M (the
//      slowest), or in the final approach of the reduced bound it ran on at
//      scan k-1 (a simpler reading judges the final approach with the bounds
//      applied at the previous scan; after nominal bounds that would also
//      exempt a small transient that starts in the curved layer, which then
//      arrives early, so only reduced bounds count);
//   3./4. otherwise the velocity bound scaled by eq. (33) (ends behind the
//      reference) or (34) (ends ahead) with tf = t_M T: unified rule, side
//      from the discrete stopping point (transient_sync_math.hpp), or the
//      paper's sign-of-rdot rule with zero-bound parking;
//   5. look-ahead guard: the reduced bound is kept only if the nominal
//      transient time of the resulting state k+1 is at most t_M - 1 (that
//      prediction is reused as n_i at scan k+1 when the inputs are exactly the
//      ones it assumed);
//   6. outputs at sample k, then state_{k+1} = plant_step(state_k, u_k, T).
// After skipped releases (an overrun) the scan first runs the missed samples
// (filters and synchronizer) with its inputs, r taken as a ramp backwards, so
// x stays on the time grid, as NONLINEAR_FILTER does.
// Everything is recomputed every scan, except values whose inputs are the
// same bit for bit (nominal z-bounds, the guard's prediction, next state and
// reduced z-bounds), which are reused: the outputs are exactly those of the
// full recomputation (tests/motion/test_motion_output_hash.cpp). execute()
// allocates nothing.
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <memory>
#include <string>
#include <type_traits>
#include <vector>

#include "fblocks/motion/motion.hpp"
#include "fblocks/motion/nonlinear_filter_math.hpp"
#include "fblocks/motion/transient_sync_math.hpp"
#include "runtime/core/pin_decl.hpp"

namespace syncplc::motion {
namespace {

enum : int {
  // array inputs
  kR = 0,
  kRDot,
  kVMin,
  kVMax,
  kAMin,
  kAMax,
  kX0,
  kV0,
  // scalar input
  kReset,
  // array outputs
  kX,
  kXDot,
  kXDDot,
  kVMinApplied,
  kVMaxApplied,
  kTracking,
  kStepsToGo,
  kError,
  // scalar outputs
  kArrival,
  kSynchronized,
  kScaled,
  kEnergy,
  kEnergyLast,
  kWindows,
  kWindowScans,
  kSpread,
};

inline constexpr std::int64_t kMaxAxes = 1024;

class TransientSync final : public Block {
 public:
  explicit TransientSync(BlockSetup& s)
      : n_(static_cast<std::uint32_t>(s.param<std::int32_t>("n"))),
        rule_(static_cast<SyncRule>(s.param<std::int32_t>("rule"))),
        derive_r_dot_(!s.connected(kRDot)),
        start_at_r_(s.param<bool>("start_at_r")),
        period_s_(static_cast<double>(s.task_period_ns()) * 1e-9),
        x_(n_), v_(n_), r_prev_(n_), vmin_prev_(n_), vmax_prev_(n_), nom_(n_), last_(n_), rin_(n_), z_(n_),
        pb_(n_), pb_key_(n_), zs_(n_), zs_key_(n_), ref_(n_), steps_(n_), arrival_(n_), flags_(n_), pred_(n_) {}

  void execute(ScanContext& ctx) noexcept override {
    const double T = period_s_;  // the filters' sampling time
    const double dt = ctx.dt_ns > 0 ? static_cast<double>(ctx.dt_ns) * 1e-9 : T;
    const bool first = first_;
    first_ = false;
    const bool hold = in<bool>(kReset);

    // Inputs, validity, start.
    int faults = 0;
    for (std::uint32_t i = 0; i < n_; ++i) {
      const double r = in<double>(kR, i);
      double r_dot = 0;
      if (!derive_r_dot_) r_dot = in<double>(kRDot, i);
      else if (!first) r_dot = (r - r_prev_[i]) / dt;
      r_prev_[i] = r;
      const FilterBounds b{in<double>(kVMin, i), in<double>(kVMax, i), in<double>(kAMin, i), in<double>(kAMax, i)};
      std::uint16_t f = flags_[i];
      if (std::isfinite(r) && std::isfinite(r_dot) && bounds_valid(b)) {
        f = static_cast<std::uint16_t>((f & ~kFaulting) | kValid | kHaveLast);
        last_[i] = b;
        if (first) {  // nothing was applied before: the nominal bounds
          vmin_prev_[i] = b.v_min;
          vmax_prev_[i] = b.v_max;
        }
      } else if (!(f & kFaulting)) {
        f |= kFaulting;
        ++faults;
      }
      if (first) {
        if (start_at_r_ && std::isfinite(r) && std::isfinite(r_dot)) {
          x_[i] = r;
          v_[i] = r_dot;
        } else {
          start_from_inputs(i);
        }
      }
      rin_[i] = Reference{r, r_dot};
      nom_[i] = b;
      flags_[i] = f;
    }
    if (faults > 0)
      ctx.fault("TRANSIENT_SYNC: invalid bounds or non-finite reference on an axis (count in value)",
                static_cast<double>(faults));
    if (!first && !hold) {
      // Skipped releases (dt = n periods): run the n - 1 missed samples with
      // this scan's inputs, r taken as a ramp backwards, so that x stays on the
      // time grid (as NONLINEAR_FILTER does).
      const double periods = std::round(dt / T);
      const int missed = periods > 1 ? static_cast<int>(std::fmin(periods - 1, double{kMaxCatchUp})) : 0;
      for (int j = missed; j >= 1; --j) sample(T, static_cast<double>(j), false, false);
    }
    if (hold)
      for (std::uint32_t i = 0; i < n_; ++i) start_from_inputs(i);
    sample(T, 0, true, hold);
    for (std::uint32_t i = 0; i < n_; ++i) flags_[i] &= static_cast<std::uint16_t>(~kValid);
  }

 private:
  enum : std::uint16_t {
    kValid = 1,           // this scan: bounds and reference valid
    kTrackingNow = 2,     // this sample: tracking
    kWasTracking = 4,     // tracking at the previous sample
    kParticipant = 8,     // not tracking at some sample of the open window
    kFaulting = 16,       // inside a series of invalid scans (one fault per series)
    kHaveLast = 32,       // last_ holds valid bounds
    kPrevReduced = 64,    // a reduced (scaled or parked) bound was applied at the previous sample
    kReducedNow = 128,    // this sample: a reduced bound is applied
    kPredicted = 256,     // pred_ holds the nominal transient time of the present state
    kPredictedNow = 512,  // this sample: pred_ set for the next state
  };

  // The look-ahead guard's nominal transient time of the next state, with the
  // reference, bounds and period it assumed. Reused by the next sample when its
  // inputs are exactly those (the same function on the same inputs). Also the
  // next state and its z-coordinates: reused when the state is still that one
  // (bit for bit; a reset replaces it).
  struct Prediction {
    double r = 0, r_dot = 0, T = 0;
    FilterBounds b{};
    std::int64_t n = 0;
    FilterState s{};
    ZState z{};
    bool matches(double r_, double r_dot_, const FilterBounds& b_, double T_) const noexcept {
      return r == r_ && r_dot == r_dot_ && T == T_ && b.v_min == b_.v_min && b.v_max == b_.v_max &&
             b.a_min == b_.a_min && b.a_max == b_.a_max;
    }
  };

  // The inputs of z_bounds(b, r_dot, T); compared bit for bit (same_bits), so
  // that a cached result is the one the computation would give (the
  // default, all NaN, matches nothing).
  struct BoundsKey {
    FilterBounds b{kNaN, kNaN, kNaN, kNaN};
    double r_dot = kNaN, T = kNaN;
  };
  template <class A>
  static bool same_bits(const A& a, const A& b) noexcept {
    static_assert(sizeof(A) % 8 == 0 && std::is_trivially_copyable_v<A>);
    std::uint64_t wa[sizeof(A) / 8], wb[sizeof(A) / 8];
    std::memcpy(wa, &a, sizeof(A));
    std::memcpy(wb, &b, sizeof(A));
    std::uint64_t diff = 0;
    for (std::size_t k = 0; k < sizeof(A) / 8; ++k) diff |= wa[k] ^ wb[k];
    return diff == 0;
  }

  // One sample of all filters and of the synchronizer. `back`: the sample lies
  // back * T before this scan (catch-up), r taken as a ramp backwards.
  // publish: write the outputs. hold: reset is TRUE (u = 0, state kept).
  void sample(double T, double back, bool publish, bool hold) {
    // Pass 1: z, nominal transient times, t_M.
    std::int64_t t_max = 0;
    bool all_tracking = true;
    for (std::uint32_t i = 0; i < n_; ++i) {
      std::uint16_t f = static_cast<std::uint16_t>(flags_[i] & ~kTrackingNow);
      std::int64_t n = kNever;
      if (f & kValid) {
        const Reference ref{rin_[i].r - back * T * rin_[i].v, rin_[i].v};
        const FilterBounds& b = nom_[i];
        // z_bounds(b, rdot, T) and the prediction's constants, kept while
        // their inputs stay the same bit for bit.
        const BoundsKey key{b, ref.v, T};
        if (!same_bits(pb_key_[i], key)) {
          pb_[i] = prepare_bounds(z_bounds(b, ref.v, T));
          pb_key_[i] = key;
        }
        const PreparedBounds& pb = pb_[i];
        const FilterState s{x_[i], v_[i]};
        const bool predicted = (f & kPredicted) && pred_[i].matches(ref.r, ref.v, b, T);
        // The guard computed to_z of this very state, reference and period.
        const Prediction& p = pred_[i];
        const ZState z = predicted && same_bits(p.s, s) && same_bits(p.r, ref.r) && same_bits(p.r_dot, ref.v) &&
                                 same_bits(p.T, T)
                             ? p.z
                             : to_z(s, ref, T);
        ref_[i] = ref;
        z_[i] = z;
        if (is_tracking(z, pb.zb)) {
          f |= kTrackingNow;
          n = 0;
        } else if (predicted) {
          n = pred_[i].n;  // the look-ahead guard of the previous sample computed it for this very state
        } else {
          n = transient_steps(z, pb);
        }
      }
      if (!(f & kTrackingNow)) all_tracking = false;
      if (n > t_max) t_max = n;
      steps_[i] = n;
      flags_[i] = f;
    }

    // Transient window bookkeeping (before this sample's contribution).
    if (!all_tracking && !window_open_) {
      window_open_ = true;
      energy_ = 0;
      window_scans_ = 0;
      for (std::uint32_t i = 0; i < n_; ++i) {
        arrival_[i] = -1;
        flags_[i] &= static_cast<std::uint16_t>(~kParticipant);
      }
    }

    // Pass 2: bounds, look-ahead guard, control, outputs, state update.
    const double tf = static_cast<double>(t_max) * T;
    std::int64_t scaled = 0;
    double e_sample = 0;
    for (std::uint32_t i = 0; i < n_; ++i) {
      std::uint16_t f = flags_[i];
      const FilterState s{x_[i], v_[i]};
      double u = 0, vmin_applied = 0, vmax_applied = 0;
      if (f & kValid) {
        const FilterBounds& b = nom_[i];
        const Reference& ref = ref_[i];
        const std::int64_t n = steps_[i];
        const ZState z = z_[i];
        const PreparedBounds& pb = pb_[i];
        const ZBounds& zb = pb.zb;
        vmin_applied = b.v_min;
        vmax_applied = b.v_max;
        // Controller C's target, common to all bounds below (computed only
        // where a clamp needs it).
        ControllerTarget w(z.z1, zb);
        bool reduced = false;
        bool nominal = rule_ == SyncRule::Off || (f & kTrackingNow) || n == kNever || n >= t_max;
        // Final approach under the reduced bound applied at the previous sample:
        // the filter has committed to its arrival, leave it alone. (Not after
        // nominal bounds: a small transient can start in the curved layer and
        // must still be slowed down.)
        if (!nominal && (f & kPrevReduced)) {
          // z_bounds of the previous sample's bounds: that sample's reduced
          // z-bounds when their inputs are the same bit for bit.
          const BoundsKey key{FilterBounds{vmin_prev_[i], vmax_prev_[i], b.a_min, b.a_max}, ref.v, T};
          if (!same_bits(zs_key_[i], key)) {
            zs_[i] = z_bounds(key.b, ref.v, T);
            zs_key_[i] = key;
          }
          nominal = w.final_approach(z, zs_[i]);
        }
        if (!nominal) {
          const ScaledBounds sb =
              scale_bounds(rule_, s.x, s.v, ref.r, ref.v, tf, b.v_min, b.v_max, b.a_min, b.a_max, T, z);
          if (sb.action != BoundAction::Nominal) {
            const BoundsKey key{FilterBounds{sb.v_min, sb.v_max, b.a_min, b.a_max}, ref.v, T};
            const ZBounds zs = z_bounds(key.b, ref.v, T);
            const double us = w.control(z, zs);
            // Look-ahead guard: the state after this sample must still make
            // t_M - 1 with the nominal bounds.
            const Reference ref_next{ref.r + T * ref.v, ref.v};
            const FilterState sn = plant_step(s, us, T);
            const ZState zn = to_z(sn, ref_next, T);
            const std::int64_t n_next = is_tracking(zn, zb) ? 0 : transient_steps(zn, pb);
            if (n_next != kNever && n_next <= t_max - 1) {
              pred_[i] = Prediction{ref_next.r, ref_next.v, T, b, n_next, sn, zn};
              zs_[i] = zs;  // the previous sample's bounds at the next sample
              zs_key_[i] = key;
              f |= kPredictedNow | kReducedNow;
              u = us;
              reduced = true;
              vmin_applied = sb.v_min;
              vmax_applied = sb.v_max;
              ++scaled;
            }
          }
        }
        if (!reduced) u = w.control(z, zb);
      } else {
        // Invalid bounds or reference: controlled stop with the last valid
        // acceleration bounds (at once if there never were any).
        u = -s.v / T;
        if (f & kHaveLast) u = u > last_[i].a_max ? last_[i].a_max : (u < last_[i].a_min ? last_[i].a_min : u);
        vmin_applied = (f & kHaveLast) ? last_[i].v_min : 0;
        vmax_applied = (f & kHaveLast) ? last_[i].v_max : 0;
      }
      if (hold) {
        u = 0;
        f &= static_cast<std::uint16_t>(~kPredictedNow);
      }
      const bool tracking = (f & kTrackingNow) != 0;
      if (publish) {
        out<double>(kX, i, s.x);
        out<double>(kXDot, i, s.v);
        out<double>(kXDDot, i, u);
        out<double>(kVMinApplied, i, vmin_applied);
        out<double>(kVMaxApplied, i, vmax_applied);
        out<bool>(kTracking, i, tracking);
        out<std::int64_t>(kStepsToGo, i, steps_[i]);
        out<bool>(kError, i, !(f & kValid));
      }
      e_sample += s.v * s.v;
      if (window_open_) {
        if (!tracking) f |= kParticipant;
        else if (!(f & kWasTracking)) arrival_[i] = window_scans_;  // (re)arrived at this sample
      }
      f = static_cast<std::uint16_t>(
          (f & ~(kTrackingNow | kWasTracking | kPrevReduced | kReducedNow | kPredicted | kPredictedNow)) |
          (tracking ? kWasTracking : 0) | ((f & kReducedNow) ? kPrevReduced : 0) |
          ((f & kPredictedNow) ? kPredicted : 0));
      flags_[i] = f;
      vmin_prev_[i] = vmin_applied;
      vmax_prev_[i] = vmax_applied;
      if (!hold) {
        const FilterState nx = plant_step(s, u, T);
        x_[i] = nx.x;
        v_[i] = nx.v;
      }
    }

    if (window_open_) {
      if (all_tracking) {  // the window closes at its first all-tracking sample
        window_open_ = false;
        energy_last_ = energy_;
        window_scans_last_ = window_scans_;
        ++windows_;
        std::int64_t lo = std::numeric_limits<std::int64_t>::max(), hi = -1;
        for (std::uint32_t i = 0; i < n_; ++i) {
          if (!(flags_[i] & kParticipant)) continue;
          if (arrival_[i] < lo) lo = arrival_[i];
          if (arrival_[i] > hi) hi = arrival_[i];
        }
        spread_ = hi >= 0 ? hi - lo : 0;
      } else {
        energy_ += e_sample * T;
        ++window_scans_;
      }
    }

    if (!publish) return;
    out<std::int64_t>(kArrival, t_max);
    out<bool>(kSynchronized, all_tracking);
    out<std::int64_t>(kScaled, scaled);
    out<double>(kEnergy, energy_);
    out<double>(kEnergyLast, energy_last_);
    out<std::int64_t>(kWindows, windows_);
    out<std::int64_t>(kWindowScans, window_open_ ? window_scans_ : window_scans_last_);
    out<std::int64_t>(kSpread, spread_);
  }

  void start_from_inputs(std::uint32_t i) {
    const double x0 = in<double>(kX0, i), v0 = in<double>(kV0, i);
    if (std::isfinite(x0) && std::isfinite(v0)) {
      x_[i] = x0;
      v_[i] = v0;
    }
  }

  const std::uint32_t n_;
  const SyncRule rule_;
  const bool derive_r_dot_;
  const bool start_at_r_;
  const double period_s_;
  // Per-axis state and per-scan scratch, sized once (structure of arrays).
  std::vector<double> x_, v_, r_prev_, vmin_prev_, vmax_prev_;
  std::vector<FilterBounds> nom_;   // nominal bounds of this scan
  std::vector<FilterBounds> last_;  // last valid nominal bounds
  std::vector<Reference> rin_;      // reference of this scan
  std::vector<ZState> z_;
  std::vector<PreparedBounds> pb_;  // nominal z-bounds (and the prediction's constants)
  std::vector<BoundsKey> pb_key_;   // the inputs pb_ was computed from
  std::vector<ZBounds> zs_;         // z-bounds of a reduced bound (the last one computed)
  std::vector<BoundsKey> zs_key_;   // the inputs zs_ was computed from
  std::vector<Reference> ref_;      // reference of this sample
  std::vector<std::int64_t> steps_;    // n_i of this sample (kNever: cannot track or invalid)
  std::vector<std::int64_t> arrival_;  // sample of the window at which the axis last began tracking
  std::vector<std::uint16_t> flags_;
  std::vector<Prediction> pred_;
  bool first_ = true;
  bool window_open_ = false;
  double energy_ = 0, energy_last_ = 0;
  std::int64_t windows_ = 0, window_scans_ = 0, window_scans_last_ = 0, spread_ = 0;
};

}  // namespace

void register_transient_sync(BlockRegistry& r) {
  BlockTypeInfo t;
  t.name = "TRANSIENT_SYNC";
  t.category = kCategory;
  t.doc =
      "Synchronizer of n nonlinear filters (paper 004, Section III): n velocity/acceleration-limited filters "
      "(those of NONLINEAR_FILTER, Section II) turn n rough references r[i] (steps and ramps) into smooth "
      "x[i]; every scan the velocity bound of each filter that is faster than the slowest is reduced so that "
      "all transients end on the same scan, which also lowers the viscous-friction energy index "
      "E = integral of x_dot^2 dt (24).\n\n"
      "Every scan k, T the task period, for every axis: (1) n_i = transient time with the "
      "nominal bounds (Table I; -1 when r_dot is outside [v_min, v_max]); t_M = the largest finite n_i "
      "(output arrival). (2) The nominal bounds stay for axes that track, cannot track, have n_i = t_M, or "
      "ran on a reduced bound at the previous scan and are in the final approach (curved part of the "
      "boundary layer) of that bound. (3) The others get, with tf = t_M T, dU = a_min - a_max, "
      "dv = x_dot - r_dot, dx = x - r: behind the reference, v_max := v^ = (a_min a_max tf + a_min x_dot - "
      "a_max r_dot + G1)/dU, G1 = sqrt(a_min a_max (tf a_min (tf a_max + 2 dv) + 2 dx dU + dv^2)) (33), the "
      "smaller root (both can be positive); ahead of it, v_min := v^ = -(a_min a_max tf + a_max x_dot - "
      "a_min r_dot + G2)/dU, G2 = sqrt(a_min a_max (tf a_max (tf a_min + 2 dv) - 2 dx dU + dv^2)) (34). These "
      "make the continuous profile (reach v^ at full acceleration, cruise, brake to r_dot; eqs. 25-32 with "
      "(31) read as s_f2 = r_dot tf) meet the reference at tf. A negative radicand, or v^ not strictly "
      "between r_dot and the nominal bound, keeps the nominal bounds. rule 0 (unified, default): (33) or (34) "
      "by the side on which the discrete filter comes to rest if it brakes at full acceleration now (dx is "
      "shifted so that the continuous model has the same stopping point), whatever the sign of r_dot; when "
      "x_dot already exceeds the solution the first phase brakes with a_min (linear in v^). rule 1 (paper): "
      "(33) only with r > x and r_dot >= 0, (34) only with r < x and r_dot <= 0, as printed; otherwise the "
      "filter is parked with v_max := min(0, v_max) (r > x) or v_min := max(0, v_min) (r < x) as in Fig. 7. "
      "rule 2 (off): never scales, n independent filters. (5) look-ahead guard: a reduced bound is applied "
      "only if the nominal transient time of the state it leads to at k+1 is at most t_M - 1; otherwise the "
      "nominal bounds are used this scan. All of it is recomputed every scan.\n\n"
      "Outputs at scan k are the filter states at sample k and the accelerations u_k applied from them (as "
      "NONLINEAR_FILTER). Transient window: opens at the first scan at which some axis does not track "
      "(synchronized FALSE) and closes at the next scan at which all track; its scans are those from the "
      "opening one to the last non-tracking one (window_scans of them). energy = T * sum over the window's "
      "scans and over all n axes of x_dot^2 (eq. 24, left rectangle rule), running while the window is open "
      "and held once it closes; energy_last = the value of the last closed window; windows counts closed "
      "windows; spread = in the last closed window, the latest minus the earliest scan at which an axis "
      "that did not track during it (last) began tracking (0: all arrived together). r_dot, when not "
      "connected, is (r_k - r_(k-1)) divided by the time between the scans (0 on the first scan; a step then "
      "looks like a one-scan ramp: give r_dot for references made of steps). A scan that follows skipped "
      "releases first runs the missed samples (up to 10000; filters, synchronizer and window, which count "
      "samples) with its inputs, r taken as a ramp backwards. Start and reset as NONLINEAR_FILTER "
      "A NaN or infinite input on any axis is the finite-input rule's (see ENO): the block does not execute, "
      "every output holds. Inconsistent bounds (v_min >= v_max, a_min >= 0 or a_max <= 0) on an axis set its error, "
      "exclude it from the synchronization (steps_to_go -1, so synchronized stays FALSE) and stop it with "
      "its last valid acceleration bounds; one block-fault event per scan at which axes start a series of "
      "invalid scans (value: their count).";
  t.reference =
      "C. Guarino Lo Bianco, \"An efficient algorithm for the real-time generation of synchronous reference "
      "signals\" (paper 004), Section III, eqs. (23)-(34), Figs. 6-8, Tables II-IV; corrections (eq. 31, "
      "roots of eqs. 33-34, the unified rule, the look-ahead guard) in "
      "docs/motion/transient-sync.md";
  t.pins = {
      input("r", IecType::LREAL).unit("m").array("n").required().doc("reference positions (steps and ramps)"),
      input("r_dot", IecType::LREAL).unit("m/s").array("n")
          .doc("reference velocities; when not connected, derived as (r_k - r_(k-1)) / (time between the scans), 0 on "
               "the first scan"),
      input("v_min", IecType::LREAL).unit("m/s").array("n").required()
          .doc("nominal lower velocity bounds (xdot-), below v_max"),
      input("v_max", IecType::LREAL).unit("m/s").array("n").required()
          .doc("nominal upper velocity bounds (xdot+), above v_min"),
      input("a_min", IecType::LREAL).unit("m/s^2").array("n").required()
          .doc("lower acceleration bounds (U-), negative"),
      input("a_max", IecType::LREAL).unit("m/s^2").array("n").required()
          .doc("upper acceleration bounds (U+), positive"),
      input("x0", IecType::LREAL).unit("m").array("n")
          .doc("start positions for reset (and the first scan when start_at_r is FALSE)"),
      input("v0", IecType::LREAL).unit("m/s").array("n")
          .doc("start velocities for reset (and the first scan when start_at_r is FALSE)"),
      input("reset", IecType::BOOL).doc("while TRUE every filter is held at x = x0, x_dot = v0 (x_ddot = 0)"),
      output("x", IecType::LREAL).unit("m").array("n").doc("filtered positions at this scan"),
      output("x_dot", IecType::LREAL).unit("m/s").array("n").doc("filtered velocities at this scan"),
      output("x_ddot", IecType::LREAL).unit("m/s^2").array("n").doc("accelerations applied from this scan to the next"),
      output("v_min_applied", IecType::LREAL).unit("m/s").array("n")
          .doc("lower velocity bounds applied this scan (v_min, or the scaled/parked bound)"),
      output("v_max_applied", IecType::LREAL).unit("m/s").array("n")
          .doc("upper velocity bounds applied this scan (v_max, or the scaled/parked bound)"),
      output("tracking", IecType::BOOL).array("n")
          .doc("TRUE when x and x_dot equal r and r_dot (within the tolerance)"),
      output("steps_to_go", IecType::LINT).array("n")
          .doc("each axis's own transient time with its nominal bounds (Table I): scans until tracking if it were not "
               "synchronized (0 tracking, -1 never)"),
      output("error", IecType::BOOL).array("n").doc("TRUE while the axis's bounds or reference are invalid"),
      output("arrival", IecType::LINT)
          .doc("t_M: scans until the common arrival, the largest finite steps_to_go (0 when all track)"),
      output("synchronized", IecType::BOOL).doc("TRUE when every axis tracks its reference"),
      output("scaled", IecType::LINT).doc("number of axes running on a reduced velocity bound this scan"),
      output("energy", IecType::LREAL).unit("m^2/s")
          .doc("E of eq. (24) of the open transient window (held after it closes): T * sum of x_dot^2 over its scans "
               "and all axes"),
      output("energy_last", IecType::LREAL).unit("m^2/s").doc("E of the last closed transient window"),
      output("windows", IecType::LINT).doc("number of closed transient windows"),
      output("window_scans", IecType::LINT)
          .doc("scans in the open transient window so far (held after it closes: its length)"),
      output("spread", IecType::LINT)
          .doc("arrival spread of the last closed window: latest minus earliest arrival scan of the axes that moved "
               "(0 = synchronous)"),
  };
  t.params = {
      parameter("n", IecType::DINT).min(1).max(static_cast<double>(kMaxAxes))
          .doc("number of axes (sets the array pin lengths)"),
      parameter("rule", IecType::DINT).init("0").min(0).max(2)
          .doc("bound-scaling rule: 0 unified (eq. 33 or 34 by the side on which the filter comes to rest, any sign of "
               "r_dot), 1 the paper's (by the signs of r - x and r_dot, zero-bound parking otherwise), 2 off "
               "(independent filters)"),
      parameter("start_at_r", IecType::BOOL).init("TRUE")
          .doc("TRUE: the first scan starts every filter at x = r, x_dot = r_dot; FALSE: at (x0, v0)"),
  };
  t.create = [](BlockSetup& s) -> std::unique_ptr<Block> {
    const auto n = s.param<std::int32_t>("n");
    const auto rule = s.param<std::int32_t>("rule");
    if (n < 1 || n > kMaxAxes) {
      s.error("TRANSIENT_SYNC: n must be 1.." + std::to_string(kMaxAxes));
      return nullptr;
    }
    if (rule < 0 || rule > 2) {
      s.error("TRANSIENT_SYNC: rule must be 0 (unified), 1 (paper) or 2 (off)");
      return nullptr;
    }
    return std::make_unique<TransientSync>(s);
  };
  r.add(std::move(t));
}

}  // namespace syncplc::motion
