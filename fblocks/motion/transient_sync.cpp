// TRANSIENT_SYNC: n velocity/acceleration-limited nonlinear filters whose
// velocity bounds are reduced so that all transients end on the same scan,
// and the energy index E of their transients. Paper 004 (C. Guarino Lo
// Bianco, "An efficient algorithm for the real-time generation of synchronous
// reference signals"), Section III, eqs. (23)-(34), with the corrections, the
// "unified" rule and the lock derived in docs/motion/transient-sync.md
// (sections 1 and 2).
//
// The scan algorithm (steps 1-7, the catch-up after skipped releases, the
// energy window) is TransientSyncCore (transient_sync_core.hpp), which other
// blocks run on their own axes too; this block is its pins: it copies the
// inputs into the core's arrays, runs one scan with T = the task period, and
// copies the outputs back. execute() allocates nothing.
#include <cstdint>
#include <memory>
#include <vector>

#include "fblocks/motion/motion.hpp"
#include "fblocks/motion/transient_sync_block.hpp"
#include "fblocks/motion/transient_sync_core.hpp"

namespace syncplc::motion {
namespace {

static_assert(TransientSyncCore::kMaxCatchUp == kMaxCatchUp);

class TransientSync final : public Block {
 public:
  explicit TransientSync(BlockSetup& s)
      : n_(static_cast<std::uint32_t>(s.param<std::int32_t>("n"))),
        derive_r_dot_(!s.connected(kRDot)),
        core_(n_, static_cast<SyncRule>(s.param<std::int32_t>("rule")),
              static_cast<double>(s.task_period_ns()) * 1e-9, s.param<bool>("start_at_r")),
        in_(kInputArrays * static_cast<std::size_t>(n_)) {}

  // An online change may connect or disconnect r_dot (the core keeps the
  // previous r either way, so a derived r_dot is right from the first scan
  // after), and re-time the task (the core's set_period: nothing carries).
  void rewire_from(const Block& fresh) noexcept override {
    const auto& f = static_cast<const TransientSync&>(fresh);
    derive_r_dot_ = f.derive_r_dot_;
    core_.set_period(f.core_.period());
  }

  void execute(ScanContext& ctx) noexcept override {
    // The array inputs, in pin order kR..kV0, each n values.
    for (int p = kR; p <= kV0; ++p) {
      double* d = column(p);
      for (std::uint32_t i = 0; i < n_; ++i) d[i] = in<double>(p, i);
    }
    TransientSyncCore::ScanInputs si;
    si.r = column(kR);
    si.r_dot = derive_r_dot_ ? nullptr : column(kRDot);
    si.v_min = column(kVMin);
    si.v_max = column(kVMax);
    si.a_min = column(kAMin);
    si.a_max = column(kAMax);
    si.x0 = column(kX0);
    si.v0 = column(kV0);
    si.reset = in<bool>(kReset);
    si.dt = ctx.dt_ns > 0 ? static_cast<double>(ctx.dt_ns) * 1e-9 : core_.period();
    const int faults = core_.scan(si);
    if (faults > 0)
      ctx.fault("TRANSIENT_SYNC: invalid bounds or non-finite reference on an axis (count in value)",
                static_cast<double>(faults));

    const auto x = core_.x(), v = core_.x_dot(), a = core_.x_ddot();
    const auto lo = core_.v_min_applied(), hi = core_.v_max_applied();
    const auto tracking = core_.tracking(), error = core_.error();
    const auto steps = core_.steps_to_go();
    for (std::uint32_t i = 0; i < n_; ++i) {
      out<double>(kX, i, x[i]);
      out<double>(kXDot, i, v[i]);
      out<double>(kXDDot, i, a[i]);
      out<double>(kVMinApplied, i, lo[i]);
      out<double>(kVMaxApplied, i, hi[i]);
      out<bool>(kTracking, i, tracking[i]);
      out<std::int64_t>(kStepsToGo, i, steps[i]);
      out<bool>(kError, i, error[i]);
    }
    const TransientSyncCore::Status& st = core_.status();
    out<std::int64_t>(kArrival, st.arrival);
    out<bool>(kSynchronized, st.synchronized);
    out<std::int64_t>(kScaled, st.scaled);
    out<double>(kEnergy, st.energy);
    out<double>(kEnergyLast, st.energy_last);
    out<std::int64_t>(kWindows, st.windows);
    out<std::int64_t>(kWindowScans, st.window_scans);
    out<std::int64_t>(kSpread, st.spread);
  }

 private:
  static constexpr std::size_t kInputArrays = kV0 - kR + 1;
  double* column(int pin) noexcept { return in_.data() + static_cast<std::size_t>(pin - kR) * n_; }

  const std::uint32_t n_;
  bool derive_r_dot_;  // r_dot unconnected (rewire_from: an online change may connect it)
  TransientSyncCore core_;
  std::vector<double> in_;  // the array inputs of this scan, pin after pin (sized once)
};

}  // namespace

std::unique_ptr<Block> make_transient_sync(BlockSetup& s) { return std::make_unique<TransientSync>(s); }

}  // namespace syncplc::motion
