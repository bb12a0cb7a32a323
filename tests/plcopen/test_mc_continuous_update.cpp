// MC_MoveAbsolute's ContinuousUpdate input in a project run by the virtual
// clock: with it TRUE at the edge, a new Position while Busy re-targets the
// (jerk-limited) move in flight; with it FALSE the change is ignored.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <memory>
#include <string>

#include "fblocks/plcopen/axis_machine.hpp"
#include "runtime/core/virtual_clock.hpp"
#include "runtime/project/loader.hpp"
#include "tests/support/image_key.hpp"

namespace syncplc {
namespace mc_continuous_update_test {

const char* kProject = R"(
tasks: [{name: motion, period: 1ms}]
tags:
  - {name: power, type: BOOL}
  - {name: go, type: BOOL}
  - {name: follow, type: BOOL}
  - {name: target, type: LREAL}
blocks:
  - {name: mv, type: MC_MoveAbsolute, params: {Axis: x}, inputs: {Velocity: 50, Acceleration: 500, Deceleration: 500, Jerk: 20000}}
  - {name: pwr, type: MC_Power, params: {Axis: x}}
  - {name: drv, type: SIM_SERVO}
  - {name: x, type: MC_AXIS, params: {v_max: 100, a_max: 1000, d_max: 1000, j_max: 100000}}
connections:
  - x.enable -> drv.enable
  - x.drive_position -> drv.target
  - drv.position -> x.actual_position
  - drv.power_on -> x.power_on
  - power -> pwr.Enable
  - go -> mv.Execute
  - follow -> mv.ContinuousUpdate
  - target -> mv.Position
)";

class CuRun {
 public:
  CuRun() {
    auto r = load_project_text(kProject, "cu.yaml", LoadOptions{});
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
  double real(const std::string& ref) { return cell(ref).get<double>(); }
  bool flag(const std::string& ref) { return cell(ref).get<bool>(); }
  void scan() {
    now_ += 1'000'000;
    clock_->run_until(now_);
  }
  // Scans until mv is Done (at most `limit`); the scans it took, -1 if never.
  int until_done(int limit) {
    for (int i = 1; i <= limit; ++i) {
      scan();
      if (flag("mv.Done")) return i;
    }
    return -1;
  }

 private:
  std::unique_ptr<Program> prog_;
  std::unique_ptr<VirtualClock> clock_;
  std::int64_t now_ = 0;
};

void start_move(CuRun& run, bool follow) {
  run.cell("power").set<bool>(true);
  for (int i = 0; i < 10; ++i) run.scan();
  ASSERT_EQ(run.cell("x.state").get<std::int16_t>(), static_cast<std::int16_t>(plcopen::AxisState::Standstill));
  run.cell("target").set<double>(10);
  run.cell("follow").set<bool>(follow);
  run.cell("go").set<bool>(true);
  for (int i = 0; i < 60; ++i) run.scan();
  ASSERT_TRUE(run.flag("mv.Busy"));
  run.cell("target").set<double>(4);
}

TEST(McContinuousUpdate, ANewPositionWhileBusyReTargetsTheMove) {
  CuRun run;
  ASSERT_TRUE(run.ok());
  start_move(run, true);
  ASSERT_GT(run.until_done(5000), 0);
  EXPECT_EQ(run.real("x.set_position"), 4);
  EXPECT_EQ(run.real("x.set_velocity"), 0);
  // After Done a change does nothing.
  run.cell("target").set<double>(7);
  for (int i = 0; i < 50; ++i) run.scan();
  EXPECT_EQ(run.real("x.set_position"), 4);
}

TEST(McContinuousUpdate, WithoutItTheInputsAreSampledAtTheEdgeOnly) {
  CuRun run;
  ASSERT_TRUE(run.ok());
  start_move(run, false);
  ASSERT_GT(run.until_done(5000), 0);
  EXPECT_EQ(run.real("x.set_position"), 10);
}

}  // namespace mc_continuous_update_test
}  // namespace syncplc
