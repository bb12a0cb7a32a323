// The per-scan set-value generators of the PLCopen axis (axis_machine.cpp):
// one sample of a discrete move (paper 004's nonlinear filter), of a velocity
// ramp (MC_MoveVelocity, MC_Halt, MC_Stop, ErrorStop's braking), the distance
// a ramp to standstill still covers, and the goal of a modulo move. Pure
// functions, noexcept, no allocation.
#pragma once

#include <cstdint>

#include "fblocks/motion/nonlinear_filter_math.hpp"
#include "fblocks/plcopen/axis_machine.hpp"

namespace syncplc::plcopen {

// The commands whose profile is a discrete move to a goal (discrete_step).
inline bool is_move(CommandKind k) noexcept {
  return k == CommandKind::MoveAbsolute || k == CommandKind::MoveRelative || k == CommandKind::MoveAdditive;
}

// One sample of a profile: the state at the next sample, the acceleration
// applied over it, and whether the profile reached its end there (discrete:
// the goal, snapped; ramp: the target velocity, snapped).
struct ProfileStep {
  motion::FilterState next;
  double a = 0;
  bool done = false;
};

// The filter's bounds for a discrete move with speed limit V and the
// acceleration acc / deceleration dec, chosen by the direction of motion: the
// set velocity's sign, or at rest the side the goal lies on (so that the
// first sample already brakes with dec and the transient time predicted from
// rest is the one the move takes).
motion::FilterBounds discrete_bounds(const motion::FilterState& s, double goal, double V, double acc,
                                     double dec) noexcept;

// One sample of the discrete move towards `goal` (reference {goal, 0}); done
// (x = goal, v = 0 exactly) once the filter tracks it.
ProfileStep discrete_step(const motion::FilterState& s, double goal, double V, double acc, double dec,
                          double T) noexcept;

// Samples until discrete_step reports done (paper 004 Table I with the bounds
// of the current direction); 0 when it already tracks.
std::int64_t discrete_remaining(const motion::FilterState& s, double goal, double V, double acc, double dec,
                                double T) noexcept;

// One sample of the velocity ramp to v_cmd: acc while |v| grows in the same
// direction, dec while it shrinks (a sample that crosses zero brakes with dec
// over the whole sample). x' = x + T (v + v')/2. done when v' == v_cmd (snapped
// once within one sample's change).
ProfileStep ramp_step(const motion::FilterState& s, double v_cmd, double acc, double dec, double T) noexcept;

// Samples ramp_step(s, 0, dec, dec, T) needs to reach v = 0.
std::int64_t ramp_remaining(double v, double dec, double T) noexcept;

// Signed distance the ramp to standstill with deceleration d covers from
// velocity v (the sum of its trapezoids), rounded away from zero by a
// relative 1e-12 so that a guard built on it is on the safe side.
double braking_distance(double v, double d, double T) noexcept;

// p wrapped into [0, m) (m > 0).
double wrap_modulo(double p, double m) noexcept;

// MC_MoveAbsolute's goal on a modulo axis: the continuous position congruent
// to `target` (in [0, m)) reached from x in `dir`; Current takes the sign of
// the set velocity v (Shortest at rest); Shortest's ties go positive.
double modulo_goal(double x, double v, double target, double m, Direction dir) noexcept;

}  // namespace syncplc::plcopen
