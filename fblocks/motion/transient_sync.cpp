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
#include <span>
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
    // The array inputs, each n values; r_dot only when connected, x0 and v0
    // only when the core reads them (the first scan and a reset): the copies
    // are what this block costs on top of the core.
    const bool reset = in<bool>(kReset);
    const bool starting = first_ || reset;
    first_ = false;
    for (int p = kR; p <= kV0; ++p) {
      if ((p == kRDot && derive_r_dot_) || ((p == kX0 || p == kV0) && !starting)) continue;
      const Cell* c = pin_cell(p);
      double* d = column(p);
      for (std::uint32_t i = 0; i < n_; ++i) d[i] = c[i].get<double>();
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
    si.reset = reset;
    si.dt = ctx.dt_ns > 0 ? static_cast<double>(ctx.dt_ns) * 1e-9 : core_.period();
    const int faults = core_.scan(si);
    if (faults > 0)
      ctx.fault("TRANSIENT_SYNC: invalid bounds or non-finite reference on an axis (count in value)",
                static_cast<double>(faults));

    // The outputs, pin by pin.
    put(kX, core_.x());
    put(kXDot, core_.x_dot());
    put(kXDDot, core_.x_ddot());
    put(kVMinApplied, core_.v_min_applied());
    put(kVMaxApplied, core_.v_max_applied());
    put(kTracking, core_.tracking());
    put(kStepsToGo, core_.steps_to_go());
    put(kError, core_.error());
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
  template <class T>
  void put(int pin, std::span<const T> values) noexcept {
    Cell* c = pin_cell(pin);
    for (std::uint32_t i = 0; i < n_; ++i) c[i].set<T>(values[i]);
  }

  const std::uint32_t n_;
  bool derive_r_dot_;  // r_dot unconnected (rewire_from: an online change may connect it)
  TransientSyncCore core_;
  std::vector<double> in_;  // the array inputs of this scan, pin after pin (sized once)
  bool first_ = true;
};

}  // namespace

std::unique_ptr<Block> make_transient_sync(BlockSetup& s) { return std::make_unique<TransientSync>(s); }

}  // namespace syncplc::motion
