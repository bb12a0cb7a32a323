// Issue 15's workload for TRANSIENT_SYNC, shared by its benchmark
// (bench/sync_workload.cpp) and its regression test
// (tests/motion/test_transient_sync_workload.cpp): n axes at rest at 0,
// seeded asymmetric limits per axis (v_max ~ U[1, 3], v_min = -v_max U[0.5, 1],
// a_max ~ U[5, 20], a_min = -a_max U[0.5, 1]), and every kMoveEvery scans of
// 1 ms a new step target ~ U[-0.5, 0.5] for every axis, zero target velocity.
#pragma once

#include <cstdint>
#include <random>
#include <vector>

namespace syncplc::bench {

inline constexpr std::int64_t kWorkloadPeriodNs = 1'000'000;  // 1 ms
inline constexpr int kMoveEvery = 500;                        // scans between new targets

struct AxisLimits {
  double v_min, v_max, a_min, a_max;
};

struct SyncWorkload {
  int n = 0;
  int moves = 0;
  std::vector<AxisLimits> limits;
  std::vector<double> targets;  // move-major: [m * n + i]

  // The targets of the move that starts at `scan`, or nullptr between moves.
  const double* targets_at(int scan) const {
    if (scan % kMoveEvery != 0 || scan / kMoveEvery >= moves) return nullptr;
    return &targets[static_cast<std::size_t>(scan / kMoveEvery) * static_cast<std::size_t>(n)];
  }
};

// The workload of n axes over `scans` scans; the same seed gives the same
// workload (std::mt19937_64 and the arithmetic below are exactly specified).
inline SyncWorkload make_sync_workload(int n, int scans, std::uint64_t seed) {
  std::mt19937_64 g(seed);
  // U[0, 1) from the top 53 bits: std::uniform_real_distribution's algorithm
  // is not fixed by the standard, this is.
  auto u01 = [&g] { return static_cast<double>(g() >> 11) * 0x1.0p-53; };
  SyncWorkload w;
  w.n = n;
  for (int i = 0; i < n; ++i) {
    const double v_max = 1 + 2 * u01();
    const double v_min = -v_max * (0.5 + 0.5 * u01());
    const double a_max = 5 + 15 * u01();
    const double a_min = -a_max * (0.5 + 0.5 * u01());
    w.limits.push_back({v_min, v_max, a_min, a_max});
  }
  w.moves = (scans + kMoveEvery - 1) / kMoveEvery;
  w.targets.resize(static_cast<std::size_t>(w.moves) * static_cast<std::size_t>(n));
  for (double& t : w.targets) t = -0.5 + u01();
  return w;
}

}  // namespace syncplc::bench
