// One PLCopen axis (PLCopen Motion Control Part 1 v2.0): the state diagram
// (§2.1), the commands of the motion blocks with their BufferMode (§2.4.2),
// error handling (§2.2), the set values the trajectory generator makes every
// scan (§2.3) and the axis parameters of MC_ReadParameter/MC_WriteParameter
// (§3.19, parameter numbers of its table). Plain data in and out, no
// allocation, no I/O: the block MC_AXIS (axis_block.cpp) owns one and calls
// cycle() once per scan; the MC_* blocks (mc_*.cpp) submit commands and read
// their reports through the axis they are linked to.
//
// Units are the axis's user units u (mm, deg, rad): positions u, velocities
// u/s, accelerations u/s^2, jerks u/s^3 (§2.4.4). Internally the position is
// continuous; a modulo axis shows it wrapped into [0, modulo).
//
// Profiles (docs/motion/plcopen.md, "Profiles"): a discrete move is paper
// 004's velocity/acceleration-limited nonlinear filter (nonlinear_filter_math.hpp,
// eqs. 1-22) tracking the target as a constant reference, so it never
// exceeds its bounds, arrives exactly and without overshoot from rest, and
// its remaining time is known exactly (Table I, transient_steps). A velocity
// move, MC_Halt and MC_Stop ramp the velocity with the acceleration limits.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>

#include "fblocks/motion/nonlinear_filter_math.hpp"
#include "fblocks/plcopen/axis_jerk.hpp"

namespace syncplc::plcopen {

// The states of §2.1; the numbers are MC_ReadStatus's order and the `state`
// output of MC_AXIS.
enum class AxisState : std::uint8_t {
  Disabled = 0,
  Standstill = 1,
  Homing = 2,
  DiscreteMotion = 3,
  ContinuousMotion = 4,
  SynchronizedMotion = 5,
  Stopping = 6,
  ErrorStop = 7,
};
const char* axis_state_name(AxisState s) noexcept;

// MC_BUFFER_MODE (§2.4.2), with the standard's numbers.
enum class BufferMode : std::uint8_t {
  Aborting = 0,
  Buffered = 1,
  BlendingLow = 2,
  BlendingPrevious = 3,
  BlendingNext = 4,
  BlendingHigh = 5,
};

// MC_DIRECTION (§3.5), with the standard's numbers; only a modulo axis has a
// choice (a linear axis has one way to each position).
enum class Direction : std::uint8_t {
  Positive = 1,
  Shortest = 2,
  Negative = 3,
  Current = 4,
};

// ErrorID values (WORD). 0x01xx: the command is not allowed in this state;
// 0x02xx: an input of the command is invalid; 0x03xx: the axis went to
// ErrorStop (the axis error MC_ReadAxisError reports).
enum class AxisError : std::uint16_t {
  None = 0,
  Disabled = 0x0101,          // a motion command to a Disabled axis
  InErrorStop = 0x0102,       // any motion command, MC_Stop included, in ErrorStop
  Stopping = 0x0103,          // a motion command while MC_Stop holds the axis
  NotStandstill = 0x0104,     // MC_Home, MC_SetPosition outside Standstill (SetPosition: or Disabled)
  NotSynchronized = 0x0105,   // MC_GearOut/MC_CamOut outside SynchronizedMotion
  StillMoving = 0x0106,       // MC_Reset while ErrorStop still brakes the axis
  MasterFailed = 0x0107,      // MC_GearIn/MC_CamIn: the master is Disabled or in ErrorStop
  BadVelocity = 0x0201,       // not finite, <= 0 where it must be positive, or above the axis maximum
  BadAcceleration = 0x0202,   // not finite, <= 0, or above the axis maximum
  BadDeceleration = 0x0203,
  BadJerk = 0x0204,           // not finite or < 0, or above the axis maximum
  BadPosition = 0x0205,       // not finite, or beyond an enabled software limit
  BadBufferMode = 0x0206,     // not one of MC_BUFFER_MODE
  BufferFull = 0x0207,        // kQueueCapacity buffered commands already wait
  BadDirection = 0x0208,
  BadParameter = 0x0209,      // MC_ReadParameter/MC_WriteParameter: unknown number, read-only, value out of range
  BadSyncInput = 0x020A,      // MC_GearIn/MC_CamIn: ratio, cam table, scaling, StartMode or MasterValueSource invalid
  DriveFault = 0x0301,        // the drive reports a fault (its code: drive_fault_code())
  PowerLost = 0x0302,         // the power stage went off while MC_Power asked for it
  FollowingError = 0x0303,    // |set - actual| beyond the axis's limit
  FeedbackLost = 0x0304,      // the drive's actual values are not fresh (bad exchange)
  SoftLimit = 0x0305,         // a continuous move reached an enabled software limit: braked before it
  HomingFailed = 0x0306,      // MC_Home's search met no reference switch within the axis's home_max_distance
  DriveHomingError = 0x0307,  // MC_Home by the drive (home_mode 3): the drive reported a homing error
  HomingTimeout = 0x0308,     // MC_Home by the drive: not attained within the axis's home_timeout
  SyncLimit = 0x0309,         // a synchronized slave was fed a sample beyond its velocity/acceleration limits
};

enum class CommandKind : std::uint8_t {
  MoveAbsolute,
  MoveRelative,
  MoveAdditive,
  MoveVelocity,
  Halt,
  Stop,
  Home,  // "set here": the position becomes `position` (homing with a switch: MC_Home's own sequence)
  // One axis of a synchronized group move (MC_GroupMoveAbsolute): its goal
  // is `position`; the group gives the set values of every sample (feed).
  GroupMove,
  // The slave of MC_GearIn/MC_CamIn (SynchronizedMotion): its coupling block
  // gives the set values of every sample (feed), checked against the axis's
  // *Appl limits (SyncLimit beyond them). Aborting or Buffered only.
  Synchronized,
  // MC_GearOut/MC_CamOut: only in SynchronizedMotion; the coupling ends and
  // the axis keeps its set velocity (ContinuousMotion, an MC_MoveVelocity with
  // the axis's *Appl ramps). Done at once.
  SyncOut,
};

// A command as its block sampled its inputs at Execute's rising edge (§2.4.1).
// Distances for MoveRelative/MoveAdditive go in `position`. velocity is
// signed only for MoveVelocity (direction by its sign); acceleration,
// deceleration and jerk 0 mean "the axis's own maximum" (§2.4.1's
// implementation choice, documented in docs/motion/plcopen.md).
struct Command {
  CommandKind kind = CommandKind::MoveAbsolute;
  double position = 0;
  double velocity = 0;
  double acceleration = 0;
  double deceleration = 0;
  double jerk = 0;
  BufferMode buffer = BufferMode::Aborting;
  Direction direction = Direction::Positive;
};

// A submitted command's handle; 0 is "none". Never reused within an axis.
using CommandId = std::uint32_t;

// Where a command is, as its block shows it (§2.4.1's output rules).
enum class CommandStatus : std::uint8_t {
  Unknown,   // never submitted here, or so old it left the report table
  Buffered,  // accepted, waits for the command before it (Busy, not Active)
  Active,    // moves the axis (Busy and Active)
  Done,      // reached its goal (Done); MC_Stop: stopped, the axis held while its Execute stays TRUE
  Aborted,   // another command took over, or MC_Power disabled the axis (CommandAborted)
  Error,     // rejected, or the axis went to ErrorStop while it was Active or Buffered (Error, ErrorID)
};

struct CommandReport {
  CommandStatus status = CommandStatus::Unknown;
  AxisError error = AxisError::None;
  // MoveVelocity: the set velocity equals the commanded one (§2.4.1 "Inxxx":
  // set, not actual values; FALSE again when it differs).
  bool in_velocity = false;
};

// The axis's settings (MC_AXIS's parameters); the *_appl limits of
// MC_WriteParameter change them while the axis runs.
struct AxisLimits {
  double v_max = 1;          // u/s, > 0: MaxVelocityAppl (and ...System)
  double a_max = 10;         // u/s^2, > 0: MaxAccelerationAppl
  double d_max = 10;         // u/s^2, > 0: MaxDecelerationAppl
  double j_max = 0;          // u/s^3, 0 = not jerk-limited: MaxJerkAppl
  double sw_limit_pos = 0;   // SWLimitPos, u
  double sw_limit_neg = 0;   // SWLimitNeg, u
  bool sw_limit_pos_on = false;  // EnableLimitPos
  bool sw_limit_neg_on = false;  // EnableLimitNeg
  double max_position_lag = 0;   // MaxPositionLag, u; 0 = not monitored (EnablePosLagMonitoring)
  double modulo = 0;         // u; 0 = a linear axis
};

// How MC_Home finds the reference (MC_AXIS's home_* parameters). §3.2
// leaves the procedure to the implementation.
struct HomingConfig {
  enum class Mode : std::uint8_t {
    SetHere = 0,         // the position becomes MC_Home's Position where the axis stands
    SwitchPositive = 1,  // search the reference switch's rising edge moving in +
    SwitchNegative = 2,  // ... moving in -
    // The drive homes itself (CiA 402 homing mode, CIA402_DRIVE's home
    // input): the axis asks, follows the drive's actual values meanwhile,
    // and takes the drive's position as its own once "homing attained".
    Drive = 3,
  };
  Mode mode = Mode::SetHere;
  double velocity = 0;      // u/s, > 0 for a switch search
  double max_distance = 0;  // u; a search longer than this is HomingFailed (0: unbounded)
  int method = 37;          // Drive: the drive's homing method (6098h), passed on
  double timeout_s = 60;    // Drive: longest wait for "homing attained" before HomingTimeout
};

// What the drive reports, sampled by MC_AXIS: in user units (MC_AXIS divides
// by its scale) and in the drive's coordinates, which MC_SetPosition and
// MC_Home shift by the axis's offset (user position = drive position + offset).
struct DriveFeedback {
  double position = 0;       // actual position, continuous (not wrapped), drive coordinates
  double velocity = 0;       // actual velocity
  bool valid = true;         // the values come from a good exchange (else FeedbackLost)
  bool power_on = false;     // the power stage is on (CiA 402: Operation enabled)
  bool fault = false;        // the drive is in fault
  std::uint16_t fault_code = 0;
  bool home_switch = false;  // the reference switch (homing on simulated axes)
  bool homing_attained = false;  // the drive's homing (home_mode 3) completed
  bool homing_error = false;     // ... failed
};

// What MC_AXIS sends the drive this scan.
struct DriveCommand {
  bool enable = false;       // power stage on
  bool reset = false;        // fault reset request (held while MC_Reset asks)
  double position = 0;       // set position, continuous, drive coordinates (set - offset)
  double velocity = 0;       // set velocity (feed-forward)
  double acceleration = 0;   // set acceleration over the coming scan
  bool home = false;         // home_mode 3: the drive is to home itself (held until it ends)
  double home_position = 0;  // ... the position its home point gets (MC_Home's Position)
};

// MC_ReadParameter/MC_WriteParameter numbers (§3.19's table).
enum class AxisParameter : std::int16_t {
  CommandedPosition = 1,   // read only
  SWLimitPos = 2,
  SWLimitNeg = 3,
  EnableLimitPos = 4,      // BOOL as 0/1
  EnableLimitNeg = 5,
  EnablePosLagMonitoring = 6,
  MaxPositionLag = 7,
  MaxVelocitySystem = 8,   // read only: the axis's configured maximum
  MaxVelocityAppl = 9,
  ActualVelocity = 10,     // read only
  CommandedVelocity = 11,  // read only
  MaxAccelerationSystem = 12,  // read only
  MaxAccelerationAppl = 13,
  MaxDecelerationSystem = 14,  // read only
  MaxDecelerationAppl = 15,
  MaxJerkSystem = 16,      // read only
  MaxJerkAppl = 17,
};

class AxisMachine {
 public:
  // Buffered commands that may wait behind the active one.
  static constexpr std::size_t kQueueCapacity = 8;
  // Reports kept for commands that ended (a block reads its own within a scan
  // or two; older ones read as Unknown).
  static constexpr std::size_t kReportCapacity = 32;

  // `system` are the configured limits (the *System parameters and the
  // initial *Appl ones); period_s the scan period T > 0. Starts Disabled at
  // position 0, velocity 0.
  AxisMachine(const AxisLimits& system, double period_s) noexcept;

  // ---- once per scan, by MC_AXIS, before its blocks run -----------------
  // Takes the drive's feedback, moves through the state diagram (power,
  // faults, following error, stale feedback, reset), advances the active
  // command's profile by one period, starts buffered commands whose turn
  // came, and updates every command's report.
  void cycle(const DriveFeedback& fb) noexcept;
  // What to send the drive after this cycle.
  const DriveCommand& drive_command() const noexcept { return out_; }

  // ---- from the blocks, after cycle() in the same scan ------------------
  // MC_Power: its Enable (level), every scan it runs.
  void request_power(bool enable) noexcept;
  // MC_Reset at its Execute's rising edge: leaves ErrorStop (to Standstill
  // when the power stage is on and MC_Power asks for it, else Disabled) once
  // the drive's fault is gone and the axis stands; a pending drive fault is
  // acknowledged by DriveCommand::reset. Returns None or the reason.
  AxisError reset() noexcept;
  // A motion command at its block's Execute edge: checked against the state
  // and the limits now; 0 and *error set when rejected (nothing changes),
  // else its id.
  CommandId submit(const Command& c, AxisError* error) noexcept;
  CommandReport report(CommandId id) const noexcept;
  // ContinuousUpdate (§2.4.1, axis_update.cpp): new inputs for a discrete
  // move or MoveVelocity still Active or Buffered, checked as at submit (its
  // BufferMode stays). The active move re-targets in flight from its set
  // values: MoveAbsolute to the new position, MoveRelative to the distance
  // from where it started, MoveAdditive from the goal it was added to.
  // Returns None (also when the command has ended: nothing to update) or
  // the reason the new inputs are refused (the command goes on unchanged).
  AxisError update(CommandId id, const Command& c) noexcept;
  // MC_Stop's Execute fell: the axis leaves Stopping once that stop is Done.
  void release_stop(CommandId id) noexcept;
  // MC_SetPosition: in Standstill or Disabled, the position becomes p
  // (relative: moves by p) without motion.
  AxisError set_position(double p, bool relative) noexcept;
  // MC_ReadParameter / MC_WriteParameter.
  AxisError read_parameter(std::int16_t number, double* value) const noexcept;
  AxisError write_parameter(std::int16_t number, double value) noexcept;
  // An online change of MC_AXIS's limits (its tunable parameters): the new
  // system limits (the modulo stays), the *Appl ones and the lag monitoring
  // set to them (a value MC_WriteParameter wrote was made for the old
  // limits). A lower *Appl maximum, here or by MC_WriteParameter, also cuts
  // the commands already given: their velocity, acceleration and deceleration
  // act within it from the next sample on.
  void retune(const AxisLimits& system) noexcept;
  // A group move's next sample, given by its group block after this scan's
  // cycle for the next one: the set position and velocity there, the
  // acceleration that leads to it, the scans to the common arrival, and
  // done when the group arrives (next is then the target, at rest). A GroupMove
  // command not fed before a cycle has lost its group: it ends Aborted and
  // the axis brakes to standstill with MaxDecelerationAppl.
  // The slave of a gear or cam (Synchronized) is fed the same way; its
  // samples are checked against the *Appl limits (SyncLimit, ErrorStop), and
  // done ends it Done (a single-shot cam's end, for a buffered command).
  void feed(CommandId id, const motion::FilterState& next, double a, std::int64_t remaining, bool done) noexcept;
  // Commands wait behind the active one (a periodic cam hands over at the end
  // of its profile).
  bool has_buffered() const noexcept { return queued_ > 0; }
  // MC_Home's procedure (set once, before the first command; default "set here").
  void configure_homing(const HomingConfig& h) noexcept { homing_ = h; }
  const HomingConfig& homing() const noexcept { return homing_; }

  // ---- what the axis shows --------------------------------------------
  AxisState state() const noexcept { return state_; }
  AxisError axis_error() const noexcept { return error_; }
  std::uint16_t drive_fault_code() const noexcept { return fault_code_; }
  bool power_on() const noexcept { return fb_.power_on; }
  bool powered_request() const noexcept { return power_request_; }
  // Set values (§2.3): continuous position, velocity, acceleration.
  double set_position() const noexcept { return set_.x; }
  double set_velocity() const noexcept { return set_.v; }
  double set_acceleration() const noexcept { return set_a_; }
  // Actual values as the last feedback gave them (position wrapped on a
  // modulo axis, as users see it) and the following error set - actual.
  double actual_position() const noexcept;
  double actual_velocity() const noexcept { return fb_.velocity; }
  double following_error() const noexcept;
  bool feedback_valid() const noexcept { return fb_.valid; }
  // Wrapped into [0, modulo) on a modulo axis, else p.
  double user_position(double continuous) const noexcept;
  // The active command (0 none) and the scans its profile still needs to
  // reach its goal (paper 004 Table I; -1 when it has no end: MoveVelocity).
  CommandId active_command() const noexcept { return active_.id; }
  CommandKind active_kind() const noexcept { return active_.cmd.kind; }
  std::int64_t remaining_scans() const noexcept;
  bool homed() const noexcept { return homed_; }
  const AxisLimits& limits() const noexcept { return appl_; }
  const AxisLimits& system_limits() const noexcept { return system_; }
  double period() const noexcept { return T_; }

 private:
  struct Slot {
    CommandId id = 0;
    Command cmd{};    // acceleration/deceleration 0 already replaced by the axis's maximum at submit
    double goal = 0;  // continuous target position of a discrete move (resolved when it starts)
    bool goal_known = false;  // goal holds it (started, or predicted at submit)
    double start = 0;         // set position when it started (a discrete move's direction)
    double base = 0;          // MoveRelative/MoveAdditive: what the distance is added to (at its start)
    std::uint8_t phase = 0;   // MC_Home with a switch: HomePhase
    double edge = 0;          // ... the actual position at the switch's rising edge
    std::int64_t waited = 0;  // MC_Home by the drive: cycles waited (home_timeout)
    // GroupMove: the sample its group fed for the next cycle.
    motion::FilterState fed{};
    double fed_a = 0;
    std::int64_t fed_remaining = -1;
    bool fed_now = false, fed_done = false;
  };
  // MC_Home with a reference switch (axis_homing.cpp).
  enum HomePhase : std::uint8_t { kHomeLeave = 1, kHomeSearch = 2, kHomeBrake = 3, kHomeDrive = 4 };
  HomingConfig homing_{};
  struct Report {
    CommandId id = 0;
    CommandReport report{};
  };

  AxisLimits system_, appl_;
  double T_;
  AxisState state_ = AxisState::Disabled;
  AxisError error_ = AxisError::None;
  std::uint16_t fault_code_ = 0;
  bool power_request_ = false;
  bool stop_held_ = false;  // the Done MC_Stop still holds the axis in Stopping
  bool homed_ = false;
  DriveFeedback fb_{};
  DriveCommand out_{};
  motion::FilterState set_{};  // set position and velocity
  double set_a_ = 0;
  double last_a_ = 0;          // the set acceleration over the last sample (set_.v's change / T)
  // A jerk-limited command's set values: the average of its inner profile
  // over the window (axis_jerk.hpp); length 1 for the others.
  JerkWindow window_{};
  double offset_ = 0;          // user position = drive position + offset_ (MC_SetPosition, MC_Home)
  bool reset_pending_ = false;   // MC_Reset came while the drive was in fault
  bool stop_released_ = false;   // the active MC_Stop's Execute already fell
  CommandId held_stop_ = 0;      // the Done MC_Stop that holds the axis (stop_held_)
  bool lag_on_ = false;          // EnablePosLagMonitoring
  double lag_value_ = 0;         // MaxPositionLag as written (appl_.max_position_lag is 0 while off)
  Slot active_{};
  std::array<Slot, kQueueCapacity> queue_{};
  std::size_t queued_ = 0;
  std::array<Report, kReportCapacity> reports_{};
  std::size_t next_report_ = 0;
  CommandId next_id_ = 1;

  void enter_error(AxisError e) noexcept;
  void end_all(CommandStatus status, AxisError e) noexcept;
  void end_command(CommandId id, CommandStatus status, AxisError e) noexcept;
  void start(const Slot& s, double base) noexcept;
  void promote_or_stand(double base) noexcept;
  double blend_target() const noexcept;
  void advance() noexcept;
  void brake(double d) noexcept;
  bool passes_limit(const motion::FilterState& next) const noexcept;
  bool beyond_sync_limits(const motion::FilterState& next) const noexcept;  // axis_sync.cpp
  void leave_sync(const Slot& s) noexcept;                                  // axis_sync.cpp
  struct Step;
  Step profile_step(const Slot& s, const motion::FilterState& from) const noexcept;
  AxisError check_command(Command* c) const noexcept;
  void begin_window(const Command& c) noexcept;
  double lookahead_accel() const noexcept;
  void update_output() noexcept;
  void limit_commands() noexcept;
  void start_homing() noexcept;
  bool homing_phase() noexcept;  // false: the search failed (ErrorStop entered)
  motion::FilterState home_step(const Slot& s, const motion::FilterState& from, bool* done, double* a) const noexcept;
  void finish_homing(const Slot& s) noexcept;
  bool drive_homing() const noexcept { return active_.id != 0 && active_.cmd.kind == CommandKind::Home && active_.phase == kHomeDrive; }
};

}  // namespace syncplc::plcopen
