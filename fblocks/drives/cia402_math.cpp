#include "fblocks/drives/cia402_math.hpp"

namespace syncplc::drives::cia402 {

const char* state_name(State s) noexcept {
  switch (s) {
    case State::kUnknown: return "unknown";
    case State::kNotReadyToSwitchOn: return "Not ready to switch on";
    case State::kSwitchOnDisabled: return "Switch on disabled";
    case State::kReadyToSwitchOn: return "Ready to switch on";
    case State::kSwitchedOn: return "Switched on";
    case State::kOperationEnabled: return "Operation enabled";
    case State::kQuickStopActive: return "Quick stop active";
    case State::kFaultReactionActive: return "Fault reaction active";
    case State::kFault: return "Fault";
  }
  return "unknown";
}

// The state coding table of 6041h. Bits 0-3 and 6 decide all but three
// states; Ready to switch on, Switched on, Operation enabled and Quick stop
// active also need bit 5 (quick stop, low active), hence two masks:
//   xxxx xxxx x0xx 0000  Not ready to switch on   (mask 0x4F, value 0x00)
//   xxxx xxxx x1xx 0000  Switch on disabled       (mask 0x4F, value 0x40)
//   xxxx xxxx x01x 0001  Ready to switch on       (mask 0x6F, value 0x21)
//   xxxx xxxx x01x 0011  Switched on              (mask 0x6F, value 0x23)
//   xxxx xxxx x01x 0111  Operation enabled        (mask 0x6F, value 0x27)
//   xxxx xxxx x00x 0111  Quick stop active        (mask 0x6F, value 0x07)
//   xxxx xxxx x0xx 1111  Fault reaction active    (mask 0x4F, value 0x0F)
//   xxxx xxxx x0xx 1000  Fault                    (mask 0x4F, value 0x08)
// Any other combination is not a state (a broken drive or a garbled value).
State decode_statusword(std::uint16_t s) noexcept {
  switch (s & 0x4F) {
    case 0x00: return State::kNotReadyToSwitchOn;
    case 0x40: return State::kSwitchOnDisabled;
    case 0x0F: return State::kFaultReactionActive;
    case 0x08: return State::kFault;
  }
  switch (s & 0x6F) {
    case 0x21: return State::kReadyToSwitchOn;
    case 0x23: return State::kSwitchedOn;
    case 0x27: return State::kOperationEnabled;
    case 0x07: return State::kQuickStopActive;
  }
  return State::kUnknown;
}

std::uint16_t statusword_of(State s) noexcept {
  switch (s) {
    case State::kUnknown: return 0;
    case State::kNotReadyToSwitchOn: return 0x00;
    case State::kSwitchOnDisabled: return 0x40;
    case State::kReadyToSwitchOn: return 0x21;
    case State::kSwitchedOn: return 0x23;
    case State::kOperationEnabled: return 0x27;
    case State::kQuickStopActive: return 0x07;
    case State::kFaultReactionActive: return 0x0F;
    case State::kFault: return 0x08;
  }
  return 0;
}

// The arrows of the PDS FSA figure.
int transition_number(State from, State to) noexcept {
  using S = State;
  if (to == S::kFaultReactionActive && from != S::kFault && from != S::kFaultReactionActive && from != S::kUnknown)
    return 13;
  struct Arrow { S from, to; int n; };
  static constexpr Arrow kArrows[] = {
      {S::kNotReadyToSwitchOn, S::kSwitchOnDisabled, 1},
      {S::kSwitchOnDisabled, S::kReadyToSwitchOn, 2},
      {S::kReadyToSwitchOn, S::kSwitchedOn, 3},
      {S::kSwitchedOn, S::kOperationEnabled, 4},
      {S::kOperationEnabled, S::kSwitchedOn, 5},
      {S::kSwitchedOn, S::kReadyToSwitchOn, 6},
      {S::kReadyToSwitchOn, S::kSwitchOnDisabled, 7},
      {S::kOperationEnabled, S::kReadyToSwitchOn, 8},
      {S::kOperationEnabled, S::kSwitchOnDisabled, 9},
      {S::kSwitchedOn, S::kSwitchOnDisabled, 10},
      {S::kOperationEnabled, S::kQuickStopActive, 11},
      {S::kQuickStopActive, S::kSwitchOnDisabled, 12},
      {S::kFaultReactionActive, S::kFault, 14},
      {S::kFault, S::kSwitchOnDisabled, 15},
      {S::kQuickStopActive, S::kOperationEnabled, 16},
  };
  for (const Arrow& a : kArrows)
    if (a.from == from && a.to == to) return a.n;
  return -1;  // 0 (start -> Not ready to switch on) has no "from" state
}

bool is_position_mode(int m) noexcept {
  return m == mode::kProfilePosition || m == mode::kInterpolatedPosition || m == mode::kCyclicSyncPosition;
}
bool is_velocity_mode(int m) noexcept { return m == mode::kProfileVelocity || m == mode::kCyclicSyncVelocity; }
bool is_torque_mode(int m) noexcept { return m == mode::kProfileTorque || m == mode::kCyclicSyncTorque; }

namespace {

// Rank on the main path Switch on disabled -> ... -> Operation enabled.
int rank(Goal g) noexcept {
  switch (g) {
    case Goal::kSwitchOnDisabled: return 0;
    case Goal::kReadyToSwitchOn: return 1;
    case Goal::kSwitchedOn: return 2;
    case Goal::kOperationEnabled: return 3;
    case Goal::kQuickStop: return 0;
  }
  return 0;
}

// The command that holds a drive at the main-path state of rank r.
std::uint16_t holding_command(int r) noexcept {
  switch (r) {
    case 0: return cw::kDisableVoltage;
    case 1: return cw::kShutdown;
    case 2: return cw::kSwitchOnCmd;
    default: return cw::kEnableOperationCmd;
  }
}

}  // namespace

std::uint16_t command_for(State s, Goal goal, bool reset, Stop stop, bool stopped) noexcept {
  if (s == State::kFault) return reset ? cw::kFaultResetCmd : cw::kDisableVoltage;  // 15 on the edge
  if (goal == Goal::kQuickStop) return cw::kQuickStopCmd;  // 7, 10, 11; then 12 by the drive
  const int want = rank(goal);
  switch (s) {
    case State::kUnknown:
    case State::kNotReadyToSwitchOn:     // the drive leaves it by itself (transition 1)
    case State::kFaultReactionActive:    // the drive ends it by itself (transition 14)
      return cw::kDisableVoltage;
    case State::kSwitchOnDisabled:
      return want >= 1 ? cw::kShutdown : cw::kDisableVoltage;  // 2
    case State::kReadyToSwitchOn:
      if (want >= 2) return cw::kSwitchOnCmd;                  // 3
      return holding_command(want);                            // hold, or 7
    case State::kSwitchedOn:
      return holding_command(want);                            // 4, hold, 6, 10
    case State::kOperationEnabled:
      if (want == 3) return cw::kEnableOperationCmd;           // hold
      // Leaving Operation enabled: the drive's ramps act unless the project
      // asked for the direct command (9 coasts the motor).
      switch (stop) {
        case Stop::kQuickStop: return cw::kQuickStopCmd;       // 11 (605Ah)
        case Stop::kShutdown: return want == 2 ? cw::kDisableOperation : cw::kShutdown;  // 5 (605Ch), 8 (605Bh)
        case Stop::kDirect: return holding_command(want);      // 5, 8, 9
      }
      return cw::kQuickStopCmd;
    case State::kQuickStopActive:
      // 16 where the drive's quick stop option code (605Ah = 5..8) keeps it
      // here; with codes 0..4 it goes to Switch on disabled itself (12).
      if (want == 3) return cw::kEnableOperationCmd;
      // Disable voltage here (12) would cut the ramp short and let the motor
      // coast: the quick stop is held until the drive reports it stopped
      // (statusword bit 10 in Quick stop active).
      return stopped ? cw::kDisableVoltage : cw::kQuickStopCmd;
    case State::kFault:
      break;
  }
  return cw::kDisableVoltage;
}

bool goal_reached(State s, Goal goal) noexcept {
  switch (goal) {
    case Goal::kQuickStop:
    case Goal::kSwitchOnDisabled:
      return s == State::kSwitchOnDisabled || s == State::kQuickStopActive;
    case Goal::kReadyToSwitchOn: return s == State::kReadyToSwitchOn;
    case Goal::kSwitchedOn: return s == State::kSwitchedOn;
    case Goal::kOperationEnabled: return s == State::kOperationEnabled;
  }
  return false;
}

MasterOutputs Master::step(const MasterInputs& in, std::int64_t now_ns) noexcept {
  MasterOutputs o;
  const bool edge = in.reset && !reset_prev_;
  reset_prev_ = in.reset;
  if (!started_) {
    started_ = true;
    since_ns_ = now_ns;
  }
  if (!in.link_ok) {
    // Nothing is known of the drive. It must not run on with what it had:
    // the link-loss command (Quick stop, or Disable voltage when the project
    // chose it) goes out with every write that still reaches the drive, and
    // is the first command it gets when the link returns. Operation resumes
    // only after enable has been FALSE with the link up (a new enable).
    o.link_lost_event = link_prev_;
    link_prev_ = false;
    // Before the link was first up this is the start (no reply yet), not a loss.
    link_lost_ = link_lost_ || ever_up_;
    o.controlword = last_cw_ = c_.link_lost == Stop::kDirect ? cw::kDisableVoltage : cw::kQuickStopCmd;
    o.state = State::kUnknown;
    o.fault = was_fault_;
    o.busy = true;
    o.link_lost = true;
    last_state_ = State::kUnknown;
    since_ns_ = now_ns;
    timed_out_ = false;
    reset_pending_ = false;
    return o;
  }
  link_prev_ = true;
  const State s = decode_statusword(in.statusword);
  // A drive already in Operation enabled (or stopping in Quick stop active)
  // at the first statusword was not enabled by this master (a restarted
  // PLC): as after a link loss, it is stopped and needs a new enable.
  if (!ever_up_ && (s == State::kOperationEnabled || s == State::kQuickStopActive)) link_lost_ = true;
  ever_up_ = true;
  if (link_lost_ && !in.enable) link_lost_ = false;  // the next rising enable is a new one
  const bool fault = s == State::kFault || s == State::kFaultReactionActive;
  if (fault && !was_fault_) o.fault_event = true;
  if (!fault && was_fault_ && s != State::kUnknown) o.recovered_event = true;
  if (s != State::kUnknown) was_fault_ = fault;
  if (edge && fault) reset_pending_ = true;
  if (!fault) reset_pending_ = false;

  Goal goal = in.enable ? Goal::kOperationEnabled : c_.idle;
  Stop stop = c_.disable;
  if (in.quick_stop) {
    goal = Goal::kQuickStop;
  } else if (link_lost_) {
    goal = c_.link_lost == Stop::kDirect ? Goal::kSwitchOnDisabled : Goal::kQuickStop;
    stop = c_.link_lost;
  }
  // The fault reset is the 0 -> 1 edge of bit 7: a pending reset is given
  // only once a scan has already seen the fault (and written bit 7 = 0).
  const bool reset_now = reset_pending_ && s == State::kFault &&
                         (last_state_ == State::kFault || last_state_ == State::kFaultReactionActive);
  const bool stopped = (in.statusword & sw::kTargetReached) != 0;
  const std::uint16_t c = command_for(s, goal, reset_now, stop, stopped);

  if (s != last_state_ || c != last_cw_ || in.mode != last_mode_) {
    since_ns_ = now_ns;
    timed_out_ = false;
  }
  last_state_ = s;
  last_cw_ = c;
  last_mode_ = in.mode;

  o.controlword = c;
  o.state = s;
  o.run = goal == Goal::kOperationEnabled;
  o.link_lost = link_lost_;
  o.fault = fault;
  o.in_mode = in.mode_display == in.mode;
  o.operation_enabled = s == State::kOperationEnabled && o.in_mode;
  const bool waiting_for_reset = s == State::kFault && !reset_pending_;
  o.busy = !waiting_for_reset && (!goal_reached(s, goal) || !o.in_mode);
  if (o.busy && now_ns - since_ns_ >= c_.transition_timeout_ns) {
    if (!timed_out_) o.timeout_event = true;
    timed_out_ = true;
    // A reset the drive did not take ends here: bit 7 falls, so the next
    // reset input edge is a new edge for the drive too.
    if (reset_pending_) {
      reset_pending_ = false;
      o.controlword = last_cw_ = command_for(s, goal, false, stop, stopped);
    }
  }
  o.timeout = timed_out_;
  return o;
}

}  // namespace syncplc::drives::cia402
