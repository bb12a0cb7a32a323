// CIA402_DRIVE: the master side of one CiA 402 (IEC 61800-7-201/-301) drive.
// The state machine is cia402_math (Master); this file scales the targets
// and actual values between the program's units and the drive's counts,
// computes the following error and raises the events. Every pin is a plain
// tag, so the drive's objects (6040h, 6041h, 6060h, 6061h, 607Ah, 60FFh,
// 60B1h, 6071h, 6064h, 606Ch, 603Fh; for homing mode 6098h, 6099h, 609Ah,
// 607Ch, cia402_homing.hpp) can come over any bus: the Modbus
// client driver, a simulated drive, an EtherCAT master later.
// See docs/drives.md.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <memory>

#include "fblocks/drives/cia402_homing.hpp"
#include "fblocks/drives/cia402_math.hpp"
#include "fblocks/drives/drives.hpp"
#include "fblocks/motion/param_read.hpp"
#include "runtime/core/pin_decl.hpp"

namespace syncplc::drives {
namespace {

using namespace cia402;

enum : int {
  // program side, in
  kEnable = 0, kQuickStop, kReset, kMode, kPositionSet, kVelocitySet, kTorqueSet,
  kHome, kHomeMethod, kHomePosition,
  // drive side, in
  kLinkOk, kStatusword, kModesDisplay, kPositionActual, kVelocityActual, kErrorCode,
  // drive side, out
  kControlword, kModesOfOperation, kTargetPosition, kTargetVelocity, kVelocityOffset, kTargetTorque,
  kHomingMethod, kHomeOffset, kHomingSpeedSwitch, kHomingSpeedZero, kHomingAcceleration,
  // program side, out
  kState, kOperationEnabled, kBusy, kFault, kFaultCode, kWarning, kTimeout, kInMode,
  kPosition, kVelocity, kFollowingError, kFollowingErrorExceeded,
  kHoming, kHomingAttained, kHomingError,
};

// Parameter indices (declaration order below).
enum : int { kPCounts = 0, kPTorqueScale, kPIdle, kPTimeout, kPFeWindow, kPFeTime, kPDisableStop, kPLinkLostStop };

struct DriveConfig {
  double counts_per_unit = 1;
  double torque_scale = 1000;
  double timeout_s = 1;
  double fe_window = 0;  // 0 = no following error supervision
  double fe_time_s = 0;
  double home_speed_switch = 1, home_speed_zero = 0.1, home_acceleration = 10;  // units/s, units/s^2
  Goal idle = Goal::kSwitchOnDisabled;
  Stop disable = Stop::kQuickStop;
  Stop link_lost = Stop::kQuickStop;
};

MasterConfig master_config(const DriveConfig& c) {
  MasterConfig m;
  m.idle = c.idle;
  m.disable = c.disable;
  m.link_lost = c.link_lost;
  m.transition_timeout_ns = std::llround(c.timeout_s * 1e9);
  return m;
}

template <class T>
T saturate(double v) noexcept {
  constexpr double lo = static_cast<double>(std::numeric_limits<T>::min());
  constexpr double hi = static_cast<double>(std::numeric_limits<T>::max());
  if (!(v > lo)) return std::numeric_limits<T>::min();  // NaN cannot reach here (ENO guard)
  if (v >= hi) return std::numeric_limits<T>::max();
  return static_cast<T>(std::llround(v));
}

class Cia402Drive final : public Block {
 public:
  Cia402Drive(const DriveConfig& c, IecType mode_type) : c_(c), mode_type_(mode_type), m_(master_config(c)) {}

  void retune_from(const Block& fresh) noexcept override {
    const auto& f = static_cast<const Cia402Drive&>(fresh);
    c_.timeout_s = f.c_.timeout_s, c_.fe_window = f.c_.fe_window, c_.fe_time_s = f.c_.fe_time_s;
    m_.reconfigure(master_config(c_));
  }
  bool tune(int param, double v) noexcept override {
    switch (param) {
      case kPTimeout: if (!(v > 0)) return false; c_.timeout_s = v; break;
      case kPFeWindow: c_.fe_window = v; break;
      case kPFeTime: c_.fe_time_s = v; break;
      default: return false;
    }
    m_.reconfigure(master_config(c_));
    return true;
  }

  void execute(ScanContext& ctx) noexcept override {
    MasterInputs mi;
    mi.enable = in<bool>(kEnable);
    mi.quick_stop = in<bool>(kQuickStop);
    mi.reset = in<bool>(kReset);
    mi.link_ok = in<bool>(kLinkOk);
    mi.statusword = in<std::uint16_t>(kStatusword);
    mi.mode = read_mode(kMode);
    mi.mode_display = read_mode(kModesDisplay);
    const int program_mode = mi.mode;

    // Homing mode (cia402_homing.hpp): while the program asks for it the
    // drive runs in mode 6 and bit 4 of the controlword starts it. The state
    // the homing master sees is last scan's (the controlword goes out after).
    HomingInputs hi;
    hi.request = in<bool>(kHome);
    hi.enabled = last_state_ == State::kOperationEnabled && last_run_;
    hi.link_ok = mi.link_ok;
    hi.statusword = mi.statusword;
    hi.mode_display = mi.mode_display;
    const HomingOutputs ho = h_.step(hi);
    if (ho.active) mi.mode = mode::kHoming;
    const MasterOutputs mo = m_.step(mi, ctx.now_ns);
    last_state_ = mo.state;
    last_run_ = mo.run;
    // Between homing mode and the program's mode the display shows one of
    // the two for a scan or more: the drive is still enabled and holds its
    // position (no target is taken from the program until it is in mode),
    // so operation_enabled does not drop for the change.
    if (ho.active || homing_mode_seen_) homing_mode_seen_ = ho.active || mi.mode_display == mode::kHoming;
    const bool mode_changing =
        homing_mode_seen_ && (mi.mode_display == mode::kHoming || mi.mode_display == program_mode);

    const std::uint16_t error_code = in<std::uint16_t>(kErrorCode);
    if (mo.fault && error_code != 0) fault_code_ = error_code;
    if (!mo.fault && mo.state != State::kUnknown) fault_code_ = 0;
    if (mo.fault_event) raise(ctx, EventKind::DriverFault, "CIA402_DRIVE: drive fault (statusword: fault reaction active or fault)", error_code);
    if (mo.recovered_event) raise(ctx, EventKind::Info, "CIA402_DRIVE: drive fault cleared (the drive left Fault)", mi.statusword);
    if (mo.link_lost_event)
      raise(ctx, EventKind::DriverFault,
            "CIA402_DRIVE: link lost (link_ok FALSE): stop commanded, targets held; a new enable is needed", mi.statusword);
    if (mo.timeout_event)
      raise(ctx, EventKind::DriverFault,
            "CIA402_DRIVE: state transition or mode change not completed within transition_timeout", mi.statusword);

    // Targets. Position targets follow the actual position except while the
    // drive runs in the requested position mode and the goal is Operation
    // enabled, so enabling (or switching into) cyclic synchronous position,
    // or stopping, never makes the drive jump to a stale target; velocity and
    // torque targets are 0 outside their modes. While the link is down the
    // actual position is stale (or a read group's safe value): the target
    // last commanded is held, never one computed from it.
    const double k = c_.counts_per_unit;
    const std::int32_t actual = in<std::int32_t>(kPositionActual);
    const double position = actual / k;
    const bool enabled = mo.state == State::kOperationEnabled && mo.run;
    const bool pos_mode = enabled && mo.in_mode && is_position_mode(mi.mode);
    const bool vel_mode = enabled && is_velocity_mode(mi.mode);
    const bool trq_mode = enabled && is_torque_mode(mi.mode);
    const double xs = in<double>(kPositionSet), vs = in<double>(kVelocitySet);
    out<std::uint16_t>(kControlword, ho.start && mo.controlword == cw::kEnableOperationCmd
                                         ? static_cast<std::uint16_t>(mo.controlword | cw::kHomingStart)
                                         : mo.controlword);
    write_mode(kModesOfOperation, mi.mode);
    if (mi.link_ok) target_ = pos_mode ? saturate<std::int32_t>(xs * k) : actual;
    out<std::int32_t>(kTargetPosition, target_);
    out<std::int32_t>(kTargetVelocity, vel_mode ? saturate<std::int32_t>(vs * k) : 0);
    out<std::int32_t>(kVelocityOffset, pos_mode ? saturate<std::int32_t>(vs * k) : 0);
    out<std::int16_t>(kTargetTorque, trq_mode ? saturate<std::int16_t>(in<double>(kTorqueSet) * c_.torque_scale) : 0);
    // Homing objects, written whenever the bus writes them: 6098h from the
    // program (MC_AXIS's home_method), 607Ch the position the home point gets.
    out<std::int16_t>(kHomingMethod, std::clamp(in<std::int16_t>(kHomeMethod), std::int16_t{-128}, std::int16_t{127}));
    out<std::int32_t>(kHomeOffset, saturate<std::int32_t>(in<double>(kHomePosition) * k));
    out<std::uint32_t>(kHomingSpeedSwitch, saturate<std::uint32_t>(c_.home_speed_switch * k));
    out<std::uint32_t>(kHomingSpeedZero, saturate<std::uint32_t>(c_.home_speed_zero * k));
    out<std::uint32_t>(kHomingAcceleration, saturate<std::uint32_t>(c_.home_acceleration * k));

    // Following error (the master's view of 60F4h / 6065h / 6066h).
    const double fe = pos_mode ? xs - position : 0.0;
    bool exceeded = false;
    if (c_.fe_window > 0 && std::abs(fe) > c_.fe_window) {
      if (!fe_outside_) fe_since_ = ctx.now_ns, fe_outside_ = true;
      exceeded = static_cast<double>(ctx.now_ns - fe_since_) >= c_.fe_time_s * 1e9;
    } else {
      fe_outside_ = false;
    }
    if (exceeded && !fe_exceeded_)
      raise(ctx, EventKind::DriverFault, "CIA402_DRIVE: following error outside following_error_window", fe);
    fe_exceeded_ = exceeded;

    out<std::int8_t>(kState, static_cast<std::int8_t>(mo.state));
    out<bool>(kOperationEnabled,
              mo.operation_enabled || (mo.state == State::kOperationEnabled && mo.run && mode_changing));
    out<bool>(kBusy, mo.busy);
    out<bool>(kFault, mo.fault);
    out<std::uint16_t>(kFaultCode, fault_code_);
    out<bool>(kWarning, mi.link_ok && (mi.statusword & sw::kWarning) != 0);
    out<bool>(kTimeout, mo.timeout);
    out<bool>(kInMode, mo.in_mode);
    out<double>(kPosition, position);
    out<double>(kVelocity, in<std::int32_t>(kVelocityActual) / k);
    out<double>(kFollowingError, fe);
    out<bool>(kFollowingErrorExceeded, exceeded);
    out<bool>(kHoming, ho.busy);
    out<bool>(kHomingAttained, ho.attained);
    out<bool>(kHomingError, ho.error);
    if (ho.error && !homing_error_prev_)
      raise(ctx, EventKind::DriverFault,
            "CIA402_DRIVE: homing error (statusword bit 13, or the drive left Operation enabled)", mi.statusword);
    homing_error_prev_ = ho.error;
  }

 private:
  static void raise(ScanContext& ctx, EventKind kind, const char* text, double value) noexcept {
    if (ctx.events) ctx.events->push(Event{ctx.now_ns, ctx.task, ctx.block, kind, text, value});
  }
  // A mode of any ANY_INT type as an int; values no drive has (beyond
  // INTEGER16) are clamped, so the conversion is always defined.
  int read_mode(int pin) const noexcept {
    const double v = cell_as_double(mode_type_, *pin_cell(pin));
    return v < -32768.0 ? -32768 : v > 32767.0 ? 32767 : static_cast<int>(v);
  }
  void write_mode(int pin, int v) noexcept {
    Cell& c = *pin_cell(pin);
    switch (mode_type_) {
      case IecType::SINT: c.set<std::int8_t>(static_cast<std::int8_t>(v)); break;
      case IecType::INT: c.set<std::int16_t>(static_cast<std::int16_t>(v)); break;
      case IecType::DINT: c.set<std::int32_t>(v); break;
      case IecType::LINT: c.set<std::int64_t>(v); break;
      case IecType::USINT: c.set<std::uint8_t>(static_cast<std::uint8_t>(v)); break;
      case IecType::UINT: c.set<std::uint16_t>(static_cast<std::uint16_t>(v)); break;
      case IecType::UDINT: c.set<std::uint32_t>(static_cast<std::uint32_t>(v)); break;
      default: c.set<std::uint64_t>(static_cast<std::uint64_t>(v)); break;
    }
  }

  DriveConfig c_;
  IecType mode_type_;
  Master m_;
  HomingMaster h_;
  State last_state_ = State::kUnknown;
  bool last_run_ = false;
  bool homing_mode_seen_ = false;  // homing asked, and the display has not yet left 6 since
  bool homing_error_prev_ = false;
  std::uint16_t fault_code_ = 0;
  std::int32_t target_ = 0;  // the target position last commanded (held while the link is down)
  bool fe_outside_ = false, fe_exceeded_ = false;
  std::int64_t fe_since_ = 0;
};

std::unique_ptr<Block> make_cia402(BlockSetup& s) {
  bool ok = true;
  DriveConfig c;
  c.counts_per_unit = motion::ctl::real_param(s, "counts_per_unit", &ok);
  c.torque_scale = motion::ctl::real_param(s, "torque_scale", &ok);
  c.timeout_s = motion::ctl::real_param(s, "transition_timeout", &ok);
  c.fe_window = motion::ctl::real_param(s, "following_error_window", &ok);
  c.fe_time_s = motion::ctl::real_param(s, "following_error_time", &ok);
  c.home_speed_switch = motion::ctl::real_param(s, "home_speed_switch", &ok);
  c.home_speed_zero = motion::ctl::real_param(s, "home_speed_zero", &ok);
  c.home_acceleration = motion::ctl::real_param(s, "home_acceleration", &ok);
  const long long idle = motion::ctl::int_param(s, "idle_state", &ok);
  c.idle = idle == 1 ? Goal::kReadyToSwitchOn : idle == 2 ? Goal::kSwitchedOn : Goal::kSwitchOnDisabled;
  const long long disable = motion::ctl::int_param(s, "disable_stop", &ok);
  c.disable = disable == 1 ? Stop::kShutdown : disable == 2 ? Stop::kDirect : Stop::kQuickStop;
  c.link_lost = motion::ctl::int_param(s, "link_lost_stop", &ok) == 1 ? Stop::kDirect : Stop::kQuickStop;
  if (ok && !(c.counts_per_unit > 0)) {
    s.error(s.type().name + ": counts_per_unit must be greater than 0");
    ok = false;
  }
  if (ok && !(c.timeout_s > 0)) {
    s.error(s.type().name + ": transition_timeout must be greater than 0");
    ok = false;
  }
  if (ok && !(c.home_speed_switch >= 0 && c.home_speed_zero >= 0 && c.home_acceleration >= 0 &&
              std::isfinite(c.home_speed_switch + c.home_speed_zero + c.home_acceleration))) {
    s.error(s.type().name + ": home_speed_switch, home_speed_zero and home_acceleration must be finite and >= 0");
    ok = false;
  }
  if (!ok) return nullptr;
  return std::make_unique<Cia402Drive>(c, s.datatype());
}

}  // namespace

void register_cia402_drive(BlockRegistry& r) {
  BlockTypeInfo t;
  t.name = "CIA402_DRIVE";
  t.category = kCategory;
  t.default_datatype = IecType::SINT;
  t.doc =
      "Master side of one CiA 402 drive (power drive system state machine). Decodes the statusword 6041h into "
      "the eight states of the PDS state machine (state: -1 unknown, 0 Not ready to switch on, 1 Switch on "
      "disabled, 2 Ready to switch on, 3 Switched on, 4 Operation enabled, 5 Quick stop active, 6 Fault "
      "reaction active, 7 Fault) and writes the controlword 6040h command that moves the drive one transition "
      "per scan towards what the inputs ask: enable TRUE -> Operation enabled (Shutdown 16#06, Switch on "
      "16#07, Enable operation 16#0F); enable FALSE -> idle_state, leaving Operation enabled as disable_stop says "
      "(default Quick stop 16#02, held until the drive reports it stopped, so its 605Ah ramp acts; 1 Shutdown or "
      "Disable operation; 2 the direct command, Disable voltage 16#00 coasting towards idle_state 0); "
      "quick_stop TRUE -> Quick stop 16#02 (then the drive goes to Switch on disabled); a "
      "rising edge of reset in Fault -> Fault reset (bit 7 rises after a scan with it low, and stays high until "
      "the drive leaves Fault or the timeout ends). modes_of_operation (6060h) = mode; in_mode when the display "
      "(6061h) equals it. Targets in counts (x counts_per_unit): in a position mode (1, 7, 8 = CSP) while "
      "Operation enabled and in mode, target_position = position_set and velocity_offset (60B1h) = "
      "velocity_set, otherwise target_position follows position_actual (no jump on enable); in a velocity mode "
      "(3 = PV, 9 = CSV) target_velocity = velocity_set; in a torque mode (4, 10 = CST) target_torque = "
      "torque_set x torque_scale (0.1 % of rated torque); else 0. following_error = position_set - position in "
      "a position mode, following_error_exceeded when it stays outside following_error_window for "
      "following_error_time. timeout when a transition or mode change has not completed within "
      "transition_timeout. link_ok (required: wire the bus's quality flag) FALSE: state -1, the controlword is "
      "Quick stop 16#02 (link_lost_stop 1: Disable voltage 16#00), target_position holds the value last commanded, "
      "velocity and torque targets 0, timers restart; after the link returns the drive is stopped the same way "
      "until enable has been FALSE with link_ok TRUE (a new enable); a drive found in Operation enabled at the "
      "first statusword is treated the same. "
      "Homing mode (6): while home is TRUE the drive is switched to mode 6 and, once the display shows it, "
      "controlword bit 4 (homing operation start) rises; homing_attained when the statusword shows bits 12 and 10 "
      "(homing completed), homing_error on bit 13 or when the drive leaves Operation enabled, both only after a "
      "statusword with bits 12 and 13 low was seen since home rose (an earlier homing's status is not believed); "
      "home FALSE drops bit 4 (the drive interrupts a homing in progress) and returns to mode. operation_enabled "
      "stays TRUE while the display changes between 6 and mode. homing_method (6098h) = home_method, home_offset "
      "(607Ch) = home_position x counts_per_unit, homing speeds 6099h:1/2 and acceleration 609Ah from the home_* "
      "parameters. "
      "Events: driver-fault on entering a fault (value: error code 603Fh), on a link loss, on a timeout and on "
      "the following error window and on a homing error; info when the drive leaves Fault. The mode pins are ANY_INT (default SINT, "
      "as 6060h). "
      "See docs/drives.md.";
  t.reference =
      "CiA 402-2 / IEC 61800-7-201 (profile type 1): PDS finite state automaton and its transitions 0-16, "
      "controlword 6040h command coding, statusword 6041h state coding, modes of operation 6060h/6061h; "
      "IEC 61800-7-301 (mapping)";
  t.pins = {
      input("enable", IecType::BOOL).doc("TRUE: bring the drive to Operation enabled"),
      input("quick_stop", IecType::BOOL).doc("TRUE: quick stop (takes precedence over enable)"),
      input("reset", IecType::BOOL).doc("rising edge: fault reset of a drive in Fault"),
      input("mode", TypeClass::ANY_INT).init("8").doc("requested modes of operation (8 CSP, 9 CSV, 10 CST, 3 PV)"),
      input("position_set", IecType::LREAL).unit("unit").doc("position set point in position modes"),
      input("velocity_set", IecType::LREAL).unit("unit/s")
          .doc("velocity set point (velocity modes) or feed-forward (velocity_offset, position modes)"),
      input("torque_set", IecType::LREAL).doc("torque set point in torque modes (x torque_scale)"),
      input("home", IecType::BOOL).doc("TRUE: home with the drive's homing mode 6 (FALSE interrupts it)"),
      input("home_method", IecType::INT).init("37").doc("homing method 6098h (e.g. 37 current position, 17/18 limit switch)"),
      input("home_position", IecType::LREAL).unit("unit").doc("the position the home point gets (home offset 607Ch)"),
      input("link_ok", IecType::BOOL).required()
          .doc("the bus's quality flag for the drive's values (e.g. a request group's _ok); FALSE: stale, the drive is stopped"),
      input("statusword", IecType::UINT).doc("statusword 6041h"),
      input("modes_display", TypeClass::ANY_INT).doc("modes of operation display 6061h"),
      input("position_actual", IecType::DINT).unit("count").doc("position actual value 6064h"),
      input("velocity_actual", IecType::DINT).unit("count/s").doc("velocity actual value 606Ch"),
      input("error_code", IecType::UINT).doc("error code 603Fh"),
      output("controlword", IecType::UINT).doc("controlword 6040h"),
      output("modes_of_operation", TypeClass::ANY_INT).doc("modes of operation 6060h"),
      output("target_position", IecType::DINT).unit("count").doc("target position 607Ah"),
      output("target_velocity", IecType::DINT).unit("count/s").doc("target velocity 60FFh"),
      output("velocity_offset", IecType::DINT).unit("count/s").doc("velocity offset 60B1h (CSP feed-forward)"),
      output("target_torque", IecType::INT).unit("0.1%").doc("target torque 6071h"),
      output("homing_method", IecType::INT).doc("homing method 6098h"),
      output("home_offset", IecType::DINT).unit("count").doc("home offset 607Ch"),
      output("homing_speed_switch", IecType::UDINT).unit("count/s").doc("homing speed during search for switch 6099h:1"),
      output("homing_speed_zero", IecType::UDINT).unit("count/s").doc("homing speed during search for zero 6099h:2"),
      output("homing_acceleration", IecType::UDINT).unit("count/s^2").doc("homing acceleration 609Ah"),
      output("state", IecType::SINT).doc("-1 unknown, 0..7 the PDS state (see above)"),
      output("operation_enabled", IecType::BOOL).doc("Operation enabled in the requested mode"),
      output("busy", IecType::BOOL).doc("the drive is not yet where the inputs ask"),
      output("fault", IecType::BOOL).doc("Fault reaction active or Fault"),
      output("fault_code", IecType::UINT).doc("error code 603Fh seen in the fault, 0 once it is reset"),
      output("warning", IecType::BOOL).doc("statusword bit 7"),
      output("timeout", IecType::BOOL).doc("a transition or mode change exceeded transition_timeout"),
      output("in_mode", IecType::BOOL).doc("modes_display = mode"),
      output("position", IecType::LREAL).unit("unit").doc("position_actual / counts_per_unit"),
      output("velocity", IecType::LREAL).unit("unit/s").doc("velocity_actual / counts_per_unit"),
      output("following_error", IecType::LREAL).unit("unit").doc("position_set - position in a position mode, else 0"),
      output("following_error_exceeded", IecType::BOOL)
          .doc("|following_error| > following_error_window for following_error_time"),
      output("homing", IecType::BOOL).doc("home is TRUE and the homing has not ended"),
      output("homing_attained", IecType::BOOL).doc("the homing asked by home completed (statusword bits 12 and 10)"),
      output("homing_error", IecType::BOOL).doc("the homing asked by home failed (bit 13, or the drive left Operation enabled)"),
  };
  t.params = {
      parameter("counts_per_unit", IecType::LREAL).init("1").unit("count/unit")
          .doc("drive counts per program unit (e.g. 1048576/(2 pi) for a 20-bit encoder in rad)"),
      parameter("torque_scale", IecType::LREAL).init("1000").unit("0.1%/unit")
          .doc("target_torque per unit of torque_set (1000: torque_set 1.0 = rated torque)"),
      parameter("idle_state", IecType::INT).init("0").min(0.0).max(2.0)
          .doc("where enable FALSE leads: 0 Switch on disabled, 1 Ready to switch on, 2 Switched on"),
      parameter("transition_timeout", IecType::LREAL).init("1").min(0.0).unit("s").tunable()
          .doc("longest time for one transition or mode change before timeout"),
      parameter("following_error_window", IecType::LREAL).init("0").min(0.0).unit("unit").tunable()
          .doc("following error window (as 6065h); 0 = not supervised"),
      parameter("following_error_time", IecType::LREAL).init("0").min(0.0).unit("s").tunable()
          .doc("time outside the window before following_error_exceeded (as 6066h)"),
      parameter("disable_stop", IecType::INT).init("0").min(0.0).max(2.0)
          .doc("how enable FALSE leaves Operation enabled: 0 Quick stop (605Ah ramp), 1 Shutdown / Disable operation "
               "(605Bh / 605Ch), 2 the direct command (idle_state 0: Disable voltage, the motor coasts)"),
      parameter("link_lost_stop", IecType::INT).init("0").min(0.0).max(1.0)
          .doc("the command while link_ok is FALSE and until a new enable: 0 Quick stop, 1 Disable voltage (coasts)"),
  };
  t.params.push_back(parameter("home_speed_switch", IecType::LREAL).init("1").min(0.0).unit("unit/s")
                         .doc("homing speed while searching for a switch (6099h:1)"));
  t.params.push_back(parameter("home_speed_zero", IecType::LREAL).init("0.1").min(0.0).unit("unit/s")
                         .doc("homing speed while searching for zero, the switch's edge (6099h:2)"));
  t.params.push_back(parameter("home_acceleration", IecType::LREAL).init("10").min(0.0).unit("unit/s^2")
                         .doc("homing acceleration (609Ah)"));
  t.create = make_cia402;
  r.add(std::move(t));
}

}  // namespace syncplc::drives
