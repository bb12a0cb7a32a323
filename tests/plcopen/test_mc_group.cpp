// MC_GroupMoveAbsolute in a project run by the virtual clock: n axes of
// random limits on simulated drives, moved from random positions to random
// targets, arrive on the same scan (spread 0), each within its own limits,
// without overshoot, at the scan the block predicted; re-targeted in flight
// they still arrive together; another command to one axis ends the group.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <random>
#include <string>
#include <vector>

#include "fblocks/plcopen/axis_machine.hpp"
#include "runtime/core/virtual_clock.hpp"
#include "runtime/project/loader.hpp"
#include "tests/support/image_key.hpp"

namespace syncplc {
namespace {

using plcopen::AxisState;

constexpr double kT = 0.001;

struct AxisSpec {
  double x0, v_max, a_max, d_max;
};

std::string group_project(const std::vector<AxisSpec>& axes) {
  const std::size_t n = axes.size();
  std::string t = "tasks: [{name: motion, period: 1ms}]\ntags:\n";
  t += "  - {name: go, type: BOOL}\n  - {name: update, type: BOOL}\n  - {name: hold, type: BOOL}\n";
  t += "  - {name: targets, type: \"ARRAY[1.." + std::to_string(n) + "] OF LREAL\"}\nblocks:\n";
  std::string names, connections;
  for (std::size_t i = 0; i < n; ++i) {
    const std::string x = "x" + std::to_string(i + 1), d = "d" + std::to_string(i + 1);
    const AxisSpec& a = axes[i];
    t += "  - {name: " + x + ", type: MC_AXIS, params: {v_max: " + std::to_string(a.v_max) +
         ", a_max: " + std::to_string(a.a_max) + ", d_max: " + std::to_string(a.d_max) + "}}\n";
    t += "  - {name: " + d + ", type: SIM_SERVO, params: {position0: " + std::to_string(a.x0) + "}}\n";
    t += "  - {name: p" + std::to_string(i + 1) + ", type: MC_Power, params: {Axis: " + x + "}, inputs: {Enable: TRUE}}\n";
    names += (i ? ", " : "") + x;
    connections += "  - " + x + ".enable -> " + d + ".enable\n  - " + x + ".drive_position -> " + d + ".target\n  - " +
                   d + ".position -> " + x + ".actual_position\n  - " + d + ".power_on -> " + x + ".power_on\n";
  }
  t += "  - {name: grp, type: MC_GroupMoveAbsolute, params: {n: " + std::to_string(n) + ", Axes: [" + names + "]}}\n";
  t += "  - {name: halt1, type: MC_Halt, params: {Axis: x1}}\n";
  t += "connections:\n" + connections;
  t += "  - go -> grp.Execute\n  - update -> grp.ContinuousUpdate\n  - targets -> grp.Position\n  - hold -> halt1.Execute\n";
  return t;
}

class GroupRun {
 public:
  explicit GroupRun(const std::vector<AxisSpec>& axes) : n_(axes.size()) {
    auto r = load_project_text(group_project(axes), "group.yaml", LoadOptions{});
    for (const auto& d : r.diagnostics.list()) ADD_FAILURE() << d.text();
    prog_ = std::move(r.program);
    if (prog_) clock_ = std::make_unique<VirtualClock>(*prog_);
  }
  bool ok() const { return prog_ != nullptr; }
  Cell& cell(const std::string& ref) {
    auto r = prog_->resolve(ref);
    EXPECT_TRUE(r) << ref;
    return *prog_->live_cell(*r, testing::image_key());
  }
  double set_x(std::size_t i) { return cell("x" + std::to_string(i + 1) + ".set_position").get<double>(); }
  double set_v(std::size_t i) { return cell("x" + std::to_string(i + 1) + ".set_velocity").get<double>(); }
  int state(std::size_t i) { return cell("x" + std::to_string(i + 1) + ".state").get<std::int16_t>(); }
  void target(std::size_t i, double r) { cell("targets[" + std::to_string(i + 1) + "]").set<double>(r); }
  void scan() { clock_->run_until(now_ += 1'000'000); }
  std::size_t size() const { return n_; }

 private:
  std::size_t n_;
  std::unique_ptr<Program> prog_;
  std::unique_ptr<VirtualClock> clock_;
  std::int64_t now_ = 0;
};

std::vector<AxisSpec> random_axes(std::size_t n, std::mt19937_64& g) {
  std::uniform_real_distribution<double> u(0, 1);
  std::vector<AxisSpec> axes;
  for (std::size_t i = 0; i < n; ++i) axes.push_back({-5 + 10 * u(g), 2 + 8 * u(g), 20 + 80 * u(g), 20 + 80 * u(g)});
  return axes;
}

// The filter's controller applies a control beyond a bound by at most its
// deadband, 1e-7 of the bound (nonlinear_filter_math.hpp, accel_deadband):
// limits are checked to 1e-6 relative.

// What one group move did, scan by scan.
struct Arrivals {
  std::vector<int> first_at_goal;  // first scan each axis stood at its target
  int done_at = -1;                // the scan grp.Done came
  std::int64_t predicted = -1;     // RemainingScans at the first scan
  bool within_limits = true, no_overshoot = true;
  std::string why;
};

Arrivals run_group(GroupRun& run, const std::vector<AxisSpec>& axes, const std::vector<double>& targets) {
  Arrivals a;
  const std::size_t n = axes.size();
  a.first_at_goal.assign(n, -1);
  std::vector<double> v_prev(n, 0.0), start(n);
  for (std::size_t i = 0; i < n; ++i) {
    run.target(i, targets[i]);
    start[i] = run.set_x(i);
  }
  run.cell("go").set<bool>(true);
  for (int k = 1; k < 200000; ++k) {
    run.scan();
    if (k == 1) a.predicted = run.cell("grp.RemainingScans").get<std::int64_t>();
    for (std::size_t i = 0; i < n; ++i) {
      const double x = run.set_x(i), v = run.set_v(i);
      if (std::abs(v) > axes[i].v_max * (1 + 1e-6)) {
        a.within_limits = false;
        a.why = "axis " + std::to_string(i + 1) + " |v| " + std::to_string(v) + " vmax " + std::to_string(axes[i].v_max) + " at scan " + std::to_string(k);
      }
      if (std::abs(v - v_prev[i]) > std::max(axes[i].a_max, axes[i].d_max) * kT * (1 + 1e-6)) {
        a.within_limits = false;
        a.why = "axis " + std::to_string(i + 1) + " dv " + std::to_string(v - v_prev[i]) + " a " + std::to_string(axes[i].a_max) + " d " + std::to_string(axes[i].d_max) + " at scan " + std::to_string(k) + " v " + std::to_string(v) + " x " + std::to_string(x) + " target " + std::to_string(targets[i]);
      }
      v_prev[i] = v;
      const double dir = targets[i] >= start[i] ? 1 : -1;
      if (dir * (x - targets[i]) > 1e-9) a.no_overshoot = false;
      if (a.first_at_goal[i] < 0 && x == targets[i] && v == 0) a.first_at_goal[i] = k;
    }
    if (run.cell("grp.Done").get<bool>()) {
      a.done_at = k;
      break;
    }
    if (run.cell("grp.Error").get<bool>() || run.cell("grp.CommandAborted").get<bool>()) break;
  }
  return a;
}

void power_up(GroupRun& run) {
  for (int k = 0; k < 5; ++k) run.scan();
  for (std::size_t i = 0; i < run.size(); ++i) ASSERT_EQ(run.state(i), static_cast<int>(AxisState::Standstill)) << i;
}

TEST(McGroup, RandomMovesOf2To100AxesArriveOnOneScanWithinTheirLimits) {
  std::mt19937_64 g(24);
  std::uniform_real_distribution<double> u(0, 1);
  for (std::size_t n : {2u, 3u, 5u, 8u, 13u, 30u, 100u}) {
    for (int rep = 0; rep < (n >= 30 ? 2 : 6); ++rep) {
      const auto axes = random_axes(n, g);
      GroupRun run(axes);
      ASSERT_TRUE(run.ok());
      power_up(run);
      std::vector<double> targets;
      for (std::size_t i = 0; i < n; ++i) targets.push_back(-10 + 20 * u(g));
      const Arrivals a = run_group(run, axes, targets);
      ASSERT_GT(a.done_at, 0) << "n " << n << " rep " << rep;
      const auto [lo, hi] = std::minmax_element(a.first_at_goal.begin(), a.first_at_goal.end());
      EXPECT_GT(*lo, 0) << "every axis reached its target";
      EXPECT_EQ(*hi - *lo, 0) << "spread in arrival, n " << n << " rep " << rep;
      EXPECT_EQ(a.done_at, *hi) << "Done in the scan the axes stand at their targets";
      EXPECT_EQ(a.predicted + 1, *hi) << "RemainingScans at the first scan: the scans until the axes stand, n " << n;
      EXPECT_TRUE(a.within_limits) << "n " << n << " rep " << rep << ": " << a.why;
      EXPECT_TRUE(a.no_overshoot) << "n " << n << " rep " << rep;
      for (std::size_t i = 0; i < n; ++i) EXPECT_EQ(run.set_x(i), targets[i]);
    }
  }
}

TEST(McGroup, ReTargetedInFlightTheAxesStillArriveTogether) {
  std::mt19937_64 g(7);
  const auto axes = random_axes(4, g);
  GroupRun run(axes);
  ASSERT_TRUE(run.ok());
  power_up(run);
  run.cell("update").set<bool>(true);
  const std::vector<double> first = {8, -6, 3, 9};
  for (std::size_t i = 0; i < 4; ++i) run.target(i, first[i]);
  run.cell("go").set<bool>(true);
  run.scan();
  const std::int64_t predicted = run.cell("grp.RemainingScans").get<std::int64_t>();
  ASSERT_GT(predicted, 50);
  for (std::int64_t k = 0; k < predicted / 3; ++k) run.scan();
  // Two axes get new targets, one of them reverses.
  const std::vector<double> second = {8, 4, -7, 9};
  for (std::size_t i = 0; i < 4; ++i) run.target(i, second[i]);
  std::vector<int> at(4, -1);
  int k = 0;
  for (; k < 100000 && !run.cell("grp.Done").get<bool>(); ++k) {
    run.scan();
    for (std::size_t i = 0; i < 4; ++i)
      if (at[i] < 0 && run.set_x(i) == second[i] && run.set_v(i) == 0) at[i] = k;
  }
  ASSERT_TRUE(run.cell("grp.Done").get<bool>());
  EXPECT_EQ(*std::max_element(at.begin(), at.end()) - *std::min_element(at.begin(), at.end()), 0) << "spread";
  for (std::size_t i = 0; i < 4; ++i) EXPECT_EQ(run.set_x(i), second[i]);
}

TEST(McGroup, AnotherCommandToOneAxisEndsTheGroupAndTheOthersStop) {
  std::mt19937_64 g(9);
  const auto axes = random_axes(3, g);
  GroupRun run(axes);
  ASSERT_TRUE(run.ok());
  power_up(run);
  for (std::size_t i = 0; i < 3; ++i) run.target(i, 9.5 - static_cast<double>(i));
  run.cell("go").set<bool>(true);
  for (int k = 0; k < 100; ++k) run.scan();
  ASSERT_TRUE(run.cell("grp.Active").get<bool>());
  run.cell("hold").set<bool>(true);  // MC_Halt on axis 1
  for (int k = 0; k < 3; ++k) run.scan();
  EXPECT_TRUE(run.cell("grp.CommandAborted").get<bool>());
  EXPECT_FALSE(run.cell("grp.Busy").get<bool>());
  for (int k = 0; k < 5000; ++k) run.scan();
  for (std::size_t i = 0; i < 3; ++i) {
    EXPECT_EQ(run.set_v(i), 0.0) << "axis " << i + 1 << " braked to standstill";
    EXPECT_EQ(run.state(i), static_cast<int>(AxisState::Standstill)) << i + 1;
  }
}

TEST(McGroup, TheAxesListMustMatchNAndNameEachAxisOnce) {
  const std::string base = R"(tasks: [{name: t, period: 1ms}]
blocks:
  - {name: x, type: MC_AXIS, inputs: {actual_position: 0}}
  - {name: y, type: MC_AXIS, inputs: {actual_position: 0}}
)";
  auto errors = [&](const std::string& group) {
    auto r = load_project_text(base + group, "p.yaml", LoadOptions{});
    std::string s;
    for (const auto& d : r.diagnostics.sorted()) s += d.text() + "\n";
    return s;
  };
  EXPECT_THAT(errors("  - {name: g, type: MC_GroupMoveAbsolute, params: {n: 3, Axes: [x, y]}}\n"),
              ::testing::HasSubstr("g.Axes: 2 instances for n = 3"));
  EXPECT_THAT(errors("  - {name: g, type: MC_GroupMoveAbsolute, params: {n: 2, Axes: [x, x]}}\n"),
              ::testing::HasSubstr("g.Axes: x is named twice"));
  EXPECT_THAT(errors("  - {name: g, type: MC_GroupMoveAbsolute, params: {n: 1, Axes: x}}\n"),
              ::testing::HasSubstr("MC_GroupMoveAbsolute.Axes: expected a list of names of instances of MC_AXIS"));
}

}  // namespace
}  // namespace syncplc
