// MC_Home with a reference switch (§3.2 leaves the procedure to the
// implementation; docs/motion/plcopen.md, "Homing"). In Homing:
//   leave   the switch is on at the start: move away from it (against the
//           search direction) at the homing velocity until it reads off;
//   search  move in the search direction at the homing velocity until the
//           switch's rising edge; the actual position there is the edge;
//   brake   ramp to standstill with MaxDecelerationAppl; then the edge's
//           position becomes MC_Home's Position (the axis's offset moves by
//           Position - edge, set and actual alike), homed, Done.
// Ramps use MaxAccelerationAppl and MaxDecelerationAppl. A search (leave and
// search together) longer than home_max_distance ends in ErrorStop
// HomingFailed. "Set here" is the mode without a switch.
//
// home_mode 3, the drive homes itself (CiA 402 homing mode through
// CIA402_DRIVE, docs/drives.md "Homing mode"): the axis raises its `home`
// output and, until the drive reports "homing attained", its set values
// follow the drive's actual ones (the drive moves on its own). Attained: the
// drive's position is the axis's (the offset returns to 0; the drive gave
// its home point MC_Home's Position as home offset 607Ch). A homing error is
// ErrorStop DriveHomingError, no end within home_timeout ErrorStop
// HomingTimeout; an abort (MC_Stop, MC_Power off) drops `home`, and the
// drive interrupts its homing.
#include <cmath>

#include "fblocks/plcopen/axis_machine.hpp"
#include "fblocks/plcopen/axis_profile.hpp"

namespace syncplc::plcopen {

using motion::FilterState;

void AxisMachine::start_homing() noexcept {
  if (homing_.mode == HomingConfig::Mode::SetHere) return;
  if (homing_.mode == HomingConfig::Mode::Drive) {
    active_.phase = kHomeDrive;
    active_.waited = 0;
    return;
  }
  active_.phase = fb_.home_switch ? kHomeLeave : kHomeSearch;
}

// The phase from this cycle's feedback, before the step; false when the
// search failed (the axis is then in ErrorStop).
bool AxisMachine::homing_phase() noexcept {
  if (homing_.mode == HomingConfig::Mode::SetHere || active_.phase == 0) return true;
  if (active_.phase == kHomeDrive) {
    ++active_.waited;
    const bool late = static_cast<double>(active_.waited) * T_ >= homing_.timeout_s && !fb_.homing_attained;
    if (fb_.homing_error || late) {
      // The drive stops on its own; the set values, which followed it, brake.
      enter_error(fb_.homing_error ? AxisError::DriveHomingError : AxisError::HomingTimeout);
      brake(system_.d_max);
      return false;
    }
    return true;
  }
  if (active_.phase == kHomeLeave && !fb_.home_switch) {
    active_.phase = kHomeSearch;
  } else if (active_.phase == kHomeSearch && fb_.home_switch) {
    active_.phase = kHomeBrake;
    active_.edge = fb_.position + offset_;
  }
  if (active_.phase != kHomeBrake && homing_.max_distance > 0 &&
      std::fabs(set_.x - active_.start) > homing_.max_distance) {
    enter_error(AxisError::HomingFailed);
    brake(system_.d_max);
    return false;
  }
  return true;
}

FilterState AxisMachine::home_step(const Slot& s, const FilterState& from, bool* done, double* a) const noexcept {
  if (homing_.mode == HomingConfig::Mode::SetHere || s.phase == 0) {
    *done = true;
    *a = 0;
    return from;
  }
  if (s.phase == kHomeDrive) {
    *done = fb_.homing_attained;
    *a = 0;
    return {fb_.position + offset_, fb_.velocity};
  }
  const double dir = homing_.mode == HomingConfig::Mode::SwitchPositive ? 1.0 : -1.0;
  ProfileStep p;
  switch (s.phase) {
    case kHomeLeave: p = ramp_step(from, -dir * homing_.velocity, appl_.a_max, appl_.d_max, T_); break;
    case kHomeSearch: p = ramp_step(from, dir * homing_.velocity, appl_.a_max, appl_.d_max, T_); break;
    default: p = ramp_step(from, 0, appl_.d_max, appl_.d_max, T_); break;
  }
  *done = s.phase == kHomeBrake && p.done;
  *a = p.a;
  return p.next;
}

void AxisMachine::finish_homing(const Slot& s) noexcept {
  if (s.phase == kHomeDrive) {
    // The drive's coordinates are the axis's now; it stands (bit 10).
    offset_ = 0;
    set_ = {fb_.position, 0};
    homed_ = true;
    return;
  }
  // Set here: where the axis stands; with a switch: where the edge was.
  const double reference = homing_.mode == HomingConfig::Mode::SetHere || s.phase == 0 ? set_.x : s.edge;
  const double shift = s.cmd.position - reference;
  offset_ += shift;
  set_.x += shift;
  homed_ = true;
}

}  // namespace syncplc::plcopen
