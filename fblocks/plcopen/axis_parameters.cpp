// MC_ReadParameter / MC_WriteParameter of the PLCopen axis (§3.19's numbers):
// the *System values are the configured limits and read only, the *Appl ones
// may be lowered (never raised above the system's) while the axis runs.
#include <cmath>

#include "fblocks/plcopen/axis_machine.hpp"

namespace syncplc::plcopen {

AxisError AxisMachine::read_parameter(std::int16_t number, double* value) const noexcept {
  if (value == nullptr) return AxisError::BadParameter;
  switch (static_cast<AxisParameter>(number)) {
    case AxisParameter::CommandedPosition: *value = user_position(set_.x); break;
    case AxisParameter::SWLimitPos: *value = appl_.sw_limit_pos; break;
    case AxisParameter::SWLimitNeg: *value = appl_.sw_limit_neg; break;
    case AxisParameter::EnableLimitPos: *value = appl_.sw_limit_pos_on ? 1 : 0; break;
    case AxisParameter::EnableLimitNeg: *value = appl_.sw_limit_neg_on ? 1 : 0; break;
    case AxisParameter::EnablePosLagMonitoring: *value = lag_on_ ? 1 : 0; break;
    case AxisParameter::MaxPositionLag: *value = lag_value_; break;
    case AxisParameter::MaxVelocitySystem: *value = system_.v_max; break;
    case AxisParameter::MaxVelocityAppl: *value = appl_.v_max; break;
    case AxisParameter::ActualVelocity: *value = fb_.velocity; break;
    case AxisParameter::CommandedVelocity: *value = set_.v; break;
    case AxisParameter::MaxAccelerationSystem: *value = system_.a_max; break;
    case AxisParameter::MaxAccelerationAppl: *value = appl_.a_max; break;
    case AxisParameter::MaxDecelerationSystem: *value = system_.d_max; break;
    case AxisParameter::MaxDecelerationAppl: *value = appl_.d_max; break;
    case AxisParameter::MaxJerkSystem: *value = system_.j_max; break;
    case AxisParameter::MaxJerkAppl: *value = appl_.j_max; break;
    default: return AxisError::BadParameter;
  }
  return AxisError::None;
}

namespace {

bool flag(double v, bool* out) noexcept {
  if (v != 0 && v != 1) return false;
  *out = v == 1;
  return true;
}

// A positive limit, at most the system's.
bool positive_upto(double v, double system, double* out) noexcept {
  if (!std::isfinite(v) || !(v > 0) || v > system) return false;
  *out = v;
  return true;
}

}  // namespace

AxisError AxisMachine::write_parameter(std::int16_t number, double value) noexcept {
  if (!std::isfinite(value)) return AxisError::BadParameter;
  AxisLimits next = appl_;
  bool ok = true;
  switch (static_cast<AxisParameter>(number)) {
    case AxisParameter::SWLimitPos: next.sw_limit_pos = value; break;
    case AxisParameter::SWLimitNeg: next.sw_limit_neg = value; break;
    case AxisParameter::EnableLimitPos: ok = flag(value, &next.sw_limit_pos_on); break;
    case AxisParameter::EnableLimitNeg: ok = flag(value, &next.sw_limit_neg_on); break;
    case AxisParameter::EnablePosLagMonitoring: {
      bool on = false;
      if (!flag(value, &on)) return AxisError::BadParameter;
      lag_on_ = on;
      appl_.max_position_lag = lag_on_ ? lag_value_ : 0;
      return AxisError::None;
    }
    case AxisParameter::MaxPositionLag:
      if (!(value >= 0)) return AxisError::BadParameter;
      lag_value_ = value;
      appl_.max_position_lag = lag_on_ ? lag_value_ : 0;
      return AxisError::None;
    case AxisParameter::MaxVelocityAppl: ok = positive_upto(value, system_.v_max, &next.v_max); break;
    case AxisParameter::MaxAccelerationAppl: ok = positive_upto(value, system_.a_max, &next.a_max); break;
    case AxisParameter::MaxDecelerationAppl: ok = positive_upto(value, system_.d_max, &next.d_max); break;
    case AxisParameter::MaxJerkAppl:  // 0 = not jerk-limited; a command with Jerk 0 takes it when it starts
      ok = value >= 0 && value <= system_.j_max;
      next.j_max = value;
      break;
    default: return AxisError::BadParameter;  // unknown, or read only
  }
  if (!ok) return AxisError::BadParameter;
  if (next.sw_limit_pos_on && next.sw_limit_neg_on && !(next.sw_limit_neg < next.sw_limit_pos))
    return AxisError::BadParameter;
  appl_ = next;
  limit_commands();
  return AxisError::None;
}

void AxisMachine::retune(const AxisLimits& system) noexcept {
  const double modulo = system_.modulo;
  system_ = system;
  system_.modulo = modulo;
  appl_ = system_;
  lag_value_ = system_.max_position_lag;
  lag_on_ = lag_value_ > 0;
  limit_commands();
}

void AxisMachine::limit_commands() noexcept {
  auto cut = [this](Slot& s) {
    Command& c = s.cmd;
    if (c.kind == CommandKind::MoveVelocity)
      c.velocity = std::fmax(-appl_.v_max, std::fmin(c.velocity, appl_.v_max));
    else if (c.velocity > appl_.v_max)
      c.velocity = appl_.v_max;
    c.acceleration = std::fmin(c.acceleration, appl_.a_max);
    c.deceleration = std::fmin(c.deceleration, appl_.d_max);
  };
  if (active_.id != 0) cut(active_);
  for (std::size_t i = 0; i < queued_; ++i) cut(queue_[i]);
}

}  // namespace syncplc::plcopen
