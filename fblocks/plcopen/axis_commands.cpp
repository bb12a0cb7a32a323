// The commands of the motion blocks at their Execute edge: checked against the
// state, the inputs and the software limits, then started (Aborting) or queued
// behind the active one (Buffered, blending).
#include <cmath>

#include "fblocks/plcopen/axis_machine.hpp"
#include "fblocks/plcopen/axis_profile.hpp"

namespace syncplc::plcopen {

namespace {

// An acceleration-like input: finite, >= 0, 0 = the axis's maximum, above it an error.
bool resolve_rate(double* v, double max) noexcept {
  if (!std::isfinite(*v) || *v < 0 || *v > max) return false;
  if (*v == 0) *v = max;
  return true;
}

}  // namespace

AxisError AxisMachine::check_command(Command* c) const noexcept {
  const CommandKind k = c->kind;
  if (k != CommandKind::MoveAbsolute && k != CommandKind::MoveRelative && k != CommandKind::MoveAdditive &&
      k != CommandKind::MoveVelocity && k != CommandKind::Halt && k != CommandKind::Stop && k != CommandKind::Home &&
      k != CommandKind::GroupMove && k != CommandKind::Synchronized && k != CommandKind::SyncOut)
    return AxisError::BadParameter;
  if (k == CommandKind::SyncOut) return AxisError::None;
  if (k == CommandKind::Synchronized) {
    // The coupling block checks its own inputs; the axis checks every sample
    // against its limits. Blending has no goal to blend at.
    if (c->buffer != BufferMode::Aborting && c->buffer != BufferMode::Buffered) return AxisError::BadBufferMode;
    return AxisError::None;
  }
  if (k == CommandKind::GroupMove) {
    // The group's synchronizer keeps the axis within its *Appl limits; only
    // Aborting (a group move takes over), never on a modulo axis.
    if (!std::isfinite(c->position) || appl_.modulo > 0) return AxisError::BadPosition;
    if (c->buffer != BufferMode::Aborting) return AxisError::BadBufferMode;
    if ((appl_.sw_limit_pos_on && c->position > appl_.sw_limit_pos) ||
        (appl_.sw_limit_neg_on && c->position < appl_.sw_limit_neg))
      return AxisError::BadPosition;
    return AxisError::None;
  }
  if (k == CommandKind::Home) return std::isfinite(c->position) ? AxisError::None : AxisError::BadPosition;
  if (is_move(k)) {
    if (!std::isfinite(c->position)) return AxisError::BadPosition;
    if (!std::isfinite(c->velocity) || !(c->velocity > 0) || c->velocity > appl_.v_max) return AxisError::BadVelocity;
  }
  if (k == CommandKind::MoveVelocity &&
      (!std::isfinite(c->velocity) || std::fabs(c->velocity) > appl_.v_max))
    return AxisError::BadVelocity;
  if ((is_move(k) || k == CommandKind::MoveVelocity) && !resolve_rate(&c->acceleration, appl_.a_max))
    return AxisError::BadAcceleration;
  if (!resolve_rate(&c->deceleration, appl_.d_max)) return AxisError::BadDeceleration;
  // Jerk: finite, >= 0, at most MaxJerkAppl when the axis has one; 0 = the
  // axis's MaxJerkAppl (0 there too: not jerk-limited). The window the
  // profile needs must fit (JerkWindow::kCapacity samples).
  if (!std::isfinite(c->jerk) || c->jerk < 0 || (appl_.j_max > 0 && c->jerk > appl_.j_max)) return AxisError::BadJerk;
  if (c->jerk == 0) c->jerk = appl_.j_max;
  if (c->jerk > 0) {
    const double U = std::fmax(c->acceleration, c->deceleration);
    if (JerkWindow::length_for(U, U, c->jerk, T_) > JerkWindow::kCapacity) return AxisError::BadJerk;
  }
  if (k != CommandKind::Stop) {
    const auto bm = static_cast<unsigned>(c->buffer);
    if (bm > static_cast<unsigned>(BufferMode::BlendingHigh)) return AxisError::BadBufferMode;
  }
  if (k == CommandKind::MoveAbsolute) {
    const auto d = static_cast<unsigned>(c->direction);
    if (d < 1 || d > 4) return AxisError::BadDirection;
    if (appl_.modulo > 0 && !(c->position >= 0 && c->position < appl_.modulo)) return AxisError::BadPosition;
  }
  return AxisError::None;
}

CommandId AxisMachine::submit(const Command& in, AxisError* error) noexcept {
  // A caller that does not want the reason may pass nullptr.
  AxisError reason_not_wanted;
  if (error == nullptr) error = &reason_not_wanted;
  *error = AxisError::None;
  const CommandKind k = in.kind;
  // MC_Home's last Homing cycle counts as Standstill: a block chained on its Done may start.
  const bool standing = state_ == AxisState::Standstill || (state_ == AxisState::Homing && active_.id == 0);
  // MC_GearOut/MC_CamOut: only a synchronized slave can leave its coupling (§4.3, §4.5).
  if (k == CommandKind::SyncOut && state_ != AxisState::SynchronizedMotion) *error = AxisError::NotSynchronized;
  else if (state_ == AxisState::Disabled) *error = AxisError::Disabled;
  else if (state_ == AxisState::ErrorStop) *error = AxisError::InErrorStop;
  else if (state_ == AxisState::Stopping && k != CommandKind::Stop) *error = AxisError::Stopping;
  else if (k == CommandKind::Home && !standing) *error = AxisError::NotStandstill;
  else if (state_ == AxisState::Homing && !standing && k != CommandKind::Stop) *error = AxisError::NotStandstill;
  if (*error != AxisError::None) return 0;

  Command c = in;
  *error = check_command(&c);
  if (*error != AxisError::None) return 0;

  // Buffered and the blending modes wait for the active command; with nothing
  // active they start at once like Aborting.
  const bool buffered =
      c.buffer != BufferMode::Aborting && k != CommandKind::Stop && k != CommandKind::SyncOut && active_.id != 0;
  if (buffered && queued_ == kQueueCapacity) {
    *error = AxisError::BufferFull;
    return 0;
  }

  // Where the chain of commands ends (the base of a relative/additive goal):
  // the set position now, or the goal of the discrete move it buffers behind.
  bool base_known = true;
  double base = set_.x, additive_base = set_.x;
  if (buffered) {
    const Slot& last = queued_ > 0 ? queue_[queued_ - 1] : active_;
    base_known = is_move(last.cmd.kind) && last.goal_known;
    base = additive_base = last.goal;
  } else if (state_ == AxisState::DiscreteMotion && is_move(active_.cmd.kind)) {
    additive_base = active_.goal;
  }
  Slot s{0, c, 0, false, 0};
  if (is_move(k)) {
    if (k == CommandKind::MoveAbsolute && appl_.modulo == 0) {
      s.goal = c.position;
      s.goal_known = true;
    } else if (k == CommandKind::MoveRelative && base_known) {
      s.goal = base + c.position;
      s.goal_known = true;
    } else if (k == CommandKind::MoveAdditive && base_known) {
      s.goal = additive_base + c.position;
      s.goal_known = true;
    }
    if (s.goal_known && ((appl_.sw_limit_pos_on && s.goal > appl_.sw_limit_pos) ||
                         (appl_.sw_limit_neg_on && s.goal < appl_.sw_limit_neg))) {
      *error = AxisError::BadPosition;
      return 0;
    }
  }

  s.id = next_id_++;
  if (buffered) {
    queue_[queued_++] = s;
    return s.id;
  }
  // Aborting (or nothing to buffer behind): every command in the axis ends Aborted.
  end_all(CommandStatus::Aborted, AxisError::None);
  if (held_stop_ != 0) {  // a Done MC_Stop's hold passes to the new MC_Stop
    held_stop_ = 0;
    stop_held_ = false;
  }
  start(s, k == CommandKind::MoveAdditive ? additive_base : set_.x);
  update_output();
  return s.id;
}

}  // namespace syncplc::plcopen
