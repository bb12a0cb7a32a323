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
#include <cmath>

#include "fblocks/plcopen/axis_machine.hpp"
#include "fblocks/plcopen/axis_profile.hpp"

namespace syncplc::plcopen {

using motion::FilterState;

void AxisMachine::start_homing() noexcept {
  if (homing_.mode == HomingConfig::Mode::SetHere) return;
  active_.phase = fb_.home_switch ? kHomeLeave : kHomeSearch;
}

// The phase from this cycle's feedback, before the step; false when the
// search failed (the axis is then in ErrorStop).
bool AxisMachine::homing_phase() noexcept {
  if (homing_.mode == HomingConfig::Mode::SetHere || active_.phase == 0) return true;
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
  // Set here: where the axis stands; with a switch: where the edge was.
  const double reference = homing_.mode == HomingConfig::Mode::SetHere || s.phase == 0 ? set_.x : s.edge;
  const double shift = s.cmd.position - reference;
  offset_ += shift;
  set_.x += shift;
  homed_ = true;
}

}  // namespace syncplc::plcopen
