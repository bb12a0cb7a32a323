// The master side of the CiA 402 power drive system state machine, without
// pins: statusword decoding, the controlword command that walks a drive from
// the state it reports towards the state the program asks for, the fault
// reset edge and the transition timeout. CIA402_DRIVE (cia402_drive.cpp)
// wraps it; tests drive it against a model of a drive (tests/drives).
//
// The standard: CiA 402 part 2 = IEC 61800-7-201 (the generic interface,
// profile type 1) and its mapping IEC 61800-7-301. Its "Finite state
// automaton" (the PDS FSA) figure has the eight states below and the
// transitions 0..16; the controlword 6040h bits 0-3 and 7 carry the commands
// (the "command coding" table), the statusword 6041h bits 0-3, 5 and 6 the
// state (the "state coding" table). Clause numbers differ between editions,
// so the code cites objects and table names. docs/drives.md draws the diagram.
#pragma once

#include <cstdint>

namespace syncplc::drives::cia402 {

// The PDS FSA states. Values are this library's own (the `state` output of
// CIA402_DRIVE); kUnknown: no valid statusword (link down, or before the
// first one arrived).
enum class State : std::int8_t {
  kUnknown = -1,
  kNotReadyToSwitchOn = 0,
  kSwitchOnDisabled = 1,
  kReadyToSwitchOn = 2,
  kSwitchedOn = 3,
  kOperationEnabled = 4,
  kQuickStopActive = 5,
  kFaultReactionActive = 6,
  kFault = 7,
};
const char* state_name(State s) noexcept;

// Statusword 6041h bits (statusword table).
namespace sw {
inline constexpr std::uint16_t kReadyToSwitchOn = 1u << 0;
inline constexpr std::uint16_t kSwitchedOn = 1u << 1;
inline constexpr std::uint16_t kOperationEnabled = 1u << 2;
inline constexpr std::uint16_t kFault = 1u << 3;
inline constexpr std::uint16_t kVoltageEnabled = 1u << 4;
inline constexpr std::uint16_t kQuickStop = 1u << 5;  // 0 = quick stop active (low active)
inline constexpr std::uint16_t kSwitchOnDisabled = 1u << 6;
inline constexpr std::uint16_t kWarning = 1u << 7;
inline constexpr std::uint16_t kRemote = 1u << 9;
inline constexpr std::uint16_t kTargetReached = 1u << 10;
inline constexpr std::uint16_t kInternalLimitActive = 1u << 11;
inline constexpr std::uint16_t kOperationModeSpecific12 = 1u << 12;  // CSP: drive follows the command value
inline constexpr std::uint16_t kOperationModeSpecific13 = 1u << 13;  // CSP: following error
}  // namespace sw

// Controlword 6040h bits (controlword table).
namespace cw {
inline constexpr std::uint16_t kSwitchOn = 1u << 0;
inline constexpr std::uint16_t kEnableVoltage = 1u << 1;
inline constexpr std::uint16_t kQuickStop = 1u << 2;  // 0 = quick stop (low active)
inline constexpr std::uint16_t kEnableOperation = 1u << 3;
inline constexpr std::uint16_t kFaultReset = 1u << 7;  // acts on its 0 -> 1 edge
inline constexpr std::uint16_t kHalt = 1u << 8;

// The commands of the command coding table (bits 7, 3, 2, 1, 0; x = 0 here).
inline constexpr std::uint16_t kShutdown = 0x0006;          // 0 x 1 1 0: transitions 2, 6, 8
inline constexpr std::uint16_t kSwitchOnCmd = 0x0007;       // 0 0 1 1 1: transition 3
inline constexpr std::uint16_t kDisableVoltage = 0x0000;    // 0 x x 0 x: transitions 7, 9, 10, 12
inline constexpr std::uint16_t kQuickStopCmd = 0x0002;      // 0 x 0 1 x: transitions 7, 10, 11
inline constexpr std::uint16_t kDisableOperation = 0x0007;  // 0 0 1 1 1: transition 5
inline constexpr std::uint16_t kEnableOperationCmd = 0x000F;  // 0 1 1 1 1: transitions 4, 16
inline constexpr std::uint16_t kFaultResetCmd = 0x0080;     // 0 -> 1 on bit 7: transition 15
}  // namespace cw

// The state coding table: the state a statusword reports (bits 0-3, 5, 6).
State decode_statusword(std::uint16_t statusword) noexcept;

// The statusword bits 0-3, 5, 6 of a state (the state coding table with
// every x = 0): what a drive in `s` reports. kUnknown gives 0.
std::uint16_t statusword_of(State s) noexcept;

// The transition number of the PDS FSA figure that a drive makes from `from`
// to `to` (0..16), or -1 when the figure has no such arrow. 13 ("any state to
// Fault reaction active") is returned for every non-fault state.
int transition_number(State from, State to) noexcept;

// The operating modes (modes of operation 6060h, display 6061h) the block
// knows the targets of. Others are passed to the drive as given.
namespace mode {
inline constexpr int kProfilePosition = 1;
inline constexpr int kProfileVelocity = 3;
inline constexpr int kProfileTorque = 4;
inline constexpr int kHoming = 6;
inline constexpr int kInterpolatedPosition = 7;
inline constexpr int kCyclicSyncPosition = 8;
inline constexpr int kCyclicSyncVelocity = 9;
inline constexpr int kCyclicSyncTorque = 10;
}  // namespace mode
bool is_position_mode(int m) noexcept;  // 1, 7, 8
bool is_velocity_mode(int m) noexcept;  // 3, 9
bool is_torque_mode(int m) noexcept;    // 4, 10

// Where the program wants the drive, from its inputs.
enum class Goal : std::uint8_t {
  kSwitchOnDisabled,   // enable FALSE, idle state "switch on disabled" (voltage off)
  kReadyToSwitchOn,    // enable FALSE, idle state "ready to switch on"
  kSwitchedOn,         // enable FALSE, idle state "switched on" (power stage on, no torque)
  kOperationEnabled,   // enable TRUE
  kQuickStop,          // quick_stop TRUE: quick stop, then switch on disabled
};

// How a drive leaves Operation enabled for a goal below it (enable FALSE, or
// the link-loss reaction). The drive's own option codes decide the ramp of
// each command: 605Ah for Quick stop, 605Bh for Shutdown, 605Ch for Disable
// operation; Disable voltage switches the power stage off (the motor coasts).
enum class Stop : std::uint8_t {
  kQuickStop,       // Quick stop (11), held while the drive ramps (statusword
                    // bit 10 in Quick stop active: stopped), then the goal
  kShutdown,        // Disable operation (5) towards Switched on, else Shutdown (8)
  kDirect,          // the goal's own command: 5, 8, or Disable voltage (9)
                    // towards Switch on disabled, where the motor coasts
};

// The controlword command that moves a drive in `s` one transition towards
// `goal` (the commands of the command coding table, one step per scan, so
// every transition is visible in the statusword). In Fault the command is
// Disable voltage (bit 7 = 0, ready for a reset edge) unless `reset` is TRUE,
// which gives the fault reset command (bit 7 = 1). `stop` chooses how
// Operation enabled is left for a goal below it; `stopped` is the
// statusword's bit 10 (in Quick stop active: the quick stop ramp is done).
std::uint16_t command_for(State s, Goal goal, bool reset, Stop stop = Stop::kQuickStop,
                          bool stopped = true) noexcept;

// TRUE when a drive in `s` has reached `goal` (Quick stop active counts as
// reached for kQuickStop and kSwitchOnDisabled: a drive with quick stop
// option code 5..8 stays there).
bool goal_reached(State s, Goal goal) noexcept;

// One scan of the master's state machine, pure: what CIA402_DRIVE computes
// before scaling its targets.
struct MasterInputs {
  bool enable = false;
  bool quick_stop = false;
  bool reset = false;           // a rising edge requests a fault reset
  bool link_ok = true;          // FALSE: the statusword is stale (the bus lost the drive)
  std::uint16_t statusword = 0;
  int mode = mode::kCyclicSyncPosition;  // requested modes of operation
  int mode_display = 0;         // modes of operation display 6061h
};

struct MasterConfig {
  Goal idle = Goal::kSwitchOnDisabled;   // where enable FALSE leads
  Stop disable = Stop::kQuickStop;       // how enable FALSE leaves Operation enabled
  // The command while the link is down, and the goal after it returns until
  // enable has been seen FALSE: kQuickStop (Quick stop, 0002h) or kDirect
  // (Disable voltage 0000h, the motor coasts); kShutdown is not offered here
  // (from Switch on disabled it would be transition 2, a step up).
  Stop link_lost = Stop::kQuickStop;
  std::int64_t transition_timeout_ns = 1'000'000'000;
};

// What one scan produced; the *_event flags are TRUE on the one scan the
// condition starts (the block raises its events from them).
struct MasterOutputs {
  std::uint16_t controlword = 0;
  State state = State::kUnknown;
  bool operation_enabled = false;  // the drive is in Operation enabled and in the requested mode
  bool fault = false;              // Fault reaction active or Fault
  bool busy = false;               // not yet where the inputs ask
  bool timeout = false;            // a transition (or a mode change) took longer than the timeout
  bool in_mode = false;            // mode_display == mode
  bool fault_event = false;        // entered Fault reaction active / Fault
  bool recovered_event = false;    // left Fault for a non-fault state
  bool timeout_event = false;      // timeout became TRUE
  // The program's targets may reach the drive: the goal is Operation enabled
  // (enable TRUE, no quick stop, no link loss waiting for a new enable).
  bool run = false;
  bool link_lost = false;          // the link is down, or it returned and enable has not been FALSE since
  bool link_lost_event = false;    // link_ok fell (this scan)
};

class Master {
 public:
  explicit Master(const MasterConfig& c = {}) : c_(c) {}
  MasterOutputs step(const MasterInputs& in, std::int64_t now_ns) noexcept;
  void reconfigure(const MasterConfig& c) noexcept { c_ = c; }
  const MasterConfig& config() const noexcept { return c_; }

 private:
  MasterConfig c_;
  bool started_ = false;
  bool reset_prev_ = false;     // the reset input last scan (edge detection)
  bool reset_pending_ = false;  // a reset edge not yet answered by the drive
  bool was_fault_ = false;
  bool timed_out_ = false;
  bool link_lost_ = false;      // latched at a link loss until enable is seen FALSE with the link up
  bool link_prev_ = false;      // link_ok last scan (the loss event)
  bool ever_up_ = false;        // the link has been up (a later FALSE is a loss, not the start)
  State last_state_ = State::kUnknown;
  std::uint16_t last_cw_ = 0;
  int last_mode_ = 0;
  std::int64_t since_ns_ = 0;   // last change of state, controlword or requested mode
};

}  // namespace syncplc::drives::cia402
