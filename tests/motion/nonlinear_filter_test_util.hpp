// Shared helpers for the NONLINEAR_FILTER tests: a seeded random source,
// random bounds/states/references, and a simulation in the original
// coordinates exactly as the block runs it.
#pragma once

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdint>
#include <random>
#include <string>

#include "fblocks/motion/nonlinear_filter_math.hpp"

namespace syncplc::motion::test {

struct Rng {
  std::mt19937_64 g;
  explicit Rng(std::uint64_t seed) : g(seed) {}
  double uni(double a, double b) { return std::uniform_real_distribution<double>(a, b)(g); }
  bool chance(double p) { return uni(0, 1) < p; }
  // Log-uniform in [a, b], a > 0.
  double logu(double a, double b) { return std::exp(uni(std::log(a), std::log(b))); }
  int integer(int a, int b) { return std::uniform_int_distribution<int>(a, b)(g); }
};

// Random asymmetric bounds: accelerations 0.5..20 m/s^2 each way, velocity
// bounds 0.05..2 m/s each way around 0, or (20 %) both on the same side of 0.
// An acceleration too small to cross the velocity range in about 300 scans of
// period T is raised (to keep the transients, and the test time, bounded).
inline FilterBounds random_bounds(Rng& rng, double T) {
  FilterBounds b;
  b.v_max = rng.logu(0.05, 2);
  b.v_min = -rng.logu(0.05, 2);
  if (rng.chance(0.2)) {
    const double shift = rng.chance(0.5) ? b.v_max - rng.uni(0, 0.02) : b.v_min + rng.uni(0, 0.02);
    b.v_max -= shift;
    b.v_min -= shift;
  }
  const double a_floor = (b.v_max - b.v_min) / (300 * T);
  b.a_max = std::fmax(rng.logu(0.5, 20), a_floor * rng.uni(1, 3));
  b.a_min = -std::fmax(rng.logu(0.5, 20), a_floor * rng.uni(1, 3));
  return b;
}

// Sampling period 0.5..10 ms.
inline double random_period(Rng& rng) { return rng.logu(5e-4, 1e-2); }

// Room for the relative velocity towards the reference: behind (dir > 0) the
// filter may gain v_max - rdot on it, ahead (dir < 0) rdot - v_min.
inline double closing_speed(const FilterBounds& b, double r_dot, int dir) {
  return dir > 0 ? b.v_max - r_dot : r_dot - b.v_min;
}

// A reference slope strictly inside the velocity bounds (0 when allowed, 30 %).
inline double random_slope(Rng& rng, const FilterBounds& b) {
  if (b.v_min < 0 && b.v_max > 0 && rng.chance(0.3)) return 0;
  return rng.uni(b.v_min, b.v_max);
}

inline double max_abs_accel(const FilterBounds& b) { return std::fmax(b.a_max, -b.a_min); }

// Tolerances of the bound checks. The controller applies a control beyond an
// acceleration bound by at most the deadband 1e-7 max(U+, -U-) (by design,
// nonlinear_filter_math.hpp); velocities are exact up to rounding of the
// velocities themselves.
inline double accel_tolerance(const FilterBounds& b) { return 1e-7 * max_abs_accel(b) * (1 + 1e-9); }
inline double velocity_tolerance(const FilterBounds& b, double r_dot) {
  return 1e-12 * (1 + std::fabs(b.v_min) + std::fabs(b.v_max) + std::fabs(r_dot));
}

inline bool tracking(const FilterState& s, const Reference& ref, const FilterBounds& b, double T) {
  return is_tracking(to_z(s, ref, T), z_bounds(b, ref.v, T));
}

// Region names: index = 2 * region + mirrored.
inline constexpr int kRegionSlots = 2 * (static_cast<int>(TransientRegion::Never) + 1);
inline std::string region_name(int slot) {
  static const char* names[] = {"Tracking", "A", "B", "C", "D", "E", "F", "G", "Never"};
  return std::string(names[slot / 2]) + (slot % 2 ? "'" : "");
}
inline int region_slot(const TransientInfo& i) { return 2 * static_cast<int>(i.region) + (i.mirrored ? 1 : 0); }

}  // namespace syncplc::motion::test
