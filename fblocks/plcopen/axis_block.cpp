// MC_AXIS (axis_block.hpp): the scan of one axis and its declaration.
#include "fblocks/plcopen/axis_block.hpp"

#include <cmath>
#include <memory>

#include "fblocks/plcopen/plcopen.hpp"
#include "runtime/core/pin_decl.hpp"

namespace syncplc::plcopen {

void AxisBlock::execute(ScanContext& ctx) noexcept {
  (void)ctx;
  DriveFeedback fb = next_;
  // No sample since the last scan: the first scan, or a drive input was not
  // finite (the guard skipped end_of_scan). Never acted on as if fresh.
  if (!sampled_) fb.valid = false;
  sampled_ = false;
  hmi_permissive();
  machine_.cycle(fb);
  hmi_reset();
  const DriveCommand& d = machine_.drive_command();
  out<bool>(kAxEnable, d.enable);
  out<bool>(kAxReset, d.reset);
  out<double>(kAxDrivePosition, d.position * scale_);
  out<double>(kAxDriveVelocity, d.velocity * scale_);
  out<double>(kAxDriveAcceleration, d.acceleration * scale_);
  out<std::int16_t>(kAxState, static_cast<std::int16_t>(machine_.state()));
  out<double>(kAxPosition, machine_.actual_position());
  out<double>(kAxVelocity, machine_.actual_velocity());
  out<double>(kAxSetPosition, machine_.user_position(machine_.set_position()));
  out<double>(kAxSetVelocity, machine_.set_velocity());
  out<double>(kAxFollowingError, machine_.following_error());
  out<bool>(kAxError, machine_.state() == AxisState::ErrorStop);
  out<std::uint16_t>(kAxErrorId, static_cast<std::uint16_t>(machine_.axis_error()));
  out<std::uint16_t>(kAxDriveFaultCode, machine_.drive_fault_code());
  out<bool>(kAxHomed, machine_.homed());
  const CommandId active = machine_.active_command();
  out<std::int16_t>(kAxCommand, active ? static_cast<std::int16_t>(static_cast<int>(machine_.active_kind()) + 1) : 0);
  out<std::int32_t>(kAxCommandBlock, source_of(active));
  out<std::int64_t>(kAxRemainingScans, machine_.remaining_scans());
  out<bool>(kAxHome, d.home);
  out<std::int16_t>(kAxDriveHomeMethod, static_cast<std::int16_t>(machine_.homing().method));
  out<double>(kAxDriveHomePosition, d.home_position * scale_);
  out<bool>(kAxPowered, machine_.power_on());
}

void AxisBlock::hmi_permissive() noexcept {
  // ANDed with MC_Power.Enable: MC_Power asked for power in the scan before
  // (after that scan's cycle); withdrawn here, this cycle takes the axis to
  // Disabled exactly as MC_Power.Enable FALSE does. MC_Power asks again every
  // scan, so the permissive holds the axis down while it is FALSE and never
  // powers an axis whose MC_Power does not ask.
  if (!in<bool>(kAxHmiEnable)) machine_.request_power(false);
}

void AxisBlock::hmi_reset() noexcept {
  if (!in<bool>(kAxHmiReset)) return;
  // MC_Reset's rising edge: outside ErrorStop nothing to do. While the axis
  // still brakes (StillMoving) the request waits for it to stand, as the
  // machine's own pending reset waits for a drive fault to clear.
  if (machine_.reset() != AxisError::StillMoving || machine_.state() != AxisState::ErrorStop)
    out<bool>(kAxHmiReset, false);
}

void AxisBlock::end_of_scan() noexcept {
  DriveFeedback fb;
  fb.position = in<double>(kAxActualPosition) / scale_;
  if (velocity_wired_) {
    fb.velocity = in<double>(kAxActualVelocity) / scale_;
  } else {
    // The backward difference over one period: what a drive without a
    // velocity object would report.
    fb.velocity = have_position_ ? (fb.position - last_position_) / machine_.period() : 0.0;
  }
  last_position_ = fb.position;
  have_position_ = true;
  fb.valid = in<bool>(kAxFeedbackOk);
  // Unwired, the power stage is an ideal drive's: on one scan after the
  // enable output asked for it. The HMI's permissive holds the enable that
  // went out FALSE, though MC_Power asked again after this scan's cycle.
  fb.power_on = power_wired_ ? in<bool>(kAxPowerOn) : machine_.drive_command().enable && in<bool>(kAxHmiEnable);
  fb.fault = in<bool>(kAxFault);
  fb.fault_code = in<std::uint16_t>(kAxFaultCode);
  fb.home_switch = in<bool>(kAxHomeSwitch);
  fb.homing_attained = in<bool>(kAxHomingAttained);
  fb.homing_error = in<bool>(kAxHomingError);
  next_ = fb;
  sampled_ = true;
}

CommandId AxisBlock::submit(const Command& c, std::int32_t block, AxisError* error) noexcept {
  const CommandId id = machine_.submit(c, error);
  // Remembered for the active one and those buffered behind it: the ring
  // holds more entries than can wait at once.
  if (id) sources_[next_source_++ % sources_.size()] = {id, block};
  return id;
}

std::int32_t AxisBlock::source_of(CommandId id) const noexcept {
  if (id)
    for (const auto& [cid, block] : sources_)
      if (cid == id) return block;
  return -1;
}

void AxisBlock::retune_from(const Block& fresh) noexcept {
  const auto& f = static_cast<const AxisBlock&>(fresh);
  limits_ = f.limits_;
  machine_.retune(limits_);
  HomingConfig h = machine_.homing();  // home_method is tunable too
  h.method = f.machine_.homing().method;
  machine_.configure_homing(h);
}

namespace {

enum AxisParam : int {
  kApScale = 0,
  kApVMax,
  kApAMax,
  kApDMax,
  kApJMax,
  kApLimitPos,
  kApLimitNeg,
  kApLimitPosOn,
  kApLimitNegOn,
  kApMaxLag,
  kApModulo,
  kApHomeMode,
  kApHomeVelocity,
  kApHomeMaxDistance,
  kApHomeMethod,
  kApHomeTimeout,
};

std::unique_ptr<Block> make_axis(BlockSetup& s) {
  AxisLimits l;
  const double scale = s.param_cell(kApScale).get<double>();
  l.v_max = s.param_cell(kApVMax).get<double>();
  l.a_max = s.param_cell(kApAMax).get<double>();
  l.d_max = s.param_cell(kApDMax).get<double>();
  l.j_max = s.param_cell(kApJMax).get<double>();
  l.sw_limit_pos = s.param_cell(kApLimitPos).get<double>();
  l.sw_limit_neg = s.param_cell(kApLimitNeg).get<double>();
  l.sw_limit_pos_on = s.param_cell(kApLimitPosOn).get<bool>();
  l.sw_limit_neg_on = s.param_cell(kApLimitNegOn).get<bool>();
  l.max_position_lag = s.param_cell(kApMaxLag).get<double>();
  l.modulo = s.param_cell(kApModulo).get<double>();
  bool ok = true;
  auto need = [&](bool cond, const char* what) {
    if (!cond) {
      s.error(std::string(kAxisType) + ": " + what);
      ok = false;
    }
  };
  need(std::isfinite(scale) && scale != 0, "scale must be finite and not 0");
  need(std::isfinite(l.v_max) && l.v_max > 0, "v_max must be finite and > 0");
  need(std::isfinite(l.a_max) && l.a_max > 0, "a_max must be finite and > 0");
  need(std::isfinite(l.d_max) && l.d_max > 0, "d_max must be finite and > 0");
  need(std::isfinite(l.j_max) && l.j_max >= 0, "j_max must be finite and >= 0");
  need(std::isfinite(l.sw_limit_pos) && std::isfinite(l.sw_limit_neg), "software limits must be finite");
  need(!(l.sw_limit_pos_on && l.sw_limit_neg_on) || l.sw_limit_neg < l.sw_limit_pos,
       "sw_limit_neg must be below sw_limit_pos when both are on");
  need(std::isfinite(l.max_position_lag) && l.max_position_lag >= 0, "max_position_lag must be finite and >= 0");
  need(std::isfinite(l.modulo) && l.modulo >= 0, "modulo must be finite and >= 0");
  need(l.modulo == 0 || !(l.sw_limit_pos_on || l.sw_limit_neg_on), "a modulo axis has no software limits");
  HomingConfig h;
  const std::int16_t mode = s.param_cell(kApHomeMode).get<std::int16_t>();
  h.mode = static_cast<HomingConfig::Mode>(mode);
  h.velocity = s.param_cell(kApHomeVelocity).get<double>();
  h.max_distance = s.param_cell(kApHomeMaxDistance).get<double>();
  h.method = s.param_cell(kApHomeMethod).get<std::int16_t>();
  h.timeout_s = s.param_cell(kApHomeTimeout).get<double>();
  need(mode >= 0 && mode <= 3,
       "home_mode must be 0 (set here), 1 (switch, positive), 2 (switch, negative) or 3 (the drive homes)");
  need(mode != 3 || (h.method >= -128 && h.method <= 127), "home_method must be -128..127 (6098h is an INTEGER8)");
  need(mode != 3 || (std::isfinite(h.timeout_s) && h.timeout_s > 0), "home_timeout must be finite and > 0 for home_mode 3");
  need(mode == 0 || mode == 3 || (std::isfinite(h.velocity) && h.velocity > 0 && h.velocity <= l.v_max),
       "home_velocity must be > 0 and <= v_max for a switch search (home_mode 1 or 2)");
  need(std::isfinite(h.max_distance) && h.max_distance >= 0, "home_max_distance must be finite and >= 0");
  if (!ok) return nullptr;
  const double period_s = static_cast<double>(s.task_period_ns()) * 1e-9;
  auto axis = std::make_unique<AxisBlock>(l, period_s, scale, s.connected(kAxActualVelocity), s.connected(kAxPowerOn));
  axis->machine().configure_homing(h);
  return axis;
}

// The limits with parameter `param` set to v, or false when they would not
// be valid (what make_axis checks).
bool with_param(AxisLimits* l, int param, double v) noexcept {
  switch (param) {
    case kApVMax: if (!(v > 0)) return false; l->v_max = v; break;
    case kApAMax: if (!(v > 0)) return false; l->a_max = v; break;
    case kApDMax: if (!(v > 0)) return false; l->d_max = v; break;
    case kApJMax: if (!(v >= 0)) return false; l->j_max = v; break;
    case kApLimitPos: l->sw_limit_pos = v; break;
    case kApLimitNeg: l->sw_limit_neg = v; break;
    case kApMaxLag: if (!(v >= 0)) return false; l->max_position_lag = v; break;
    default: return false;
  }
  return std::isfinite(v) && (!(l->sw_limit_pos_on && l->sw_limit_neg_on) || l->sw_limit_neg < l->sw_limit_pos);
}

}  // namespace

bool AxisBlock::tune(int param, double value) noexcept {
  if (param == kApHomeMethod) {
    // The drive's homing method, for the next MC_Home (a homing under way
    // keeps the method its drive started with).
    if (!(value >= -128 && value <= 127 && value == std::floor(value))) return false;
    HomingConfig h = machine_.homing();
    h.method = static_cast<int>(value);
    machine_.configure_homing(h);
    return true;
  }
  AxisLimits next = limits_;
  if (!with_param(&next, param, value)) return false;
  limits_ = next;
  machine_.retune(limits_);
  return true;
}

void register_axis(BlockRegistry& r) {
  BlockTypeInfo t;
  t.name = kAxisType;
  t.category = kCategory;
  t.doc =
      "One axis of PLCopen Motion Control (the AXIS_REF the MC_* blocks name with params: {Axis: <this instance>}): "
      "the axis state diagram (Disabled, Standstill, Homing, DiscreteMotion, ContinuousMotion, "
      "SynchronizedMotion, Stopping, ErrorStop), the commands of its MC_* blocks with their BufferMode, and the "
      "set values of the active command every scan (discrete moves: paper 004's nonlinear filter, so velocity "
      "and acceleration stay within their limits and the arrival is exact). Wire its drive side to a "
      "CIA402_DRIVE, to a position controller of a sim_table axis, or to a SIM_SERVO: actual_position (and "
      "optionally actual_velocity, power_on, fault, fault_code, feedback_ok, home_switch, homing_attained, "
      "homing_error) in, enable, reset, drive_position/velocity/acceleration (and home, drive_home_method, "
      "drive_home_position for a drive that homes itself, home_mode 3) out, in drive units (user units x scale). A unit delay: it runs "
      "first in the scan, from the feedback sampled at the end of the scan before. Unwired power_on follows "
      "enable one scan later (an ideal drive). The limits are tunable: an online change or a tuning input "
      "changes them on the running axis, which keeps its state and its motion (the *Appl values return to the "
      "new limits; commands already given act within them from the next scan). See docs/motion/plcopen.md.";
  t.reference = "PLCopen Motion Control Part 1 v2.0, sections 2.1-2.4; paper 004 (Guarino Lo Bianco), eqs. 1-22";
  t.pins = {
      input("actual_position", IecType::LREAL).unit("unit").required().doc("actual position from the drive, drive units"),
      input("actual_velocity", IecType::LREAL).unit("unit/s")
          .doc("actual velocity, drive units/s; unwired: the backward difference of actual_position"),
      input("feedback_ok", IecType::BOOL).init("TRUE")
          .doc("the actual values come from a good exchange (FALSE: ErrorStop FeedbackLost unless Disabled)"),
      input("power_on", IecType::BOOL).doc("the power stage is on (CIA402_DRIVE.operation_enabled); unwired: enable one scan later"),
      input("fault", IecType::BOOL).doc("the drive is in fault: ErrorStop DriveFault"),
      input("fault_code", IecType::UINT).doc("the drive's error code (CiA 402 603Fh)"),
      input("home_switch", IecType::BOOL).doc("reference switch, for MC_Home with home_mode 1 or 2"),
      input("homing_attained", IecType::BOOL).doc("the drive's homing completed (CIA402_DRIVE.homing_attained), home_mode 3"),
      input("homing_error", IecType::BOOL).doc("the drive's homing failed (CIA402_DRIVE.homing_error): ErrorStop 0x0307"),
      output("enable", IecType::BOOL).doc("power stage on (to CIA402_DRIVE.enable)"),
      output("reset", IecType::BOOL).doc("fault reset request, held while MC_Reset waits for the drive"),
      output("drive_position", IecType::LREAL).unit("unit").doc("set position in drive units"),
      output("drive_velocity", IecType::LREAL).unit("unit/s").doc("set velocity in drive units/s (feed-forward)"),
      output("drive_acceleration", IecType::LREAL).unit("unit/s^2").doc("set acceleration in drive units/s^2"),
      output("state", IecType::INT)
          .doc("0 Disabled, 1 Standstill, 2 Homing, 3 DiscreteMotion, 4 ContinuousMotion, 5 SynchronizedMotion, "
               "6 Stopping, 7 ErrorStop"),
      output("position", IecType::LREAL).doc("actual position, user units (wrapped on a modulo axis)"),
      output("velocity", IecType::LREAL).doc("actual velocity, user units/s"),
      output("set_position", IecType::LREAL).doc("set position, user units (wrapped on a modulo axis)"),
      output("set_velocity", IecType::LREAL).doc("set velocity, user units/s"),
      output("following_error", IecType::LREAL).doc("set position minus actual position, user units"),
      output("error", IecType::BOOL).doc("the axis is in ErrorStop"),
      output("error_id", IecType::WORD).doc("the axis error (docs/motion/plcopen.md, \"Error IDs\"), 0 none"),
      output("drive_fault_code", IecType::WORD).doc("the drive's error code seen at its fault"),
      output("homed", IecType::BOOL).doc("MC_Home completed since the axis was made"),
      output("command", IecType::INT)
          .doc("active command: 0 none, 1 MoveAbsolute, 2 MoveRelative, 3 MoveAdditive, 4 MoveVelocity, 5 Halt, "
               "6 Stop, 7 Home, 8 a group move"),
      output("command_block", IecType::DINT).doc("the block that gave the active command (its place in the scan), -1 none"),
      output("remaining_scans", IecType::LINT)
          .doc("scans until the active discrete move arrives (paper 004 Table I), -1 without one"),
      input("hmi_enable", IecType::BOOL).init("TRUE")
          .doc("the HMI's enable permissive, ANDed with MC_Power.Enable: FALSE takes the axis to Disabled as "
               "MC_Power.Enable FALSE does; TRUE powers nothing by itself (POST /api/v1/axes/{name}/enable, /disable)"),
      input("hmi_reset", IecType::BOOL)
          .doc("the HMI's reset request: acknowledges the axis error as MC_Reset does, at the next scan; cleared by "
               "the axis once done (POST /api/v1/axes/{name}/reset)"),
      output("powered", IecType::BOOL).doc("the power stage reports on"),
      output("home", IecType::BOOL).doc("home_mode 3: TRUE while MC_Home waits for the drive's homing (to CIA402_DRIVE.home)"),
      output("drive_home_method", IecType::INT).doc("the home_method parameter (to CIA402_DRIVE.home_method)"),
      output("drive_home_position", IecType::LREAL).unit("unit")
          .doc("MC_Home's Position in drive units, the home offset (to CIA402_DRIVE.home_position)"),
  };
  t.params = {
      parameter("scale", IecType::LREAL).init("1").unit("unit/unit").doc("drive units per user unit (counts/mm, rad/rad)"),
      parameter("v_max", IecType::LREAL).init("1").min(0.0).tunable().doc("MaxVelocitySystem, user units/s"),
      parameter("a_max", IecType::LREAL).init("10").min(0.0).tunable().doc("MaxAccelerationSystem, user units/s^2"),
      parameter("d_max", IecType::LREAL).init("10").min(0.0).tunable().doc("MaxDecelerationSystem, user units/s^2"),
      parameter("j_max", IecType::LREAL).init("0").min(0.0).tunable().doc("MaxJerkSystem, user units/s^3 (0: none)"),
      parameter("sw_limit_pos", IecType::LREAL).init("0").tunable().doc("SWLimitPos, user units"),
      parameter("sw_limit_neg", IecType::LREAL).init("0").tunable().doc("SWLimitNeg, user units"),
      parameter("limit_pos", IecType::BOOL).init("FALSE").doc("EnableLimitPos"),
      parameter("limit_neg", IecType::BOOL).init("FALSE").doc("EnableLimitNeg"),
      parameter("max_position_lag", IecType::LREAL).init("0").min(0.0).tunable()
          .doc("MaxPositionLag, user units: a larger following error is ErrorStop (0: not monitored)"),
      parameter("modulo", IecType::LREAL).init("0").min(0.0).doc("modulo of a rotary axis, user units (0: linear)"),
      parameter("home_mode", IecType::INT).init("0").min(0.0).max(3.0)
          .doc("MC_Home's procedure: 0 set here, 1 search the home_switch's rising edge moving in +, 2 moving in -, "
               "3 the drive homes itself (CiA 402 homing mode with home_method)"),
      parameter("home_velocity", IecType::LREAL).init("0").min(0.0).doc("search velocity, user units/s (home_mode 1, 2)"),
      parameter("home_max_distance", IecType::LREAL).init("0").min(0.0)
          .doc("a search longer than this is ErrorStop HomingFailed, user units (0: unbounded)"),
      parameter("home_method", IecType::INT).init("37").min(-128.0).max(127.0).tunable()
          .doc("home_mode 3: the drive's homing method 6098h (35/37 current position, 17/18 limit switch, ...)"),
      parameter("home_timeout", IecType::LREAL).init("60").min(0.0).unit("s")
          .doc("home_mode 3: longest wait for the drive's homing attained before ErrorStop 0x0308"),
  };
  t.unit_delay = true;
  t.create = make_axis;
  r.add(std::move(t));
}

}  // namespace syncplc::plcopen
