// Online change of a project with an axis: the blocks linked to a kept axis
// reach the kept one after the switch (the instance the new program made is
// swapped out), a move goes on through the switch, and a block whose axis is
// re-created reports its command aborted.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>

#include "fblocks/plcopen/axis_machine.hpp"
#include "runtime/core/program_change.hpp"
#include "runtime/core/virtual_clock.hpp"
#include "runtime/project/loader.hpp"
#include "tests/support/image_key.hpp"

namespace syncplc {
namespace {

constexpr std::int64_t kChangeMs = 1'000'000;

std::string axis_project(const std::string& v_max, const std::string& extra, const std::string& scale = "1") {
  return R"(
tasks: [{name: motion, period: 1ms}]
tags:
  - {name: power, type: BOOL}
  - {name: go, type: BOOL}
blocks:
  - {name: x, type: MC_AXIS, params: {v_max: )" + v_max + R"(, a_max: 100, d_max: 100, scale: )" + scale + R"(}}
  - {name: drv, type: SIM_SERVO}
  - {name: pwr, type: MC_Power, params: {Axis: x}}
  - {name: mv, type: MC_MoveAbsolute, params: {Axis: x}, inputs: {Position: 50, Velocity: 10}}
)" + extra + R"(
connections:
  - x.enable -> drv.enable
  - x.drive_position -> drv.target
  - drv.position -> x.actual_position
  - drv.power_on -> x.power_on
  - power -> pwr.Enable
  - go -> mv.Execute
)";
}

std::unique_ptr<Program> load(const std::string& text) {
  auto r = load_project_text(text, "axis.yaml", LoadOptions{});
  for (const auto& d : r.diagnostics.list()) ADD_FAILURE() << d.text();
  return std::move(r.program);
}

Cell& change_cell(Program& p, const std::string& ref) {
  auto r = p.resolve(ref);
  EXPECT_TRUE(r) << ref;
  return *p.live_cell(*r, testing::image_key());
}

struct Switched {
  std::unique_ptr<Program> a, b;
  std::unique_ptr<ProgramChange> change;
  std::unique_ptr<VirtualClock> clock;
  std::int64_t now = 0;
  void scan() { clock->run_until(now += kChangeMs); }
};

// A runs a move for 200 scans, then switches to B (T = 210 ms).
Switched start_and_switch(const std::string& a, const std::string& b) {
  Switched s;
  s.a = load(a);
  if (!s.a) return s;
  s.clock = std::make_unique<VirtualClock>(*s.a);
  change_cell(*s.a, "power").set<bool>(true);
  for (int i = 0; i < 5; ++i) s.scan();
  change_cell(*s.a, "go").set<bool>(true);
  for (int i = 0; i < 200; ++i) s.scan();
  s.b = load(b);
  if (!s.b) return s;
  s.change = plan_change(*s.a, *s.b);
  s.change->switch_ns = s.now + 10 * kChangeMs;
  s.clock->begin_change(*s.change);
  for (int i = 0; i < 12; ++i) s.scan();
  EXPECT_TRUE(s.clock->change_complete());
  return s;
}

TEST(McOnlineChange, ABlockAddedBesideAKeptAxisReadsTheKeptAxis) {
  const std::string reader = "  - {name: st, type: MC_ReadStatus, params: {Axis: x}, inputs: {Enable: TRUE}}\n";
  Switched s = start_and_switch(axis_project("10", ""), axis_project("10", reader));
  ASSERT_TRUE(s.b);
  Program& p = s.clock->program();
  ASSERT_EQ(&p, s.b.get());
  // The axis was kept mid-move: the new reader sees it moving, not the
  // Disabled axis the new program had made.
  EXPECT_TRUE(change_cell(p, "st.DiscreteMotion").get<bool>());
  EXPECT_FALSE(change_cell(p, "st.Disabled").get<bool>());
  EXPECT_TRUE(change_cell(p, "mv.Busy").get<bool>()) << "the kept move block goes on with its command";
  // The move goes on to its goal.
  int scans = 0;
  while (!change_cell(p, "mv.Done").get<bool>() && scans < 20000) {
    s.scan();
    ++scans;
  }
  EXPECT_TRUE(change_cell(p, "mv.Done").get<bool>());
  EXPECT_EQ(change_cell(p, "x.set_position").get<double>(), 50.0);
}

TEST(McOnlineChange, ALowerVelocityLimitActsOnTheRunningMove) {
  // The limits are tunable: the axis is kept, mid-move, and its move goes on
  // within the new limit.
  Switched s = start_and_switch(axis_project("10", ""), axis_project("5", ""));
  ASSERT_TRUE(s.b);
  bool retuned = false;
  for (const auto& c : s.change->instances) retuned |= c.name == "x" && c.fate == InstanceFate::Retuned;
  EXPECT_TRUE(retuned) << "x is retuned, not re-created";
  Program& p = s.clock->program();
  EXPECT_TRUE(change_cell(p, "mv.Busy").get<bool>());
  EXPECT_NE(change_cell(p, "x.state").get<std::int16_t>(), static_cast<std::int16_t>(plcopen::AxisState::Disabled));
  double fastest_late = 0;
  int scans = 0;
  while (!change_cell(p, "mv.Done").get<bool>() && scans < 20000) {
    s.scan();
    if (++scans > 60) fastest_late = std::max(fastest_late, std::abs(change_cell(p, "x.set_velocity").get<double>()));
  }
  EXPECT_TRUE(change_cell(p, "mv.Done").get<bool>());
  EXPECT_EQ(change_cell(p, "x.set_position").get<double>(), 50.0);
  EXPECT_LE(fastest_late, 5.0) << "the running move keeps the new limit once braked to it (5 rad/s at 100 rad/s^2: 50 scans)";
  EXPECT_GT(fastest_late, 4.9) << "...and cruises at it";
}

TEST(McOnlineChange, AMoveBlockWhoseAxisIsRecreatedReportsItsCommandAborted) {
  // scale is a structural parameter of MC_AXIS: the axis is re-created.
  Switched s = start_and_switch(axis_project("10", ""), axis_project("10", "", "2"));
  ASSERT_TRUE(s.b);
  Program& p = s.clock->program();
  EXPECT_TRUE(change_cell(p, "mv.CommandAborted").get<bool>());
  EXPECT_FALSE(change_cell(p, "mv.Busy").get<bool>());
  // The new axis starts Disabled and MC_Power, kept and still enabled,
  // powers it again; it stands where the drive is.
  for (int i = 0; i < 5; ++i) s.scan();
  EXPECT_EQ(change_cell(p, "x.state").get<std::int16_t>(), static_cast<std::int16_t>(plcopen::AxisState::Standstill));
  EXPECT_EQ(change_cell(p, "x.set_velocity").get<double>(), 0.0);
}

}  // namespace
}  // namespace syncplc
