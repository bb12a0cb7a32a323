// Per-scan cost of a PLCopen axis with an active move (issue 24), side by
// side with TRANSIENT_SYNC on the same targets, through the block harness.
//
//   BM_AxisMove/n        n axes, each an MC_AXIS with two MC_MoveAbsolute
//                        blocks taking turns (every new target is a rising
//                        Execute edge, BufferMode Aborting), on an ideal drive
//                        (actual = set); one iteration is one scan of all of them
//   BM_AxisMoveJerk/n    BM_AxisMove with Jerk 400 on every move (jerk-limited:
//                        a window of 5-10 samples, docs/motion/jerk-profile.md)
//   BM_AxisStandstill/n  the same axes powered and standing: the floor
//   BM_SyncTargets/n     TRANSIENT_SYNC with n filters on the same targets
//                        (r_dot = 0), unified rule; rule 2 (unsynchronized)
//   BM_AsyncTargets/n    as the second column of docs/benchmarks.md section 3
//   BM_GroupMove/n       MC_GroupMoveAbsolute on n such axes (the axes' own
//                        MC_Power and MC_MoveAbsolute blocks idle beside it),
//                        the targets of all changed together, re-targeted in flight
// Targets: steps held 0.1-0.5 s (seeded), per-axis limits |v| 4-6, |a| 20-40,
// T = 20 ms as in section 3.
#include <benchmark/benchmark.h>

#include <memory>
#include <random>
#include <set>
#include <string>
#include <vector>

#include "fblocks/library.hpp"
#include "runtime/core/block_harness.hpp"

namespace {

using namespace syncplc;

constexpr std::int64_t kPeriod = 20'000'000;
constexpr int kSteps = 50'000;

struct Targets {
  std::vector<double> r;  // [k * n + i]
  std::vector<char> change;  // a new target at scan k for axis i
  std::vector<double> v, a;  // per axis
  int n = 0;
};

Targets make_targets(int n, std::uint64_t seed) {
  std::mt19937_64 g(seed);
  std::uniform_real_distribution<double> u01(0, 1);
  Targets t;
  t.n = n;
  t.r.resize(static_cast<std::size_t>(kSteps) * n);
  t.change.resize(t.r.size());
  for (int i = 0; i < n; ++i) {
    t.v.push_back(4 + 2 * u01(g));
    t.a.push_back(20 + 20 * u01(g));
    double r = 0;
    int left = 0;
    for (int k = 0; k < kSteps; ++k) {
      const std::size_t at = static_cast<std::size_t>(k) * n + i;
      if (left-- <= 0) {
        left = 5 + static_cast<int>(u01(g) * 20);
        r = -5 + 10 * u01(g);
        t.change[at] = 1;
      }
      t.r[at] = r;
    }
  }
  return t;
}

BlockHarness::Options opts(std::map<std::string, std::string> params) {
  BlockHarness::Options o;
  o.params = std::move(params);
  o.period_ns = kPeriod;
  return o;
}

// One axis: MC_AXIS, MC_Power and two MC_MoveAbsolute linked to it by hand
// (the loader's job in a project: Block::link), pins looked up once.
struct AxisRig {
  std::unique_ptr<BlockHarness> axis, power, move[2];
  Cell *actual, *set, *exec[2], *pos[2];
  int turn = 0;

  AxisRig(double v, double a, double jerk = 0) {
    BlockHarness::Options o = opts({{"v_max", "6"}, {"a_max", "40"}, {"d_max", "40"}});
    o.connected = std::set<std::string>{"actual_position"};  // an ideal drive: power on follows enable
    axis = std::make_unique<BlockHarness>(builtin_blocks(), "MC_AXIS", o);
    power = std::make_unique<BlockHarness>(builtin_blocks(), "MC_Power", opts({}));
    power->block().link(0, 0, axis->block());
    power->set<bool>("Enable", true);
    for (int m = 0; m < 2; ++m) {
      move[m] = std::make_unique<BlockHarness>(builtin_blocks(), "MC_MoveAbsolute", opts({}));
      move[m]->block().link(0, 0, axis->block());
      move[m]->set<double>("Velocity", v);
      move[m]->set<double>("Acceleration", a);
      move[m]->set<double>("Deceleration", a);
      move[m]->set<double>("Jerk", jerk);
      exec[m] = &move[m]->cell("Execute");
      pos[m] = &move[m]->cell("Position");
    }
    actual = &axis->cell("actual_position");
    set = &axis->cell("drive_position");
    for (int k = 0; k < 5; ++k) scan();  // powered: Standstill
  }
  std::int16_t state() { return axis->get<std::int16_t>("state"); }
  // A scan in the task's order: the axis (a unit delay: execute first,
  // end_of_scan samples the drive), then its blocks; the ideal drive is at
  // the set position by the end of the scan.
  void scan() {
    power->scan();
    move[0]->scan();
    move[1]->scan();
    actual->set<double>(set->get<double>());
    axis->scan();
  }
  void target(double r) {
    turn ^= 1;
    exec[turn]->set<bool>(true);
    exec[turn ^ 1]->set<bool>(false);
    pos[turn]->set<double>(r);
  }
};

void axis_bench(benchmark::State& state, bool moving, double jerk = 0) {
  const int n = static_cast<int>(state.range(0));
  Targets t = make_targets(n, 5);
  std::vector<std::unique_ptr<AxisRig>> rigs;
  for (int i = 0; i < n; ++i) {
    rigs.push_back(std::make_unique<AxisRig>(t.v[static_cast<std::size_t>(i)], t.a[static_cast<std::size_t>(i)], jerk));
    if (!rigs.back()->axis->ok()) {
      state.SkipWithError("MC_AXIS did not build");
      return;
    }
  }
  if (rigs[0]->state() != 1) {
    state.SkipWithError("the axis is not in Standstill after MC_Power");
    return;
  }
  std::size_t k = 0, moving_scans = 0, scans = 0;
  for (auto _ : state) {
    ++scans;
    moving_scans += rigs[0]->state() == 3;
    for (std::size_t i = 0; i < static_cast<std::size_t>(n); ++i) {
      if (moving && t.change[k * n + i]) rigs[i]->target(t.r[k * n + i]);
      rigs[i]->scan();
    }
    if (++k == static_cast<std::size_t>(kSteps)) k = 0;
  }
  // How much of the time the first axis was in DiscreteMotion.
  state.counters["moving"] = scans ? static_cast<double>(moving_scans) / static_cast<double>(scans) : 0.0;
}
void BM_AxisMove(benchmark::State& state) { axis_bench(state, true); }
void BM_AxisStandstill(benchmark::State& state) { axis_bench(state, false); }
void BM_AxisMoveJerk(benchmark::State& state) { axis_bench(state, true, 400); }
BENCHMARK(BM_AxisMove)->Arg(1)->Arg(6)->Arg(100);
BENCHMARK(BM_AxisMoveJerk)->Arg(1)->Arg(6)->Arg(100);
BENCHMARK(BM_AxisStandstill)->Arg(1)->Arg(100);

// n axes moved together by MC_GroupMoveAbsolute (one block, its links set
// by hand), new targets for all at every change of axis 1's sequence,
// ContinuousUpdate: the synchronizer re-targets them in flight.
void BM_GroupMove(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  Targets t = make_targets(n, 5);
  std::vector<std::unique_ptr<AxisRig>> rigs;
  BlockHarness group(builtin_blocks(), "MC_GroupMoveAbsolute", opts({{"n", std::to_string(n)}}));
  if (!group.ok()) {
    state.SkipWithError("MC_GroupMoveAbsolute did not build");
    return;
  }
  for (int i = 0; i < n; ++i) {
    rigs.push_back(std::make_unique<AxisRig>(t.v[static_cast<std::size_t>(i)], t.a[static_cast<std::size_t>(i)]));
    group.block().link(0, static_cast<std::uint32_t>(i), rigs.back()->axis->block());
  }
  Cell* pos = &group.cell("Position", 0);
  for (int i = 0; i < n; ++i) pos[i].set<double>(t.r[static_cast<std::size_t>(i)]);
  group.set<bool>("ContinuousUpdate", true);
  group.set<bool>("Execute", true);
  std::size_t k = 0, moving_scans = 0, scans = 0;
  for (auto _ : state) {
    ++scans;
    moving_scans += rigs[0]->state() == 3;
    if (t.change[k * n]) {
      // A new set of targets; a group that arrived starts again.
      for (std::size_t i = 0; i < static_cast<std::size_t>(n); ++i) pos[i].set<double>(t.r[k * n + i]);
      if (group.get<bool>("Done")) group.set<bool>("Execute", false);
    } else {
      group.set<bool>("Execute", true);
    }
    for (auto& r : rigs) r->scan();
    group.scan();
    if (++k == static_cast<std::size_t>(kSteps)) k = 0;
  }
  state.counters["moving"] = scans ? static_cast<double>(moving_scans) / static_cast<double>(scans) : 0.0;
}
BENCHMARK(BM_GroupMove)->Arg(6)->Arg(100);

void sync_bench(benchmark::State& state, int rule) {
  const int n = static_cast<int>(state.range(0));
  Targets t = make_targets(n, 5);
  BlockHarness h(builtin_blocks(), "TRANSIENT_SYNC", opts({{"n", std::to_string(n)}, {"rule", std::to_string(rule)}}));
  if (!h.ok()) {
    state.SkipWithError("TRANSIENT_SYNC did not build");
    return;
  }
  for (int i = 0; i < n; ++i) {
    const auto u = static_cast<std::uint32_t>(i);
    h.set<double>("a_min", u, -t.a[u]);
    h.set<double>("a_max", u, t.a[u]);
    h.set<double>("v_min", u, -t.v[u]);
    h.set<double>("v_max", u, t.v[u]);
    h.set<double>("r_dot", u, 0.0);
  }
  Cell* r = &h.cell("r", 0);
  std::size_t k = 0;
  for (auto _ : state) {
    for (std::size_t i = 0; i < static_cast<std::size_t>(n); ++i) r[i].set<double>(t.r[k * n + i]);
    h.scan();
    if (++k == static_cast<std::size_t>(kSteps)) k = 0;
  }
}
void BM_SyncTargets(benchmark::State& state) { sync_bench(state, 0); }
void BM_AsyncTargets(benchmark::State& state) { sync_bench(state, 2); }
BENCHMARK(BM_SyncTargets)->Arg(1)->Arg(6)->Arg(100);
BENCHMARK(BM_AsyncTargets)->Arg(1)->Arg(6)->Arg(100);

}  // namespace

BENCHMARK_MAIN();
