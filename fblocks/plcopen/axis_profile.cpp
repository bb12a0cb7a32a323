#include "fblocks/plcopen/axis_profile.hpp"

#include <cmath>

namespace syncplc::plcopen {

using motion::FilterBounds;
using motion::FilterState;
using motion::Reference;

FilterBounds discrete_bounds(const FilterState& s, double goal, double V, double acc, double dec) noexcept {
  const bool negative = s.v < 0 || (s.v == 0 && goal < s.x);
  // Moving (or about to move) in +: accelerating is U+, braking U-; mirrored in -.
  return negative ? FilterBounds{-V, V, -acc, dec} : FilterBounds{-V, V, -dec, acc};
}

ProfileStep discrete_step(const FilterState& s, double goal, double V, double acc, double dec, double T) noexcept {
  const Reference ref{goal, 0};
  const FilterBounds b = discrete_bounds(s, goal, V, acc, dec);
  const motion::ZBounds zb = motion::z_bounds(b, 0, T);
  if (motion::is_tracking(motion::to_z(s, ref, T), zb)) return {{goal, 0}, 0, true};
  const motion::FilterStep step = motion::filter_step(s, ref, b, T);
  if (motion::is_tracking(motion::to_z(step.next, ref, T), zb)) return {{goal, 0}, step.u, true};
  return {step.next, step.u, false};
}

std::int64_t discrete_remaining(const FilterState& s, double goal, double V, double acc, double dec,
                                double T) noexcept {
  const Reference ref{goal, 0};
  const FilterBounds b = discrete_bounds(s, goal, V, acc, dec);
  return motion::transient_steps(motion::to_z(s, ref, T), motion::z_bounds(b, 0, T));
}

ProfileStep ramp_step(const FilterState& s, double v_cmd, double acc, double dec, double T) noexcept {
  const double v = s.v;
  const bool grows = (v >= 0 && v_cmd > v) || (v <= 0 && v_cmd < v);
  const double max_dv = (grows ? acc : dec) * T;
  const double dv = v_cmd - v;
  double v_next;
  bool done = false;
  if (std::fabs(dv) <= max_dv) {
    v_next = v_cmd;
    done = true;
  } else {
    v_next = v + std::copysign(max_dv, dv);
  }
  return {{s.x + T * 0.5 * (v + v_next), v_next}, (v_next - v) / T, done};
}

std::int64_t ramp_remaining(double v, double dec, double T) noexcept {
  if (v == 0) return 0;
  const double n = std::ceil(std::fabs(v) / (dec * T));
  return n < 1 ? 1 : static_cast<std::int64_t>(n);
}

double braking_distance(double v, double d, double T) noexcept {
  const double s = std::fabs(v);
  if (s == 0) return 0;
  const double dT = d * T;
  const double n = std::ceil(s / dT) - 1;  // samples of full deceleration before the last one
  const double r = s - n * dT;             // the velocity the last sample removes
  const double dist = (T * (n * s - 0.5 * n * n * dT) + 0.5 * T * r) * (1 + 1e-12);
  return std::copysign(dist, v);
}

double wrap_modulo(double p, double m) noexcept {
  double r = std::fmod(p, m);
  if (r < 0) r += m;
  if (r >= m) r = 0;  // -tiny + m rounded up to m
  return r;
}

double modulo_goal(double x, double v, double target, double m, Direction dir) noexcept {
  const double base = x - wrap_modulo(x, m);  // the period x is in
  const double ahead = target >= wrap_modulo(x, m) ? base + target : base + m + target;   // first >= x
  const double behind = target <= wrap_modulo(x, m) ? base + target : base - m + target;  // first <= x
  if (dir == Direction::Current) dir = v > 0 ? Direction::Positive : (v < 0 ? Direction::Negative : Direction::Shortest);
  switch (dir) {
    case Direction::Positive: return ahead;
    case Direction::Negative: return behind;
    default: return (ahead - x) <= (x - behind) ? ahead : behind;
  }
}

}  // namespace syncplc::plcopen
