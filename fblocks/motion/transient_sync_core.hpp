// The per-scan algorithm of the n-axis synchronizer (paper 004, Section III),
// apart from any block: n velocity/acceleration-limited nonlinear filters
// whose velocity bounds are reduced so that all transients end on the same
// sample, the carried counts, the lock, the look-ahead guard, the catch-up
// after skipped releases, and the energy window. TRANSIENT_SYNC
// (transient_sync.cpp) is this class behind pins; a block that moves a group
// of axes runs the same algorithm on its own inputs.
//
// Per scan k, T = the sampling time, for every axis i:
//   1. n_i = Table I steps from sample k with the nominal bounds (-1: never),
//      or the count of sample k-1 minus one when the axis's inputs are those
//      sample k-1 expected (reference continued as its ramp, same r_dot,
//      bounds and T: Table I counts the filter's own samples; section 2 of
//      docs/motion/transient-sync.md, "What carries"); a locked axis counts
//      its planned arrival. t_M = the largest finite n_i.
//   2. nominal bounds if: rule off, tracking, cannot track, n_i = t_M (the
//      slowest), or in the final approach of the reduced bound it ran on at
//      scan k-1 with unchanged inputs (only reduced bounds count: a small
//      transient that starts in the curved layer is still slowed down; and a
//      changed reference or bound is a new transient, synchronized afresh);
//   3./4. otherwise the velocity bound scaled by eq. (33) (ends behind the
//      reference) or (34) (ends ahead) with tf = t_M T: unified rule, side
//      from the discrete stopping point (transient_sync_math.hpp), or the
//      paper's sign-of-rdot rule with zero-bound parking;
//   5. lock (unified rule): if Table I with the reduced bound, held, ends the
//      transient at exactly t_M (tf = t_M T, or once more with tf corrected
//      by the miss), the bound is locked and held, with no rescaling, guard or
//      prediction, until the axis's inputs change, t_M grows, or an axis that
//      set t_M changes (then locked axes are predicted afresh);
//   6. otherwise the look-ahead guard: the reduced bound is kept only if the
//      nominal transient time of the resulting state k+1 is at most t_M - 1
//      (that prediction is reused as n_i at scan k+1);
//   7. outputs at sample k, then state_{k+1} = plant_step(state_k, u_k, T).
// After skipped releases (an overrun) the scan first runs the missed samples
// (filters and synchronizer) with its inputs, r taken as a ramp backwards, so
// x stays on the time grid, as NONLINEAR_FILTER does. Values whose inputs are
// the same bit for bit (nominal z-bounds, the guard's prediction, next state,
// reduced z-bounds) are reused.
//
// Everything is sized in the constructor; scan() and the other calls after it
// allocate nothing and throw nothing.
#pragma once

#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include "fblocks/motion/nonlinear_filter_math.hpp"
#include "fblocks/motion/transient_sync_math.hpp"

namespace syncplc::motion {

class TransientSyncCore {
 public:
  // Most samples one scan catches up after skipped releases (motion.hpp's
  // kMaxCatchUp, which TRANSIENT_SYNC checks it equals).
  static constexpr int kMaxCatchUp = 10000;

  // The inputs of one scan: each pointer to n values, one per axis (the
  // nominal bounds are those of NONLINEAR_FILTER: v_min < v_max, a_min < 0 <
  // a_max; an axis with invalid bounds or a non-finite r or r_dot is stopped
  // with its last valid acceleration bounds and excluded).
  struct ScanInputs {
    const double* r = nullptr;      // reference positions
    const double* r_dot = nullptr;  // reference velocities; nullptr: (r - r of the previous scan) / dt, 0 on the first
    const double* v_min = nullptr;
    const double* v_max = nullptr;
    const double* a_min = nullptr;
    const double* a_max = nullptr;
    // Start states, read on a reset and on the first scan when start_at_r is
    // false (a non-finite pair, or nullptr, keeps the state).
    const double* x0 = nullptr;
    const double* v0 = nullptr;
    bool reset = false;  // hold every filter at (x0, v0), u = 0; nothing carries
    // Time since the previous scan (s); <= 0: one period. dt = m periods
    // (m > 1, rounded) first runs the m - 1 missed samples (at most
    // kMaxCatchUp).
    double dt = 0;
  };

  // The scalar outputs of the last scan.
  struct Status {
    std::int64_t arrival = 0;     // t_M: samples until the common arrival (0 when all track)
    bool synchronized = false;    // every axis tracks
    std::int64_t scaled = 0;      // axes on a reduced velocity bound
    double energy = 0;            // E of eq. (24) of the open window (held after it closes)
    double energy_last = 0;       // E of the last closed window
    std::int64_t windows = 0;     // closed windows
    std::int64_t window_scans = 0;  // samples of the open window so far (held after it closes)
    std::int64_t spread = 0;      // last closed window: latest minus earliest arrival of the axes that moved
  };

  // n >= 1 axes, T > 0 the sampling time (s). start_at_r: the first scan
  // starts every filter at x = r, x_dot = r_dot (unless start() came first);
  // false: at (x0, v0) of the first scan's inputs.
  TransientSyncCore(std::uint32_t n, SyncRule rule, double T, bool start_at_r);

  // One scan: the missed samples (see ScanInputs::dt), then the sample of
  // this scan, whose outputs are published. Returns the number of axes whose
  // inputs turned invalid at this scan (the start of a series of invalid
  // scans; one report per series).
  int scan(const ScanInputs& in) noexcept;

  // Starts filter i (or every filter) at (x0, v0), e.g. the current set
  // position and velocity of an axis: what the next sample filters from. As a
  // reset, nothing carries into the next sample (counts, locks, predictions).
  // Before the first scan it replaces the start of start_at_r / (x0, v0).
  // Non-finite values are taken as they are (the caller checks them).
  void start(std::uint32_t i, double x0, double v0) noexcept;
  void start(std::span<const double> x0, std::span<const double> v0) noexcept;

  // The state of filter i at the next sample (after scan(): the state the
  // outputs' x_ddot leads to).
  FilterState state(std::uint32_t i) const noexcept { return FilterState{x_[i], v_[i]}; }

  // A new sampling time (a re-timed task): counts and locks are in samples of
  // the old period, so none carries (as after a reset); the prepared bounds
  // are keyed with T and are computed again.
  void set_period(double T) noexcept;
  double period() const noexcept { return period_s_; }

  std::uint32_t size() const noexcept { return n_; }
  SyncRule rule() const noexcept { return rule_; }

  // Per-axis outputs of the last scan (n values each): the filter states at
  // this sample, the acceleration applied from it, the velocity bounds
  // applied (nominal, or the scaled/parked/locked bound), tracking, the
  // samples until the axis tracks (its own Table I time on nominal bounds,
  // t_M on a reduced bound under the unified rule; 0 tracking, -1 never) and
  // invalid inputs.
  std::span<const double> x() const noexcept { return {out_x_.data(), n_}; }
  std::span<const double> x_dot() const noexcept { return {out_v_.data(), n_}; }
  std::span<const double> x_ddot() const noexcept { return {out_a_.data(), n_}; }
  std::span<const double> v_min_applied() const noexcept { return {out_vmin_.data(), n_}; }
  std::span<const double> v_max_applied() const noexcept { return {out_vmax_.data(), n_}; }
  std::span<const bool> tracking() const noexcept { return {out_tracking_.get(), n_}; }
  std::span<const std::int64_t> steps_to_go() const noexcept { return {out_steps_.data(), n_}; }
  std::span<const bool> error() const noexcept { return {out_error_.get(), n_}; }
  const Status& status() const noexcept { return status_; }

 private:
  enum : std::uint16_t {
    kValid = 1,           // this scan: bounds and reference valid
    kTrackingNow = 2,     // this sample: tracking
    kWasTracking = 4,     // tracking at the previous sample
    kParticipant = 8,     // not tracking at some sample of the open window
    kFaulting = 16,       // inside a series of invalid scans (one fault per series)
    kHaveLast = 32,       // last_ holds valid bounds
    kPrevReduced = 64,    // a reduced (scaled, parked or locked) bound was applied at the previous sample
    kReducedNow = 128,    // this sample: a reduced bound is applied
    kPredicted = 256,     // pred_ holds the nominal transient time of the present state
    kPredictedNow = 512,  // this sample: pred_ set for the next state
    kSame = 1024,         // this sample's inputs are those the previous sample expected (next_)
    kCarry = 2048,        // count_ holds this axis's count at the previous sample, to be carried
    kLocked = 4096,       // on a locked bound: the reduced bound of the previous sample, held (vmin_prev_, vmax_prev_)
  };
  // What a state that the previous sample did not hand over ends.
  static constexpr std::uint16_t kFresh = kSame | kCarry | kLocked | kPredicted;

  // The inputs a sample expects of the next one: the reference continued as a
  // ramp over the sample (r + T r_dot, exactly as the filters extrapolate it),
  // the same r_dot and bounds (T is the core's own). Compared bit for bit
  // (same_bits).
  struct Inputs {
    double r = kNaN, r_dot = kNaN;
    FilterBounds b{kNaN, kNaN, kNaN, kNaN};
  };

  // The look-ahead guard's nominal transient time of the next state, and that
  // state with its z-coordinates. Reused by the next sample when its inputs
  // are those expected (kSame) and the state is this one, bit for bit (the
  // same function on the same inputs).
  struct Prediction {
    std::int64_t n = 0;
    FilterState s{};
    ZState z{};
  };

  // The inputs of z_bounds(b, r_dot, T); compared bit for bit (same_bits), so
  // that a cached result is the one the computation would give (the
  // default, all NaN, matches nothing).
  struct BoundsKey {
    FilterBounds b{kNaN, kNaN, kNaN, kNaN};
    double r_dot = kNaN, T = kNaN;
  };

  const ZBounds& previous_z_bounds(std::uint32_t i, const FilterBounds& b, double r_dot, double T) noexcept;
  std::int64_t count_axis(std::uint32_t i, double T, double back, std::uint16_t& f) noexcept;
  void sample(double T, double back, bool publish, bool hold) noexcept;
  bool reduce(std::uint32_t i, const FilterState& s, const ZState& z, const Reference& ref, const FilterBounds& b,
              const PreparedBounds& pb, ControllerTarget& w, std::int64_t t_max, double tf, double T,
              std::uint16_t& f, double& u, double& vmin_applied, double& vmax_applied) noexcept;
  bool lock(std::uint32_t i, const FilterState& s, const ZState& z, const Reference& ref, const FilterBounds& b,
            ControllerTarget& w, const ScaledBounds& sb, std::int64_t t_max, double T, std::uint16_t& f, double& u,
            double& vmin_applied, double& vmax_applied) noexcept;
  void start_from(std::uint32_t i, const double* x0, const double* v0) noexcept;

  const std::uint32_t n_;
  const SyncRule rule_;
  const bool start_at_r_;
  double period_s_;  // the sampling time T
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
  std::vector<std::int64_t> count_;    // the count handed to the next sample (kCarry)
  std::vector<std::int64_t> arrival_;  // sample of the window at which the axis last began tracking
  std::vector<std::uint16_t> flags_;
  std::vector<Inputs> next_;        // the inputs the next sample is expected to have (kSame)
  std::vector<Prediction> pred_;
  // Outputs of the last published sample.
  std::vector<double> out_x_, out_v_, out_a_, out_vmin_, out_vmax_;
  std::vector<std::int64_t> out_steps_;
  std::unique_ptr<bool[]> out_tracking_, out_error_;
  Status status_;
  bool first_ = true;    // no scan yet
  bool started_ = false;  // start() set the state before the first scan
  bool window_open_ = false;
  std::int64_t t_prev_ = -1;  // t_M of the previous sample
  double energy_ = 0, energy_last_ = 0;
  std::int64_t windows_ = 0, window_scans_ = 0, window_scans_last_ = 0, spread_ = 0;
};

}  // namespace syncplc::motion
