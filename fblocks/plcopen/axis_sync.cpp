// The axis side of synchronized motion (MC_GearIn/MC_CamIn's slave, MC_GearOut/
// MC_CamOut): the check of every sample a coupling block feeds against the
// axis's *Appl limits, and the way out of SynchronizedMotion.
#include <cmath>

#include "fblocks/plcopen/axis_machine.hpp"

namespace syncplc::plcopen {

namespace axis_sync {

// Relative slack for rounding: a ramp at exactly the limit passes.
constexpr double kSlack = 1e-9;

}  // namespace axis_sync

// A fed sample is beyond the limits when its velocity, the mean velocity of
// its position step (which catches a jump) or the velocity change over the
// sample is more than MaxVelocityAppl, MaxAccelerationAppl (speeding up) or
// MaxDecelerationAppl (slowing down) allow; a change through zero is taken
// at the higher of the two (as ramp_step brakes through zero with one rate).
bool AxisMachine::beyond_sync_limits(const motion::FilterState& next) const noexcept {
  using axis_sync::kSlack;
  if (!std::isfinite(next.x) || !std::isfinite(next.v)) return true;
  const double v_lim = appl_.v_max * (1 + kSlack);
  if (std::fabs(next.v) > v_lim) return true;
  const double dx = std::fabs(next.x - set_.x);
  const double round = 8e-16 * (std::fabs(next.x) + std::fabs(set_.x));
  if (dx > v_lim * T_ + round) return true;
  const double v0 = set_.v, v1 = next.v;
  double need = 0;  // time the change needs at the limits
  if (v0 * v1 >= 0) {
    const double dv = std::fabs(v1) - std::fabs(v0);
    need = dv >= 0 ? dv / appl_.a_max : -dv / appl_.d_max;
  } else {
    need = (std::fabs(v0) + std::fabs(v1)) / std::fmax(appl_.a_max, appl_.d_max);
  }
  const double v_round = 8e-16 * (std::fabs(v0) + std::fabs(v1)) / std::fmin(appl_.a_max, appl_.d_max);
  return need > T_ * (1 + kSlack) + v_round;
}

// MC_GearOut/MC_CamOut: the coupling (and what waits behind it) ended by
// submit's Aborting; the out command is Done at once and the axis keeps the
// set velocity it has, as an MC_MoveVelocity would (ContinuousMotion, §4.5).
void AxisMachine::leave_sync(const Slot& s) noexcept {
  end_command(s.id, CommandStatus::Done, AxisError::None);
  Slot keep{};
  keep.id = next_id_++;
  keep.cmd.kind = CommandKind::MoveVelocity;
  keep.cmd.velocity = std::fmax(-appl_.v_max, std::fmin(set_.v, appl_.v_max));
  keep.cmd.acceleration = appl_.a_max;
  keep.cmd.deceleration = appl_.d_max;
  active_ = keep;
  active_.start = active_.goal = set_.x;
  active_.goal_known = true;
  state_ = AxisState::ContinuousMotion;
  stop_released_ = false;
}

}  // namespace syncplc::plcopen
