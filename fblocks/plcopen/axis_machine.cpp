// The PLCopen axis's state diagram, the active command's profile each cycle,
// the queue and the reports (see axis_machine.hpp; the commands' checks are in
// axis_commands.cpp, the profiles in axis_profile.cpp, the parameters in
// axis_parameters.cpp).
#include "fblocks/plcopen/axis_machine.hpp"

#include <cmath>

#include "fblocks/plcopen/axis_profile.hpp"

namespace syncplc::plcopen {

using motion::FilterState;

struct AxisMachine::Step {
  ProfileStep p;
  bool finite_end = true;  // false: MoveVelocity (its "done" is in_velocity)
};

const char* axis_state_name(AxisState s) noexcept {
  switch (s) {
    case AxisState::Disabled: return "Disabled";
    case AxisState::Standstill: return "Standstill";
    case AxisState::Homing: return "Homing";
    case AxisState::DiscreteMotion: return "DiscreteMotion";
    case AxisState::ContinuousMotion: return "ContinuousMotion";
    case AxisState::SynchronizedMotion: return "SynchronizedMotion";
    case AxisState::Stopping: return "Stopping";
    case AxisState::ErrorStop: return "ErrorStop";
  }
  return "?";
}

namespace {

AxisState state_of(CommandKind k) noexcept {
  switch (k) {
    case CommandKind::MoveVelocity: return AxisState::ContinuousMotion;
    case CommandKind::Stop: return AxisState::Stopping;
    case CommandKind::Home: return AxisState::Homing;
    case CommandKind::Synchronized: return AxisState::SynchronizedMotion;
    default: return AxisState::DiscreteMotion;
  }
}

}  // namespace

AxisMachine::AxisMachine(const AxisLimits& system, double period_s) noexcept
    : system_(system), appl_(system), T_(period_s) {
  lag_value_ = system.max_position_lag;
  lag_on_ = lag_value_ > 0;
  update_output();
}

double AxisMachine::user_position(double continuous) const noexcept {
  return appl_.modulo > 0 ? wrap_modulo(continuous, appl_.modulo) : continuous;
}

double AxisMachine::actual_position() const noexcept { return user_position(fb_.position + offset_); }

double AxisMachine::following_error() const noexcept { return set_.x - (fb_.position + offset_); }

std::int64_t AxisMachine::remaining_scans() const noexcept {
  if (active_.id == 0) return set_.v == 0 ? 0 : -1;
  const Command& c = active_.cmd;
  switch (c.kind) {
    case CommandKind::MoveVelocity: return -1;
    case CommandKind::Halt:
    case CommandKind::Stop:
      if (window_.averaging()) return window_.remaining(ramp_remaining(window_.inner().v, c.deceleration, T_));
      return ramp_remaining(set_.v, c.deceleration, T_);
    case CommandKind::GroupMove:
    case CommandKind::Synchronized: return active_.fed_remaining;
    case CommandKind::Home:
      // Set here: one cycle; a switch search has no known end until it brakes.
      if (homing_.mode == HomingConfig::Mode::SetHere || active_.phase == 0) return 1;
      return active_.phase == kHomeBrake ? ramp_remaining(set_.v, appl_.d_max, T_) : -1;
    default:
      if (window_.averaging())
        return window_.remaining(
            discrete_remaining(window_.inner(), blend_target(), c.velocity, c.acceleration, c.deceleration, T_));
      return discrete_remaining(set_, blend_target(), c.velocity, c.acceleration, c.deceleration, T_);
  }
}

// ---- reports ------------------------------------------------------------------

void AxisMachine::end_command(CommandId id, CommandStatus status, AxisError e) noexcept {
  reports_[next_report_ % kReportCapacity] = {id, {status, e, false}};
  ++next_report_;
}

void AxisMachine::end_all(CommandStatus status, AxisError e) noexcept {
  if (active_.id != 0) end_command(active_.id, status, e);
  active_ = {};
  for (std::size_t i = 0; i < queued_; ++i) end_command(queue_[i].id, status, e);
  queued_ = 0;
  stop_released_ = false;
}

CommandReport AxisMachine::report(CommandId id) const noexcept {
  if (id == 0) return {};
  if (id == active_.id) {
    const bool in_v = active_.cmd.kind == CommandKind::MoveVelocity && set_.v == active_.cmd.velocity;
    return {CommandStatus::Active, AxisError::None, in_v};
  }
  for (std::size_t i = 0; i < queued_; ++i)
    if (queue_[i].id == id) return {CommandStatus::Buffered, AxisError::None, false};
  for (const Report& r : reports_)
    if (r.id == id) return r.report;
  return {};
}

// ---- state diagram ------------------------------------------------------------

void AxisMachine::enter_error(AxisError e) noexcept {
  end_all(CommandStatus::Error, e);
  state_ = AxisState::ErrorStop;
  error_ = e;
  held_stop_ = 0;
  stop_held_ = false;
  reset_pending_ = false;
}

void AxisMachine::request_power(bool enable) noexcept {
  power_request_ = enable;
  if (!enable && state_ != AxisState::Disabled && state_ != AxisState::ErrorStop) {
    end_all(CommandStatus::Aborted, AxisError::None);
    state_ = AxisState::Disabled;
    held_stop_ = 0;
    stop_held_ = false;
    set_a_ = 0;
  }
  update_output();
}

AxisError AxisMachine::reset() noexcept {
  if (state_ != AxisState::ErrorStop) return AxisError::None;
  if (fb_.fault) {
    reset_pending_ = true;  // completes in the cycle the fault clears
    update_output();
    return AxisError::None;
  }
  if (set_.v != 0) return AxisError::StillMoving;
  reset_pending_ = false;
  error_ = AxisError::None;
  fault_code_ = 0;
  set_a_ = 0;
  state_ = fb_.power_on && power_request_ ? AxisState::Standstill : AxisState::Disabled;
  update_output();
  return AxisError::None;
}

void AxisMachine::release_stop(CommandId id) noexcept {
  if (id == 0) return;
  if (id == active_.id && active_.cmd.kind == CommandKind::Stop) {
    stop_released_ = true;
  } else if (id == held_stop_) {
    held_stop_ = 0;
    stop_held_ = false;
    if (state_ == AxisState::Stopping) state_ = AxisState::Standstill;
  }
}

AxisError AxisMachine::set_position(double p, bool relative) noexcept {
  const bool standing = state_ == AxisState::Standstill || (state_ == AxisState::Homing && active_.id == 0);
  if (!standing && state_ != AxisState::Disabled) return AxisError::NotStandstill;
  if (!std::isfinite(p)) return AxisError::BadPosition;
  const double target = relative ? set_.x + p : p;
  offset_ += target - set_.x;
  set_.x = target;
  update_output();
  return AxisError::None;
}

void AxisMachine::cycle(const DriveFeedback& fb) noexcept {
  fb_ = fb;
  const double v_before = set_.v;
  const double actual = fb.position + offset_;

  // Errors (§2.2): a drive fault from any state; the others while enabled.
  if (fb.fault) {
    fault_code_ = fb.fault_code;
    if (state_ != AxisState::ErrorStop) enter_error(AxisError::DriveFault);
    else error_ = AxisError::DriveFault;  // the fault outranks what led here: the power stage is off now
  } else if (state_ != AxisState::Disabled && state_ != AxisState::ErrorStop) {
    if (!fb.valid) enter_error(AxisError::FeedbackLost);
    else if (power_request_ && !fb.power_on) enter_error(AxisError::PowerLost);
    // While the drive homes itself it follows no set value of the axis (and
    // its position may jump to the home offset): no lag to watch.
    else if (!drive_homing() && lag_on_ && lag_value_ > 0 && std::fabs(set_.x - actual) > lag_value_)
      enter_error(AxisError::FollowingError);
  }

  if (state_ == AxisState::Disabled && power_request_ && fb.power_on && fb.valid) {
    state_ = AxisState::Standstill;
    set_ = {actual, 0};
  }

  switch (state_) {
    case AxisState::Disabled:
      if (fb.valid) set_ = {actual, fb.velocity};  // nothing jumps when it powers up
      set_a_ = 0;
      break;
    case AxisState::ErrorStop:
      if (fb.power_on && !fb.fault) {
        brake(system_.d_max);
      } else {
        if (fb.valid) set_ = {actual, fb.velocity};
        set_a_ = 0;
      }
      if (reset_pending_ && !fb.fault && set_.v == 0) {
        reset_pending_ = false;
        reset();
      }
      break;
    case AxisState::Standstill:
      set_.v = 0;
      set_a_ = 0;
      break;
    default:
      advance();
      break;
  }
  // The acceleration a jerk-limited command continues from: none at rest
  // (entering Standstill drops the velocity the set values took from the
  // drive while Disabled; that step is not a profile's acceleration).
  last_a_ = state_ == AxisState::Standstill || state_ == AxisState::Disabled ? 0 : (set_.v - v_before) / T_;
  update_output();
}

void AxisMachine::update_output() noexcept {
  const bool faulted = state_ == AxisState::ErrorStop && (error_ == AxisError::DriveFault || fb_.fault);
  out_.enable = power_request_ && !faulted;
  out_.reset = reset_pending_ && fb_.fault;
  out_.position = set_.x - offset_;
  out_.velocity = set_.v;
  out_.acceleration = set_a_;
  out_.home = drive_homing();
  out_.home_position = active_.cmd.position;
}

// ---- profiles -----------------------------------------------------------------

AxisMachine::Step AxisMachine::profile_step(const Slot& s, const FilterState& from) const noexcept {
  const Command& c = s.cmd;
  switch (c.kind) {
    case CommandKind::MoveVelocity: return {ramp_step(from, c.velocity, c.acceleration, c.deceleration, T_), false};
    case CommandKind::Halt:
    case CommandKind::Stop: return {ramp_step(from, 0, c.deceleration, c.deceleration, T_), true};
    case CommandKind::GroupMove:
    case CommandKind::Synchronized: return {{s.fed, s.fed_a, s.fed_done}, true};
    case CommandKind::Home: {
      Step st;
      st.p.next = home_step(s, from, &st.p.done, &st.p.a);
      return st;
    }
    default: {
      const double target = s.id == active_.id ? blend_target() : s.goal;
      return {discrete_step(from, target, c.velocity, c.acceleration, c.deceleration, T_), true};
    }
  }
}

bool AxisMachine::passes_limit(const FilterState& next) const noexcept {
  const double reach = next.x + braking_distance(next.v, system_.d_max, T_);
  if (appl_.sw_limit_pos_on && next.x > set_.x && (reach > appl_.sw_limit_pos || next.x > appl_.sw_limit_pos))
    return true;
  if (appl_.sw_limit_neg_on && next.x < set_.x && (reach < appl_.sw_limit_neg || next.x < appl_.sw_limit_neg))
    return true;
  return false;
}

// One sample of the ramp to standstill; the set position never passes an
// enabled software limit (the guard in advance() left room for this ramp;
// the clamp only absorbs rounding).
void AxisMachine::brake(double d) noexcept {
  const ProfileStep p = ramp_step(set_, 0, d, d, T_);
  FilterState next = p.next;
  if (appl_.sw_limit_pos_on && next.v >= 0 && next.x > appl_.sw_limit_pos && set_.x <= appl_.sw_limit_pos)
    next.x = appl_.sw_limit_pos;
  if (appl_.sw_limit_neg_on && next.v <= 0 && next.x < appl_.sw_limit_neg && set_.x >= appl_.sw_limit_neg)
    next.x = appl_.sw_limit_neg;
  set_ = next;
  set_a_ = next.v == 0 ? 0 : ramp_step(set_, 0, d, d, T_).a;
}

void AxisMachine::advance() noexcept {
  if (active_.id == 0) {
    // MC_Home's extra Homing cycle, a Done MC_Stop's hold.
    if (state_ == AxisState::Homing) {
      state_ = AxisState::Standstill;
    }
    set_.v = 0;
    set_a_ = 0;
    return;
  }
  if (active_.cmd.kind == CommandKind::Home && !homing_phase()) return;
  const bool fed_kind = active_.cmd.kind == CommandKind::GroupMove || active_.cmd.kind == CommandKind::Synchronized;
  if (fed_kind) {
    if (!active_.fed_now) {
      // The group stopped feeding (it ended, or lost another of its axes),
      // or a gear/cam block let its slave go (its master failed): this axis
      // brakes on its own.
      end_command(active_.id, CommandStatus::Aborted, AxisError::None);
      Slot halt{};
      halt.id = next_id_++;
      halt.cmd.kind = CommandKind::Halt;
      halt.cmd.deceleration = appl_.d_max;
      start(halt, set_.x);
    }
    active_.fed_now = false;
  }
  // A jerk-limited command steps its inner profile; the set values are the
  // window's average (axis_jerk.hpp).
  const bool averaged = window_.averaging();
  const Step step = profile_step(active_, averaged ? window_.inner() : set_);
  if (active_.cmd.kind == CommandKind::Synchronized && beyond_sync_limits(step.p.next)) {
    // The master demands more than this slave can do: it does not follow
    // beyond its limits (docs/motion/plcopen.md, "Limits of the slave").
    enter_error(AxisError::SyncLimit);
    brake(system_.d_max);
    return;
  }
  // A drive homing itself may pass the software limits (they are not yet
  // known to be right): the set values only follow it then.
  if (!drive_homing() && passes_limit(averaged ? window_.peek(step.p.next) : step.p.next)) {
    enter_error(AxisError::SoftLimit);
    brake(system_.d_max);
    return;
  }
  const double v_prev = set_.v;
  bool done = step.p.done;
  if (averaged) {
    set_ = window_.push(step.p.next, step.p.done);
    done = window_.settled();
  } else {
    set_ = step.p.next;
  }
  last_a_ = (set_.v - v_prev) / T_;  // a command started below continues from it
  if (!done && is_move(active_.cmd.kind) && blend_target() != active_.goal) {
    // Blending (§2.4.2): the move is Done where it passes its goal, the next one
    // takes over from the set values there.
    const double dir = active_.goal > active_.start ? 1 : -1;
    done = dir * (set_.x - active_.goal) >= 0;
  }
  if (done) {
    const Slot ended = active_;
    if (ended.cmd.kind == CommandKind::Home) {
      finish_homing(ended);
      active_ = {};
      end_command(ended.id, CommandStatus::Done, AxisError::None);
    } else if (ended.cmd.kind == CommandKind::Stop) {
      active_ = {};
      end_command(ended.id, CommandStatus::Done, AxisError::None);
      if (stop_released_) {
        state_ = AxisState::Standstill;
      } else {
        held_stop_ = ended.id;
        stop_held_ = true;
      }
      stop_released_ = false;
    } else if (ended.cmd.kind == CommandKind::MoveVelocity) {
      if (queued_ > 0) {  // in velocity: the buffered command takes over
        end_command(ended.id, CommandStatus::Aborted, AxisError::None);
        active_ = {};
        promote_or_stand(set_.x);
      }
    } else {
      active_ = {};
      end_command(ended.id, CommandStatus::Done, AxisError::None);
      // A relative or additive move buffered behind a move starts from its goal
      // (where the set position is, unless blending passed it).
      promote_or_stand(is_move(ended.cmd.kind) ? ended.goal : set_.x);
    }
  }
  set_a_ = lookahead_accel();
}

// The set acceleration over the coming sample (the active profile's next step, not taken).
double AxisMachine::lookahead_accel() const noexcept {
  if (active_.id == 0) return 0;
  if (!window_.averaging()) return profile_step(active_, set_).p.a;
  const Step ahead = profile_step(active_, window_.inner());
  if (window_.settled() && ahead.p.done) return 0;
  return (window_.peek(ahead.p.next).v - set_.v) / T_;
}

void AxisMachine::promote_or_stand(double base) noexcept {
  if (queued_ == 0) {
    state_ = AxisState::Standstill;
    return;
  }
  const Slot next = queue_[0];
  for (std::size_t i = 1; i < queued_; ++i) queue_[i - 1] = queue_[i];
  --queued_;
  start(next, base);
}

// The position the active discrete move's filter tracks: its goal, or with a
// blending move next in the same direction (§2.4.2) a point beyond it from
// which braking with the move's deceleration leaves the blending velocity at
// the goal (Low: the lower of the two velocities, High: the higher,
// Previous: the first's, Next: the second's; never above the first's bound,
// which limits the filter, nor above what the second can brake from). The
// move hands over where it passes its goal.
double AxisMachine::blend_target() const noexcept {
  const double g = active_.goal;
  if (!is_move(active_.cmd.kind) || queued_ == 0) return g;
  const Slot& next = queue_[0];
  const BufferMode bm = next.cmd.buffer;
  if (bm == BufferMode::Aborting || bm == BufferMode::Buffered || !is_move(next.cmd.kind) || !next.goal_known)
    return g;
  const double dir = g > active_.start ? 1 : (g < active_.start ? -1 : 0);
  if (dir == 0 || !(dir * (next.goal - g) > 0)) return g;  // a reversal stops at the goal
  const double va = active_.cmd.velocity, vb = next.cmd.velocity;
  double v = va;
  switch (bm) {
    case BufferMode::BlendingLow: v = va < vb ? va : vb; break;
    case BufferMode::BlendingHigh: v = va > vb ? va : vb; break;
    case BufferMode::BlendingNext: v = vb; break;
    default: break;  // BlendingPrevious
  }
  // Never faster than the second move can brake from before its own goal:
  // v^2/(2 d) within its distance less the samples the hand-over may be late
  // (3 v T), and 5 % below that for the filters' discrete approach.
  const double dist = std::fabs(next.goal - g), d = next.cmd.deceleration;
  double cap = std::sqrt(2 * d * dist);
  cap = 0.95 * std::sqrt(2 * d * std::fmax(0, dist - 3 * cap * T_));
  if (v > cap) v = cap;
  return g + dir * v * v / (2 * active_.cmd.deceleration);
}

// The command becomes Active: its goal is resolved from the set values now
// (its first sample is the next cycle's).
void AxisMachine::start(const Slot& s, double base) noexcept {
  if (s.cmd.kind == CommandKind::SyncOut) return leave_sync(s);
  active_ = s;
  active_.start = set_.x;
  active_.base = base;
  const Command& c = s.cmd;
  switch (c.kind) {
    case CommandKind::MoveAbsolute:
      active_.goal = appl_.modulo > 0 ? modulo_goal(set_.x, set_.v, c.position, appl_.modulo, c.direction) : c.position;
      break;
    case CommandKind::MoveRelative:
    case CommandKind::MoveAdditive: active_.goal = base + c.position; break;
    default: active_.goal = set_.x; break;
  }
  active_.goal_known = true;
  begin_window(c);
  state_ = state_of(c.kind);
  stop_released_ = false;
  if (c.kind == CommandKind::Home) start_homing();
  if (c.kind == CommandKind::GroupMove) active_.goal = c.position;
  // The acceleration of the coming sample is the new command's: a gear or cam
  // block later in this scan predicts this axis's next set values from it
  // (mc_coupling.hpp). A fed command's sample comes with its feed.
  if (c.kind != CommandKind::GroupMove && c.kind != CommandKind::Synchronized && c.kind != CommandKind::Home)
    set_a_ = profile_step(active_, set_).p.a;
}

// The window of the command that starts: its jerk (resolved at submit; 0 for
// MC_Home, group moves and the axis's own halts) and its acceleration bound.
void AxisMachine::begin_window(const Command& c) noexcept {
  const bool jerk_limited = c.jerk > 0 && c.kind != CommandKind::Home && c.kind != CommandKind::GroupMove;
  const double U = c.kind == CommandKind::Halt || c.kind == CommandKind::Stop ? c.deceleration
                                                                                : std::fmax(c.acceleration, c.deceleration);
  const double U_old = window_.in_step_with(set_) ? window_.accel_bound() : std::fabs(last_a_);
  const std::int64_t m = jerk_limited ? JerkWindow::length_for(U, U_old, c.jerk, T_) : 1;
  window_.begin(m, U, set_, last_a_, T_);
}

void AxisMachine::feed(CommandId id, const FilterState& next, double a, std::int64_t remaining, bool done) noexcept {
  if (id == 0 || id != active_.id) return;
  const bool group = active_.cmd.kind == CommandKind::GroupMove;
  if (!group && active_.cmd.kind != CommandKind::Synchronized) return;
  // A group's done: next is the goal, at rest (the group's target, which it
  // may have moved in flight). A slave's done (a cam handing over) keeps its
  // velocity for the command after it.
  const bool at_rest = group && done;
  if (done) active_.goal = next.x;
  active_.fed = at_rest ? FilterState{next.x, 0} : next;
  active_.fed_a = at_rest ? 0 : a;
  active_.fed_remaining = remaining;
  active_.fed_done = done;
  active_.fed_now = true;
}

}  // namespace syncplc::plcopen
