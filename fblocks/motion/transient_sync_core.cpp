// TransientSyncCore (transient_sync_core.hpp): the synchronizer's scan
// algorithm, steps 1-7 of the header; derivations in
// docs/motion/transient-sync.md (sections 1 and 2).
#include "fblocks/motion/transient_sync_core.hpp"

#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <type_traits>

namespace syncplc::motion {
namespace {

template <class A>
bool same_bits(const A& a, const A& b) noexcept {
  static_assert(sizeof(A) % 8 == 0 && std::is_trivially_copyable_v<A>);
  std::uint64_t wa[sizeof(A) / 8], wb[sizeof(A) / 8];
  std::memcpy(wa, &a, sizeof(A));
  std::memcpy(wb, &b, sizeof(A));
  std::uint64_t diff = 0;
  for (std::size_t k = 0; k < sizeof(A) / 8; ++k) diff |= wa[k] ^ wb[k];
  return diff == 0;
}

}  // namespace

TransientSyncCore::TransientSyncCore(std::uint32_t n, SyncRule rule, double T, bool start_at_r)
    : n_(n), rule_(rule), start_at_r_(start_at_r), period_s_(T),
      x_(n), v_(n), r_prev_(n), vmin_prev_(n), vmax_prev_(n), nom_(n), last_(n), rin_(n), z_(n), pb_(n),
      pb_key_(n), zs_(n), zs_key_(n), ref_(n), steps_(n), count_(n), arrival_(n), flags_(n), next_(n), pred_(n),
      out_x_(n), out_v_(n), out_a_(n), out_vmin_(n), out_vmax_(n), out_steps_(n),
      out_tracking_(std::make_unique<bool[]>(n)), out_error_(std::make_unique<bool[]>(n)) {}

void TransientSyncCore::set_period(double T) noexcept {
  if (period_s_ == T) return;
  period_s_ = T;
  for (auto& fl : flags_) fl &= static_cast<std::uint16_t>(~kFresh);
}

void TransientSyncCore::start(std::uint32_t i, double x0, double v0) noexcept {
  x_[i] = x0;
  v_[i] = v0;
  flags_[i] &= static_cast<std::uint16_t>(~kFresh);
  if (first_) started_ = true;
}

void TransientSyncCore::start(std::span<const double> x0, std::span<const double> v0) noexcept {
  for (std::uint32_t i = 0; i < n_ && i < x0.size() && i < v0.size(); ++i) start(i, x0[i], v0[i]);
}

inline void TransientSyncCore::start_from(std::uint32_t i, const double* x0, const double* v0) noexcept {
  if (x0 == nullptr || v0 == nullptr) return;
  if (std::isfinite(x0[i]) && std::isfinite(v0[i])) {
    x_[i] = x0[i];
    v_[i] = v0[i];
  }
}

int TransientSyncCore::scan(const ScanInputs& in) noexcept {
  const double T = period_s_;  // the filters' sampling time
  const double dt = in.dt > 0 ? in.dt : T;
  const bool first = first_;
  first_ = false;
  const bool hold = in.reset;

  // Inputs, validity, start.
  int faults = 0;
  for (std::uint32_t i = 0; i < n_; ++i) {
    const double r = in.r[i];
    double r_dot = 0;
    if (in.r_dot != nullptr) r_dot = in.r_dot[i];
    else if (!first) r_dot = (r - r_prev_[i]) / dt;
    r_prev_[i] = r;
    const FilterBounds b{in.v_min[i], in.v_max[i], in.a_min[i], in.a_max[i]};
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
    if (first && !started_) {
      if (start_at_r_ && std::isfinite(r) && std::isfinite(r_dot)) {
        x_[i] = r;
        v_[i] = r_dot;
      } else {
        start_from(i, in.x0, in.v0);
      }
    }
    rin_[i] = Reference{r, r_dot};
    nom_[i] = b;
    flags_[i] = f;
  }
  if (!first && !hold) {
    // Skipped releases (dt = n periods): run the n - 1 missed samples with
    // this scan's inputs, r taken as a ramp backwards, so that x stays on the
    // time grid (as NONLINEAR_FILTER does).
    const double periods = std::round(dt / T);
    const int missed = periods > 1 ? static_cast<int>(std::fmin(periods - 1, double{kMaxCatchUp})) : 0;
    for (int j = missed; j >= 1; --j) sample(T, static_cast<double>(j), false, false);
  }
  if (hold)
    for (std::uint32_t i = 0; i < n_; ++i) {
      start_from(i, in.x0, in.v0);  // a state the previous sample did not hand over: nothing carries
      flags_[i] &= static_cast<std::uint16_t>(~kFresh);
    }
  sample(T, 0, true, hold);
  for (std::uint32_t i = 0; i < n_; ++i) flags_[i] &= static_cast<std::uint16_t>(~kValid);
  return faults;
}

// z_bounds of the velocity bounds applied at the previous sample (a reduced
// or locked bound) with this sample's acceleration bounds, r_dot and T: the
// cached ones when their inputs are the same bit for bit.
inline const ZBounds& TransientSyncCore::previous_z_bounds(std::uint32_t i, const FilterBounds& b, double r_dot, double T) noexcept {
  // On a locked bound with the inputs the previous sample expected, the key
  // is the one that sample used (the bound it applied, the same b, r_dot, T).
  if ((flags_[i] & (kLocked | kSame)) == (kLocked | kSame)) return zs_[i];
  const BoundsKey key{FilterBounds{vmin_prev_[i], vmax_prev_[i], b.a_min, b.a_max}, r_dot, T};
  if (!same_bits(zs_key_[i], key)) {
    zs_[i] = z_bounds(key.b, r_dot, T);
    zs_key_[i] = key;
  }
  return zs_[i];
}

// Pass 1 for one valid axis: z, tracking, and its count n_i (step 1 of the
// header): 0 tracking; the count of the previous sample minus one when it
// carries (docs/motion/transient-sync.md, section 2, "What carries"); the look-ahead
// guard's prediction of this very state; else Table I afresh. Returns n_i;
// `f` gets kTrackingNow and kSame, loses kLocked/kCarry where they no longer hold.
// Inlined into sample(), its only caller, as it was when the algorithm was a
// class of internal linkage in transient_sync.cpp (GCC no longer inlines it on
// its own: the block cost 8 % more per scan).
[[gnu::always_inline]] inline std::int64_t TransientSyncCore::count_axis(std::uint32_t i, double T, double back, std::uint16_t& f) noexcept {
  const Reference ref{rin_[i].r - back * T * rin_[i].v, rin_[i].v};
  const FilterBounds& b = nom_[i];
  if ((f & kSame) == 0 || !same_bits(next_[i], Inputs{ref.r, ref.v, b})) {
    f &= static_cast<std::uint16_t>(~kFresh);
    // z_bounds(b, rdot, T) and the prediction's constants, kept while their
    // inputs stay the same bit for bit (with kSame they are those of the
    // previous sample, which set them).
    const BoundsKey key{b, ref.v, T};
    if (!same_bits(pb_key_[i], key)) {
      pb_[i] = prepare_bounds(z_bounds(b, ref.v, T));
      pb_key_[i] = key;
    }
  }
  const PreparedBounds& pb = pb_[i];
  const FilterState s{x_[i], v_[i]};
  const Prediction& p = pred_[i];
  // The guard computed to_z of this very state for these very inputs.
  const bool predicted = (f & kPredicted) && same_bits(p.s, s);
  const ZState z = predicted ? p.z : to_z(s, ref, T);
  ref_[i] = ref;
  z_[i] = z;
  if (is_tracking(z, pb.zb)) {
    f = static_cast<std::uint16_t>((f | kTrackingNow) & ~kLocked);
    return 0;
  }
  if ((f & kCarry) && count_[i] >= 2) return count_[i] - 1;
  f &= static_cast<std::uint16_t>(~kLocked);  // a count that does not carry ends a lock
  if (predicted) return p.n;  // the look-ahead guard of the previous sample computed it for this very state
  return transient_steps(z, pb);
}

// One sample of all filters and of the synchronizer. `back`: the sample lies
// back * T before this scan (catch-up), r taken as a ramp backwards.
// publish: write the outputs. hold: reset is TRUE (u = 0, state kept).
inline void TransientSyncCore::sample(double T, double back, bool publish, bool hold) noexcept {
  // Pass 1: z, counts, t_M.
  std::int64_t t_max = 0;
  bool all_tracking = true;
  bool release = false;  // an axis that set t_M at the previous sample on its nominal bounds changed
  for (std::uint32_t i = 0; i < n_; ++i) {
    std::uint16_t f = static_cast<std::uint16_t>(flags_[i] & ~kTrackingNow);
    const bool was_slowest = (f & kCarry) && !(f & kLocked) && count_[i] == t_prev_;
    std::int64_t n = kNever;
    if (f & kValid) {
      n = count_axis(i, T, back, f);
    } else {
      f &= static_cast<std::uint16_t>(~kFresh);
    }
    if (was_slowest && !(f & kSame)) release = true;
    if (!(f & kTrackingNow)) all_tracking = false;
    if (n > t_max) t_max = n;
    steps_[i] = n;
    flags_[i] = f;
  }
  if (release) {
    // The common arrival was set by an axis whose inputs changed: it may come
    // earlier now. A locked axis's count is its planned arrival, not its own
    // time: it is predicted afresh, and t_M is again the largest own time.
    t_max = 0;
    for (std::uint32_t i = 0; i < n_; ++i) {
      std::uint16_t& f = flags_[i];
      if (f & kLocked) {
        steps_[i] = transient_steps(z_[i], pb_[i]);
        f &= static_cast<std::uint16_t>(~(kLocked | kCarry));
      }
      if (steps_[i] > t_max) t_max = steps_[i];
    }
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

  // Pass 2: bounds, look-ahead guard, lock, control, outputs, state update.
  const double tf = static_cast<double>(t_max) * T;
  std::int64_t scaled = 0;
  double e_sample = 0;
  for (std::uint32_t i = 0; i < n_; ++i) {
    std::uint16_t f = flags_[i];
    const FilterState s{x_[i], v_[i]};
    double u = 0, vmin_applied = 0, vmax_applied = 0;
    bool reduced = false;
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
      bool nominal = rule_ == SyncRule::Off || (f & kTrackingNow) || n == kNever;
      if (!nominal && (f & kLocked)) {
        if (n == t_max) {
          // On its plan: the locked bound, which ends the transient with
          // the slowest axis's (doc section 2, "What carries").
          u = w.control(z, previous_z_bounds(i, b, ref.v, T));
          reduced = true;
          vmin_applied = vmin_prev_[i];
          vmax_applied = vmax_prev_[i];
        } else {
          f &= static_cast<std::uint16_t>(~kLocked);  // t_M grew: synchronized afresh
        }
      }
      if (!reduced) {
        f &= static_cast<std::uint16_t>(~kLocked);
        nominal = nominal || n >= t_max;
        // Final approach under the reduced bound applied at the previous
        // sample, with the inputs that sample expected: the filter has
        // committed to its arrival, leave it alone. (Not after nominal
        // bounds: a small transient can start in the curved layer and must
        // still be slowed down. Not after a change of its reference or
        // bounds: that is a new transient, which arrives with the others.)
        if (!nominal && (f & kPrevReduced) && (f & kSame))
          nominal = w.final_approach(z, previous_z_bounds(i, b, ref.v, T));
        if (!nominal) reduced = reduce(i, s, z, ref, b, pb, w, t_max, tf, T, f, u, vmin_applied, vmax_applied);
        if (!reduced) u = w.control(z, zb);
      }
    } else {
      // Invalid bounds or reference: controlled stop with the last valid
      // acceleration bounds (at once if there never were any).
      u = -s.v / T;
      if (f & kHaveLast) u = u > last_[i].a_max ? last_[i].a_max : (u < last_[i].a_min ? last_[i].a_min : u);
      vmin_applied = (f & kHaveLast) ? last_[i].v_min : 0;
      vmax_applied = (f & kHaveLast) ? last_[i].v_max : 0;
    }
    if (reduced) {
      f |= kReducedNow;
      ++scaled;
    }
    // The count this sample hands to the next: the planned one on a locked
    // bound, the own one on the nominal bounds; none on a scaled bound
    // (pred_ then holds the next state's) or without valid inputs.
    if ((f & kValid) && !hold && steps_[i] >= 1 && (!reduced || (f & kLocked))) {
      count_[i] = (f & kLocked) ? t_max : steps_[i];
      f |= kCarry;
    } else {
      f &= static_cast<std::uint16_t>(~kCarry);
    }
    if (hold) {
      u = 0;
      f &= static_cast<std::uint16_t>(~(kPredictedNow | kLocked));
    }
    const bool tracking = (f & kTrackingNow) != 0;
    if (publish) {
      out_x_[i] = s.x;
      out_v_[i] = s.v;
      out_a_[i] = u;
      out_vmin_[i] = vmin_applied;
      out_vmax_[i] = vmax_applied;
      out_tracking_[i] = tracking;
      // Scans until the axis tracks: under the unified rule an axis on a
      // reduced bound arrives with the slowest.
      out_steps_[i] = reduced && rule_ == SyncRule::Unified ? t_max : steps_[i];
      out_error_[i] = !(f & kValid);
    }
    e_sample += s.v * s.v;
    if (window_open_) {
      if (!tracking) f |= kParticipant;
      else if (!(f & kWasTracking)) arrival_[i] = window_scans_;  // (re)arrived at this sample
    }
    // The inputs the next sample is expected to have.
    if ((f & kValid) && !hold) {
      const Reference& ref = ref_[i];
      next_[i] = Inputs{ref.r + T * ref.v, ref.v, nom_[i]};
      f |= kSame;
    } else {
      f &= static_cast<std::uint16_t>(~kSame);
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
  t_prev_ = t_max;

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
  status_.arrival = t_max;
  status_.synchronized = all_tracking;
  status_.scaled = scaled;
  status_.energy = energy_;
  status_.energy_last = energy_last_;
  status_.windows = windows_;
  status_.window_scans = window_open_ ? window_scans_ : window_scans_last_;
  status_.spread = spread_;
}

// Steps 3-5 and the lock for one axis that is neither tracking, nor the
// slowest, nor in its committed final approach: the scaled bound of
// eq. (33)/(34) (or the paper's parking); under the unified rule locked when
// holding it (or the one-correction bound, see lock()) ends the transient
// exactly at t_M, else kept for this sample only if the look-ahead guard
// passes. True when a reduced bound is applied (u and the applied bounds set).
inline bool TransientSyncCore::reduce(std::uint32_t i, const FilterState& s, const ZState& z, const Reference& ref, const FilterBounds& b,
            const PreparedBounds& pb, ControllerTarget& w, std::int64_t t_max, double tf, double T,
            std::uint16_t& f, double& u, double& vmin_applied, double& vmax_applied) noexcept {
  const ScaledBounds sb = scale_bounds(rule_, s.x, s.v, ref.r, ref.v, tf, b.v_min, b.v_max, b.a_min, b.a_max, T, z);
  if (sb.action == BoundAction::Nominal) return false;
  if (rule_ == SyncRule::Unified && lock(i, s, z, ref, b, w, sb, t_max, T, f, u, vmin_applied, vmax_applied))
    return true;
  const BoundsKey key{FilterBounds{sb.v_min, sb.v_max, b.a_min, b.a_max}, ref.v, T};
  const ZBounds zs = z_bounds(key.b, ref.v, T);
  const double us = w.control(z, zs);
  // Look-ahead guard: the state after this sample must still make t_M - 1
  // with the nominal bounds.
  const Reference ref_next{ref.r + T * ref.v, ref.v};
  const FilterState sn = plant_step(s, us, T);
  const ZState zn = to_z(sn, ref_next, T);
  const std::int64_t n_next = is_tracking(zn, pb.zb) ? 0 : transient_steps(zn, pb);
  if (n_next == kNever || n_next > t_max - 1) return false;
  zs_[i] = zs;  // the previous sample's bounds at the next sample
  zs_key_[i] = key;
  u = us;
  vmin_applied = sb.v_min;
  vmax_applied = sb.v_max;
  pred_[i] = Prediction{n_next, sn, zn};
  f |= kPredictedNow;
  return true;
}

// The lock (docs/motion/transient-sync.md, section 2, "What carries"): a reduced bound that,
// held from this sample on, ends the transient exactly t_M samples from now
// by Table I with that bound. The scaled bound sb of eq. (33)/(34) with
// tf = t_M T is tried first; the continuous model usually misses the
// discrete count by a sample (the filter's output lags its input by one), so
// when Table I gives t_M + d instead, the bound for tf = (t_M - d) T of the
// same side is tried once. True and applied when one of them ends at t_M.
inline bool TransientSyncCore::lock(std::uint32_t i, const FilterState& s, const ZState& z, const Reference& ref, const FilterBounds& b,
          ControllerTarget& w, const ScaledBounds& sb, std::int64_t t_max, double T, std::uint16_t& f, double& u,
          double& vmin_applied, double& vmax_applied) noexcept {
  ScaledBounds cand = sb;
  for (int attempt = 0; attempt < 2; ++attempt) {
    const BoundsKey key{FilterBounds{cand.v_min, cand.v_max, b.a_min, b.a_max}, ref.v, T};
    const ZBounds zs = z_bounds(key.b, ref.v, T);
    const std::int64_t n_red = transient_steps(z, prepare_bounds(zs));
    if (n_red == t_max) {
      zs_[i] = zs;
      zs_key_[i] = key;
      u = w.control(z, zs);
      vmin_applied = cand.v_min;
      vmax_applied = cand.v_max;
      f |= kLocked;
      return true;
    }
    const std::int64_t aim = 2 * t_max - n_red;
    if (n_red == kNever || attempt == 1 || aim < 1) return false;
    cand = scale_bounds(rule_, s.x, s.v, ref.r, ref.v, static_cast<double>(aim) * T, b.v_min, b.v_max, b.a_min,
                        b.a_max, T, z);
    if (cand.action != sb.action) return false;
  }
  return false;
}

}  // namespace syncplc::motion
