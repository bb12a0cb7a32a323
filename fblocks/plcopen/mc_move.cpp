// The motion blocks of PLCopen Part 1 v2.0 that start a command on their axis
// at Execute's rising edge: MC_MoveAbsolute (§3.5), MC_MoveRelative (§3.6),
// MC_MoveAdditive (§3.7), MC_MoveVelocity (§3.9), MC_Halt (§3.4), MC_Stop
// (§3.3), MC_Home (§3.2, "set here"). The axis (axis_machine.hpp) checks and
// runs the command; the block samples its inputs at the edge and shows the
// command's progress by the rules of §2.4.1 (mc_block.hpp).
#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include "fblocks/plcopen/mc_block.hpp"
#include "fblocks/plcopen/plcopen.hpp"
#include "runtime/core/pin_decl.hpp"

namespace syncplc::plcopen {

LinkDecl axis_link() {
  return {"Axis", kAxisType, "the MC_AXIS instance this block works on (AXIS_REF)"};
}

namespace {

// Where a move block's pins are (-1: the type has no such pin).
struct MovePins {
  int execute = 0;
  int continuous_update = -1;  // the discrete moves (§2.4.1)
  int position = -1;  // Position or Distance
  int velocity = -1;
  int acceleration = -1;
  int deceleration = -1;
  int jerk = -1;
  int direction = -1;
  int buffer = -1;
  int done = -1;  // Done, or InVelocity for MC_MoveVelocity
  int busy = -1, active = -1, aborted = -1, error = -1, error_id = -1;
};

class MoveBlock final : public McBlock {
 public:
  MoveBlock(CommandKind kind, const MovePins& pins) noexcept : kind_(kind), p_(pins) {}

  void execute(ScanContext& ctx) noexcept override {
    const AxisMachine* m = axis_ ? &axis_->machine() : nullptr;
    tracker_.update(in<bool>(p_.execute), m, [&](AxisError* e) -> CommandId {
      Command c;
      if (!sample(&c, e)) return 0;
      follow_inputs_ = p_.continuous_update >= 0 && in<bool>(p_.continuous_update);
      sampled_ = c;
      return axis_->submit(c, ctx.block, e);
    });
    if (follow_inputs_ && tracker_.command() && tracker_.outputs().busy) continuous_update();
    if (kind_ == CommandKind::Stop && axis_) {
      // §3.3: the axis leaves Stopping once the stop is Done and its
      // Execute is FALSE.
      const CommandId last = tracker_.last_command();
      if (!tracker_.execute() && last && last != released_) {
        axis_->machine().release_stop(last);
        released_ = last;
      }
    }
    const ExecuteOutputs& o = tracker_.outputs();
    out<bool>(p_.done, kind_ == CommandKind::MoveVelocity ? o.in_velocity : o.done);
    out<bool>(p_.busy, o.busy);
    out<bool>(p_.active, o.active);
    out<bool>(p_.aborted, o.aborted);
    out<bool>(p_.error, o.error);
    out<std::uint16_t>(p_.error_id, o.error_id);
  }

 protected:
  void axis_changed() noexcept override { tracker_.axis_changed(); }

 private:
  double real(int pin) const noexcept { return pin >= 0 ? in<double>(pin) : 0.0; }

  // ContinuousUpdate TRUE at the edge (§2.4.1): while the command is Busy,
  // inputs that changed go to the axis, which re-targets the move in flight.
  // New inputs the axis refuses leave the command going on as it was.
  void continuous_update() noexcept {
    Command c;
    AxisError e = AxisError::None;
    if (!sample(&c, &e)) return;
    if (c.position == sampled_.position && c.velocity == sampled_.velocity &&
        c.acceleration == sampled_.acceleration && c.deceleration == sampled_.deceleration &&
        c.jerk == sampled_.jerk && c.direction == sampled_.direction)
      return;
    sampled_ = c;  // a refused change is not offered again every scan
    axis_->machine().update(tracker_.command(), c);
  }

  // The inputs at the edge, as the axis's command; false with *e set for
  // an enumeration out of range.
  bool sample(Command* c, AxisError* e) const noexcept {
    c->kind = kind_;
    c->position = real(p_.position);
    c->velocity = real(p_.velocity);
    c->acceleration = real(p_.acceleration);
    c->deceleration = real(p_.deceleration);
    c->jerk = real(p_.jerk);
    if (p_.buffer >= 0) {
      const std::int16_t b = in<std::int16_t>(p_.buffer);
      if (b < 0 || b > 5) {
        *e = AxisError::BadBufferMode;
        return false;
      }
      c->buffer = static_cast<BufferMode>(b);
    }
    if (p_.direction >= 0) {
      const std::int16_t d = in<std::int16_t>(p_.direction);
      if (d < 1 || d > 4) {
        *e = AxisError::BadDirection;
        return false;
      }
      c->direction = static_cast<Direction>(d);
    }
    if (kind_ == CommandKind::MoveVelocity) {
      // §3.9: Velocity's sign times the direction's (positive, negative,
      // current); shortest way has no meaning for a velocity.
      double sign = 1;
      switch (c->direction) {
        case Direction::Positive: sign = 1; break;
        case Direction::Negative: sign = -1; break;
        case Direction::Current: sign = axis_->machine().set_velocity() < 0 ? -1 : 1; break;
        case Direction::Shortest: *e = AxisError::BadDirection; return false;
      }
      c->velocity *= sign;
    }
    return true;
  }

  CommandKind kind_;
  MovePins p_;
  ExecuteTracker tracker_;
  CommandId released_ = 0;
  bool follow_inputs_ = false;  // ContinuousUpdate was TRUE at the edge
  Command sampled_{};           // the inputs the axis has
};

// The pins in the standard's order: inputs, then outputs.
struct MoveType {
  const char* name;
  CommandKind kind;
  const char* section;
  const char* doc;
  const char* position;  // "Position", "Distance" or nullptr
  bool velocity, accelerations, direction, buffer;
};

void add_move(BlockRegistry& r, const MoveType& m) {
  BlockTypeInfo t;
  t.name = m.name;
  t.category = kCategory;
  t.doc = m.doc;
  t.reference = std::string("PLCopen Motion Control Part 1 v2.0, ") + m.section + " and 2.4.1";
  MovePins p;
  auto add = [&](Pin pin) {
    t.pins.push_back(pin);
    return static_cast<int>(t.pins.size() - 1);
  };
  p.execute = add(input("Execute", IecType::BOOL).doc("rising edge: the command starts, with the inputs sampled now"));
  if (m.kind == CommandKind::MoveAbsolute || m.kind == CommandKind::MoveRelative || m.kind == CommandKind::MoveAdditive ||
      m.kind == CommandKind::MoveVelocity)
    p.continuous_update = add(input("ContinuousUpdate", IecType::BOOL)
                                  .doc(m.kind == CommandKind::MoveVelocity
                                           ? "TRUE at the edge: changes of the inputs while Busy change the velocity to reach "
                                             "in flight (BufferMode stays)"
                                           : "TRUE at the edge: changes of the inputs while Busy re-target the move in flight "
                                             "(Distance from where the move started; BufferMode stays)"));
  if (m.position)
    p.position = add(input(m.position, IecType::LREAL)
                         .doc(std::string(m.position) == "Position" ? "target position, user units"
                                                                     : "distance to travel, user units"));
  if (m.velocity)
    p.velocity = add(input("Velocity", IecType::LREAL)
                         .doc(m.kind == CommandKind::MoveVelocity
                                  ? "velocity to reach, user units/s (signed; times the Direction's sign)"
                                  : "maximum velocity, user units/s, > 0"));
  if (m.accelerations) {
    p.acceleration = add(input("Acceleration", IecType::LREAL).doc("user units/s^2; 0: the axis's MaxAccelerationAppl"));
    p.deceleration = add(input("Deceleration", IecType::LREAL).doc("user units/s^2; 0: the axis's MaxDecelerationAppl"));
  } else if (m.kind == CommandKind::Halt || m.kind == CommandKind::Stop) {
    p.deceleration = add(input("Deceleration", IecType::LREAL).doc("user units/s^2; 0: the axis's MaxDecelerationAppl"));
  }
  if (m.kind != CommandKind::Home)
    p.jerk = add(input("Jerk", IecType::LREAL).doc("user units/s^3, > 0: a jerk-limited profile; 0: the axis's MaxJerkAppl (0 there too: not jerk-limited)"));
  if (m.direction)
    p.direction = add(input("Direction", IecType::INT).init("1")
                          .doc("MC_DIRECTION: 1 positive, 2 shortest way, 3 negative, 4 current"));
  if (m.buffer)
    p.buffer = add(input("BufferMode", IecType::INT).init("0")
                       .doc("MC_BUFFER_MODE: 0 Aborting, 1 Buffered, 2 BlendingLow, 3 BlendingPrevious, 4 BlendingNext, 5 BlendingHigh"));
  p.done = add(m.kind == CommandKind::MoveVelocity
                   ? output("InVelocity", IecType::BOOL).doc("the set velocity equals Velocity (set, not actual)")
                   : output("Done", IecType::BOOL).doc("the command reached its goal"));
  p.busy = add(output("Busy", IecType::BOOL).doc("the command has not ended"));
  p.active = add(output("Active", IecType::BOOL).doc("the command has control of the axis"));
  p.aborted = add(output("CommandAborted", IecType::BOOL).doc("another command, or MC_Power off, ended it"));
  p.error = add(output("Error", IecType::BOOL).doc("the command was refused or the axis went to ErrorStop"));
  p.error_id = add(output("ErrorID", IecType::WORD).doc("why (docs/motion/plcopen.md, \"Error IDs\")"));
  t.links = {axis_link()};
  const CommandKind kind = m.kind;
  t.create = [kind, p](BlockSetup&) -> std::unique_ptr<Block> { return std::make_unique<MoveBlock>(kind, p); };
  r.add(std::move(t));
}

}  // namespace

void register_move_blocks(BlockRegistry& r) {
  const std::vector<MoveType> types = {
      {"MC_MoveAbsolute", CommandKind::MoveAbsolute, "3.5",
       "Moves the axis to Position with at most Velocity, Acceleration and Deceleration, arriving at rest "
       "(paper 004's filter: exact arrival, no overshoot from rest). A modulo axis takes Position in [0, modulo) "
       "and goes the way Direction says.",
       "Position", true, true, true, true},
      {"MC_MoveRelative", CommandKind::MoveRelative, "3.6",
       "Moves the axis by Distance from its set position when the command starts.", "Distance", true, true, false,
       true},
      {"MC_MoveAdditive", CommandKind::MoveAdditive, "3.7",
       "Adds Distance to the goal of the discrete move before it (in DiscreteMotion), else to the set position.",
       "Distance", true, true, false, true},
      {"MC_MoveVelocity", CommandKind::MoveVelocity, "3.9",
       "Runs the axis at Velocity (ContinuousMotion) until another command takes over; InVelocity while the set "
       "velocity equals it.",
       nullptr, true, true, true, true},
      {"MC_Halt", CommandKind::Halt, "3.4",
       "Brakes the axis to standstill with Deceleration (DiscreteMotion, then Standstill); another command may "
       "take over while it brakes.",
       nullptr, false, false, false, true},
      {"MC_Stop", CommandKind::Stop, "3.3",
       "Brakes the axis to standstill with Deceleration and holds it in Stopping, refusing every other motion "
       "command, until this block's Execute is FALSE after Done.",
       nullptr, false, false, false, false},
      {"MC_Home", CommandKind::Home, "3.2",
       "Homing from Standstill by the axis's home_mode: 0 \"set here\", the position becomes Position where the axis "
       "stands (Homing for one scan); 1 or 2, a search at home_velocity for the rising edge of the axis's "
       "home_switch moving in + or - (first away from the switch if it is on), then a stop: the position at the "
       "edge becomes Position; 3, the drive homes itself (CiA 402 homing mode through CIA402_DRIVE, with the "
       "axis's home_method): Position becomes the drive's home offset, Done when the drive reports homing "
       "attained, ErrorStop 0x0307 on its homing error, 0x0308 after home_timeout. Then Standstill, homed.",
       "Position", false, false, false, true},
  };
  for (const auto& m : types) add_move(r, m);
}

}  // namespace syncplc::plcopen
