// MC_GearIn (PLCopen Part 1 v2.0 §4.4), and the blocks that end a coupling:
// MC_GearOut (§4.5) and MC_CamOut (§4.3). MC_GearIn ramps the slave's
// velocity to RatioNumerator/RatioDenominator times the master's with its
// Acceleration and Deceleration, then locks the positions (InGear): from the
// lock on, slave = slave_at_lock + ratio (master - master_at_lock), computed
// from positions every scan, so nothing drifts however long it runs.
#include <cmath>
#include <memory>
#include <string>

#include "fblocks/plcopen/axis_profile.hpp"
#include "fblocks/plcopen/mc_coupling.hpp"
#include "fblocks/plcopen/plcopen.hpp"
#include "runtime/core/pin_decl.hpp"

namespace syncplc::plcopen {
namespace mc_gear {

enum : int {
  kGiExecute = 0, kGiNumerator, kGiDenominator, kGiSource, kGiAcceleration, kGiDeceleration, kGiJerk, kGiBuffer,
  kGiInGear, kGiBusy, kGiActive, kGiAborted, kGiError, kGiErrorId,
};

// An acceleration-like input as the moves take it (axis_commands.cpp): finite,
// >= 0, 0 = the slave's maximum, above it refused.
bool resolve_rate(double* v, double max) noexcept {
  if (!std::isfinite(*v) || *v < 0 || *v > max) return false;
  if (*v == 0) *v = max;
  return true;
}

class GearIn final : public CouplingBlock {
 public:
  explicit GearIn(double T) noexcept { T_ = T; }

  void execute(ScanContext& ctx) noexcept override {
    run(ctx, in<bool>(kGiExecute));
    out<bool>(kGiInGear, out_.in_sync);
    out<bool>(kGiBusy, out_.busy);
    out<bool>(kGiActive, out_.active);
    out<bool>(kGiAborted, out_.aborted);
    out<bool>(kGiError, out_.error);
    out<std::uint16_t>(kGiErrorId, out_.error_id);
  }

 private:
  AxisError sample_inputs() noexcept override {
    const auto num = in<std::int16_t>(kGiNumerator);
    const auto den = in<std::uint16_t>(kGiDenominator);
    if (den == 0) return AxisError::BadSyncInput;
    ratio_ = static_cast<double>(num) / static_cast<double>(den);
    if (const AxisError e = coupling_common(in<std::int16_t>(kGiSource), in<std::int16_t>(kGiBuffer), &source_, &buffer_);
        e != AxisError::None)
      return e;
    const AxisLimits& l = slave_->machine().limits();
    acc_ = in<double>(kGiAcceleration);
    dec_ = in<double>(kGiDeceleration);
    if (!resolve_rate(&acc_, l.a_max)) return AxisError::BadAcceleration;
    if (!resolve_rate(&dec_, l.d_max)) return AxisError::BadDeceleration;
    // Not jerk-limited yet: a jerk asked for is refused, not ignored.
    const double jerk = in<double>(kGiJerk);
    if (!std::isfinite(jerk) || jerk != 0) return AxisError::BadJerk;
    return AxisError::None;
  }

  void on_start(const MasterSample&) noexcept override {
    locked_ = false;
    out_.in_sync = false;
  }

  void next_sample(const MasterSample& m, motion::FilterState* next, bool* done) noexcept override {
    *done = false;  // a gear never ends by itself
    if (locked_) {
      out_.in_sync = synced_scans_ > lock_scan_;  // the slave's set values are the locked ones
      *next = {slave_at_lock_ + ratio_ * (m.x - master_at_lock_), ratio_ * m.v};
      return;
    }
    // Velocity gearing first: a ramp to ratio times the master's velocity
    // (a target that moves while the master accelerates).
    const AxisMachine& s = slave_->machine();
    const ProfileStep p = ramp_step({s.set_position(), s.set_velocity()}, ratio_ * m.v, acc_, dec_, T_);
    *next = p.next;
    if (p.done) {
      locked_ = true;
      lock_scan_ = synced_scans_;
      slave_at_lock_ = p.next.x;
      master_at_lock_ = m.x;
    }
  }

  double ratio_ = 1, acc_ = 0, dec_ = 0;
  bool locked_ = false;
  std::int64_t lock_scan_ = 0;
  double slave_at_lock_ = 0, master_at_lock_ = 0;
};

// MC_GearOut / MC_CamOut: Execute, Done, Busy, Error, ErrorID.
enum : int { kOutExecute = 0, kOutDone, kOutBusy, kOutError, kOutErrorId };

class CouplingOut final : public McBlock {
 public:
  void execute(ScanContext& ctx) noexcept override {
    const AxisMachine* m = axis_ ? &axis_->machine() : nullptr;
    tracker_.update(in<bool>(kOutExecute), m, [&](AxisError* e) -> CommandId {
      Command c;
      c.kind = CommandKind::SyncOut;
      return axis_->submit(c, ctx.block, e);
    });
    const ExecuteOutputs& o = tracker_.outputs();
    out<bool>(kOutDone, o.done);
    out<bool>(kOutBusy, o.busy);
    out<bool>(kOutError, o.error);
    out<std::uint16_t>(kOutErrorId, o.error_id);
  }

 protected:
  void axis_changed() noexcept override { tracker_.axis_changed(); }

 private:
  ExecuteTracker tracker_;
};

std::unique_ptr<Block> make_gear_in(BlockSetup& s) {
  return std::make_unique<GearIn>(static_cast<double>(s.task_period_ns()) * 1e-9);
}

void add_out(BlockRegistry& r, const char* name, const char* section, const char* what) {
  BlockTypeInfo t;
  t.name = name;
  t.category = kCategory;
  t.doc = std::string("Ends the slave's ") + what +
          " (any coupling of MC_GearIn or MC_CamIn): the slave keeps the set velocity it has and goes to "
          "ContinuousMotion, as an MC_MoveVelocity at that velocity would; Done at once. Outside SynchronizedMotion "
          "refused with ErrorID 0x0105.";
  t.reference = std::string("PLCopen Motion Control Part 1 v2.0, ") + section + " and 2.4.1";
  t.pins = {
      input("Execute", IecType::BOOL).doc("rising edge: the slave leaves the coupling"),
      output("Done", IecType::BOOL).doc("the slave left the coupling and keeps its velocity"),
      output("Busy", IecType::BOOL).doc("the command has not ended"),
      output("Error", IecType::BOOL).doc("refused: the slave is not in SynchronizedMotion (0x0105), or no slave"),
      output("ErrorID", IecType::WORD).doc("why (docs/motion/plcopen.md, \"Error IDs\")"),
  };
  t.links = {LinkDecl{"Slave", kAxisType, "the MC_AXIS instance that leaves its coupling"}};
  t.create = [](BlockSetup&) -> std::unique_ptr<Block> { return std::make_unique<CouplingOut>(); };
  r.add(std::move(t));
}

}  // namespace mc_gear

void register_gear_blocks(BlockRegistry& r) {
  using namespace mc_gear;
  BlockTypeInfo t;
  t.name = "MC_GearIn";
  t.category = kCategory;
  t.doc =
      "Couples the Slave axis to the Master axis with the ratio RatioNumerator/RatioDenominator "
      "(SynchronizedMotion): the slave's velocity ramps with Acceleration and Deceleration to ratio times the "
      "master's, then the positions lock (InGear): slave = slave at the lock + ratio (master - master at the lock), "
      "exact and without drift. The master value is its set value (MasterValueSource 0, exact: the slave's set "
      "values of a scan are those of the master's of the same scan) or its actual value (1, extrapolated by one "
      "scan). A sample beyond the slave's velocity or acceleration limits puts the slave in ErrorStop (0x0309); a "
      "master Disabled or in ErrorStop ends the coupling with Error 0x0107 and the slave brakes with its "
      "MaxDecelerationAppl. BufferMode 0 Aborting or 1 Buffered. Ended by MC_GearOut (CommandAborted here).";
  t.reference = "PLCopen Motion Control Part 1 v2.0, 4.4 and 2.4.1";
  t.pins = {
      input("Execute", IecType::BOOL).doc("rising edge: the coupling starts, with the inputs sampled now"),
      input("RatioNumerator", IecType::INT).init("1").doc("gear ratio numerator (negative: the slave runs the other way)"),
      input("RatioDenominator", IecType::UINT).init("1").doc("gear ratio denominator, > 0"),
      input("MasterValueSource", IecType::INT).init("0").doc("MC_SOURCE: 0 the master's set value, 1 its actual value"),
      input("Acceleration", IecType::LREAL).doc("of the slave until InGear, user units/s^2; 0: its MaxAccelerationAppl"),
      input("Deceleration", IecType::LREAL).doc("of the slave until InGear, user units/s^2; 0: its MaxDecelerationAppl"),
      input("Jerk", IecType::LREAL).doc("user units/s^3; 0: not jerk-limited (jerk-limited profiles: not yet)"),
      input("BufferMode", IecType::INT).init("0").doc("MC_BUFFER_MODE: 0 Aborting, 1 Buffered (blending: refused)"),
      output("InGear", IecType::BOOL).doc("the slave's set position is locked to the master's"),
      output("Busy", IecType::BOOL).doc("the command has not ended"),
      output("Active", IecType::BOOL).doc("the command has control of the slave"),
      output("CommandAborted", IecType::BOOL).doc("another command (MC_GearOut too) or MC_Power off ended it"),
      output("Error", IecType::BOOL).doc("refused, the slave went to ErrorStop, or the master failed"),
      output("ErrorID", IecType::WORD).doc("why (docs/motion/plcopen.md, \"Error IDs\")"),
  };
  t.links = {LinkDecl{"Master", kAxisType, "the MC_AXIS instance the slave follows"},
             LinkDecl{"Slave", kAxisType, "the MC_AXIS instance coupled to the master"}};
  t.create = make_gear_in;
  r.add(std::move(t));
  add_out(r, "MC_GearOut", "4.5", "gearing");
  add_out(r, "MC_CamOut", "4.3", "camming");
}

}  // namespace syncplc::plcopen
