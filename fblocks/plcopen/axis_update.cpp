// ContinuousUpdate of the discrete moves and MC_MoveVelocity (PLCopen Part 1
// v2.0 §2.4.1, the input ContinuousUpdate): new inputs for a command that is
// still Active or Buffered. The profile needs no re-planning: the filter (and the jerk
// window) is memoryless in its goal, so the active move simply tracks the new
// goal from the state it is in, and its remaining scans are those of the new
// goal from there.
#include <cmath>

#include "fblocks/plcopen/axis_machine.hpp"
#include "fblocks/plcopen/axis_profile.hpp"

namespace syncplc::plcopen {

AxisError AxisMachine::update(CommandId id, const Command& in) noexcept {
  if (id == 0) return AxisError::None;
  Slot* s = nullptr;
  if (id == active_.id) {
    s = &active_;
  } else {
    for (std::size_t i = 0; i < queued_; ++i)
      if (queue_[i].id == id) s = &queue_[i];
  }
  if (s == nullptr) return AxisError::None;  // ended: nothing left to update
  const bool velocity_move = s->cmd.kind == CommandKind::MoveVelocity;
  if ((!is_move(s->cmd.kind) && !velocity_move) || in.kind != s->cmd.kind) return AxisError::BadParameter;
  Command c = in;
  c.buffer = s->cmd.buffer;  // how it joined the queue is history
  const AxisError e = check_command(&c);
  if (e != AxisError::None) return e;

  double goal = s->goal;
  bool known = s->goal_known;
  // MC_MoveVelocity has no goal: its ramp goes on from the set velocity to the new one.
  if (!velocity_move && s == &active_) {
    if (c.kind == CommandKind::MoveAbsolute)
      goal = appl_.modulo > 0 ? modulo_goal(set_.x, set_.v, c.position, appl_.modulo, c.direction) : c.position;
    else
      goal = s->base + c.position;  // Relative: from where it started; Additive: from the goal it was added to
    known = true;
  } else if (!velocity_move && known) {
    // Waiting: its goal is resolved again when it starts; the prediction
    // (for blending and the limit check) moves with the input.
    goal = c.kind == CommandKind::MoveAbsolute ? c.position : s->goal - s->cmd.position + c.position;
  }
  if (!velocity_move && known && ((appl_.sw_limit_pos_on && goal > appl_.sw_limit_pos) ||
                (appl_.sw_limit_neg_on && goal < appl_.sw_limit_neg)))
    return AxisError::BadPosition;
  s->cmd = c;
  s->goal = goal;
  s->goal_known = known;
  if (s == &active_) {
    begin_window(c);  // the same window goes on; a new jerk or acceleration rebuilds it continuously
    set_a_ = lookahead_accel();
    update_output();
  }
  return AxisError::None;
}

}  // namespace syncplc::plcopen
