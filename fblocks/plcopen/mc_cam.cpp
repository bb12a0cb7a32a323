// MC_CamIn (PLCopen Part 1 v2.0 §4.2): the slave follows a cam profile of the
// master's position, the table given as the block's array inputs
// MasterPositions / SlavePositions (n points, sampled at Execute's edge; the
// standard's MC_CamTableSelect is folded into the block: Periodic and the
// interpolation are inputs too). Master coordinate of the table
// u = (master - MasterOffset) / MasterScaling (StartMode absolute) or
// u = first master point + (master - master at the start - MasterOffset) /
// MasterScaling (relative); slave = SlaveScaling f(u) + SlaveOffset
// (absolute) or slave at the start + SlaveScaling (f(u) - first slave point)
// + SlaveOffset (relative).
#include <cmath>
#include <memory>
#include <vector>

#include "fblocks/plcopen/cam_profile.hpp"
#include "fblocks/plcopen/mc_coupling.hpp"
#include "fblocks/plcopen/plcopen.hpp"
#include "runtime/core/pin_decl.hpp"

namespace syncplc::plcopen {
namespace mc_cam {

enum : int {
  kCiExecute = 0, kCiMasterOffset, kCiSlaveOffset, kCiMasterScaling, kCiSlaveScaling, kCiStartMode, kCiSource,
  kCiPeriodic, kCiInterpolation, kCiBuffer, kCiMasterPositions, kCiSlavePositions,
  kCiInSync, kCiBusy, kCiActive, kCiAborted, kCiError, kCiErrorId, kCiEndOfProfile,
};

class CamIn final : public CouplingBlock {
 public:
  CamIn(std::uint32_t n, double T) : n_(n), profile_(n), m_(n), s_(n) { T_ = T; }

  void execute(ScanContext& ctx) noexcept override {
    end_of_profile_ = false;
    run(ctx, in<bool>(kCiExecute));
    out<bool>(kCiInSync, out_.in_sync);
    out<bool>(kCiBusy, out_.busy);
    out<bool>(kCiActive, out_.active);
    out<bool>(kCiAborted, out_.aborted);
    out<bool>(kCiError, out_.error);
    out<std::uint16_t>(kCiErrorId, out_.error_id);
    out<bool>(kCiEndOfProfile, end_of_profile_);
  }

 private:
  AxisError sample_inputs() noexcept override {
    if (const AxisError e = coupling_common(in<std::int16_t>(kCiSource), in<std::int16_t>(kCiBuffer), &source_, &buffer_);
        e != AxisError::None)
      return e;
    master_offset_ = in<double>(kCiMasterOffset);
    slave_offset_ = in<double>(kCiSlaveOffset);
    master_scaling_ = in<double>(kCiMasterScaling);
    slave_scaling_ = in<double>(kCiSlaveScaling);
    const auto mode = in<std::int16_t>(kCiStartMode);
    const auto how = in<std::int16_t>(kCiInterpolation);
    if (!std::isfinite(master_offset_) || !std::isfinite(slave_offset_) || !std::isfinite(master_scaling_) ||
        !std::isfinite(slave_scaling_) || master_scaling_ == 0 || slave_scaling_ == 0 || (mode != 0 && mode != 1) ||
        (how != 0 && how != 1))
      return AxisError::BadSyncInput;
    relative_ = mode == 1;
    for (std::uint32_t i = 0; i < n_; ++i) {
      m_[i] = in<double>(kCiMasterPositions, i);
      s_[i] = in<double>(kCiSlavePositions, i);
    }
    if (!profile_.load(m_.data(), s_.data(), n_, static_cast<CamProfile::Interpolation>(how), in<bool>(kCiPeriodic)))
      return AxisError::BadSyncInput;  // not strictly increasing, or not finite
    return AxisError::None;
  }

  void on_start(const MasterSample& now) noexcept override {
    master_at_start_ = now.x;
    base_ = relative_ ? slave_->machine().set_position() - slave_scaling_ * profile_.first_slave() + slave_offset_
                      : slave_offset_;
    double s = 0, ds = 0;
    profile_.eval(table_u(now.x), &s, &ds, &period_);
    out_.in_sync = false;
  }

  double table_u(double master) const noexcept {
    return relative_ ? profile_.first_master() + (master - master_at_start_ - master_offset_) / master_scaling_
                     : (master - master_offset_) / master_scaling_;
  }

  void next_sample(const MasterSample& m, motion::FilterState* next, bool* done) noexcept override {
    out_.in_sync = synced_scans_ >= 1;  // the slave's set values are the cam's
    double s = 0, ds = 0;
    long long period = 0;
    profile_.eval(table_u(m.x), &s, &ds, &period);
    *next = {base_ + slave_scaling_ * s, slave_scaling_ * ds * m.v / master_scaling_};
    // The end of the profile: a periodic cam's every wrap (either way), a
    // single shot's passing its last master point forwards.
    const bool end = profile_.periodic() ? period != period_ : (period == 1 && period_ != 1);
    period_ = period;
    end_of_profile_ = end;
    *done = end;  // a buffered command takes over here (cam switching)
  }

  std::uint32_t n_;
  CamProfile profile_;
  std::vector<double> m_, s_;
  double master_offset_ = 0, slave_offset_ = 0, master_scaling_ = 1, slave_scaling_ = 1;
  bool relative_ = false, end_of_profile_ = false;
  double master_at_start_ = 0, base_ = 0;
  long long period_ = 0;
};

std::unique_ptr<Block> make_cam_in(BlockSetup& s) {
  const auto n = static_cast<std::uint32_t>(s.param<std::int32_t>("n"));
  return std::make_unique<CamIn>(n, static_cast<double>(s.task_period_ns()) * 1e-9);
}

}  // namespace mc_cam

void register_cam_blocks(BlockRegistry& r) {
  using namespace mc_cam;
  BlockTypeInfo t;
  t.name = "MC_CamIn";
  t.category = kCategory;
  t.doc =
      "Couples the Slave axis to the Master axis by a cam profile (SynchronizedMotion): the table of n points "
      "MasterPositions (strictly increasing) / SlavePositions, interpolated linearly (Interpolation 0) or by a cubic "
      "spline (1: natural for a single shot, periodic for a periodic cam), sampled at Execute's edge. Table master "
      "coordinate u = (master - MasterOffset) / MasterScaling (StartMode 0, absolute) or from the master's position at "
      "the start (1, relative); slave = SlaveScaling f(u) + SlaveOffset (absolute) or from the slave's position at the "
      "start (relative, no jump). Periodic: the profile repeats, the slave advancing by the table's rise each period; "
      "single shot: the slave holds the last value past the end. EndOfProfile pulses for one scan at each end of the "
      "profile; a command buffered behind takes over there (cam switching). A sample beyond the slave's limits puts "
      "it in ErrorStop (0x0309); a master Disabled or in ErrorStop ends the coupling with Error 0x0107 and the slave "
      "brakes. Ended by MC_CamOut (CommandAborted here).";
  t.reference = "PLCopen Motion Control Part 1 v2.0, 4.1, 4.2 and 2.4.1";
  t.pins = {
      input("Execute", IecType::BOOL).doc("rising edge: the coupling starts, with the inputs and the table sampled now"),
      input("MasterOffset", IecType::LREAL).doc("master position of the table's origin, user units of the master"),
      input("SlaveOffset", IecType::LREAL).doc("added to the slave's profile, user units of the slave"),
      input("MasterScaling", IecType::LREAL).init("1").doc("master distance per table master unit, != 0"),
      input("SlaveScaling", IecType::LREAL).init("1").doc("slave distance per table slave unit, != 0"),
      input("StartMode", IecType::INT).init("0").doc("0 absolute (a jump is possible), 1 relative to where master and slave are"),
      input("MasterValueSource", IecType::INT).init("0").doc("MC_SOURCE: 0 the master's set value, 1 its actual value"),
      input("Periodic", IecType::BOOL).init("TRUE").doc("TRUE periodic, FALSE single shot"),
      input("Interpolation", IecType::INT).init("0").doc("0 linear, 1 cubic spline"),
      input("BufferMode", IecType::INT).init("0").doc("MC_BUFFER_MODE: 0 Aborting, 1 Buffered (starts at the end of the profile before)"),
      input("MasterPositions", IecType::LREAL).array("n").doc("the table's master positions, strictly increasing"),
      input("SlavePositions", IecType::LREAL).array("n").doc("the table's slave positions"),
      output("InSync", IecType::BOOL).doc("the slave's set values are on the profile"),
      output("Busy", IecType::BOOL).doc("the command has not ended"),
      output("Active", IecType::BOOL).doc("the command has control of the slave"),
      output("CommandAborted", IecType::BOOL).doc("another command (MC_CamOut, the next cam) or MC_Power off ended it"),
      output("Error", IecType::BOOL).doc("refused, the slave went to ErrorStop, or the master failed"),
      output("ErrorID", IecType::WORD).doc("why (docs/motion/plcopen.md, \"Error IDs\")"),
      output("EndOfProfile", IecType::BOOL).doc("one scan at each end of the profile (the slave is given the sample past it)"),
  };
  t.params = {parameter("n", IecType::DINT).min(2.0).max(4096.0).doc("number of points of the cam table")};
  t.links = {LinkDecl{"Master", kAxisType, "the MC_AXIS instance the slave follows"},
             LinkDecl{"Slave", kAxisType, "the MC_AXIS instance coupled to the master"}};
  t.create = make_cam_in;
  r.add(std::move(t));
}

}  // namespace syncplc::plcopen
