// MC_Home with a reference switch on a simulated drive (home_mode 1, 2):
// the search, the edge's position becoming MC_Home's Position, a switch
// already on at the start, and a search that finds nothing.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <string>

#include "fblocks/plcopen/axis_machine.hpp"
#include "runtime/core/virtual_clock.hpp"
#include "runtime/project/loader.hpp"
#include "tests/support/image_key.hpp"

namespace syncplc {
namespace {

using plcopen::AxisError;
using plcopen::AxisState;

class HomingRun {
 public:
  HomingRun(const std::string& mode, const std::string& max_distance, const std::string& start) {
    const std::string text = R"(
tasks: [{name: motion, period: 1ms}]
tags:
  - {name: power, type: BOOL}
  - {name: home, type: BOOL}
blocks:
  - name: x
    type: MC_AXIS
    params: {v_max: 10, a_max: 100, d_max: 100, home_mode: )" + mode + R"(, home_velocity: 2, home_max_distance: )" +
                             max_distance + R"(}
  - {name: drv, type: SIM_SERVO, params: {home_at: 3.25, position0: )" + start + R"(}}
  - {name: pwr, type: MC_Power, params: {Axis: x}}
  - {name: hm, type: MC_Home, params: {Axis: x}, inputs: {Position: 100}}
connections:
  - x.enable -> drv.enable
  - x.drive_position -> drv.target
  - drv.position -> x.actual_position
  - drv.power_on -> x.power_on
  - drv.home_switch -> x.home_switch
  - power -> pwr.Enable
  - home -> hm.Execute
)";
    auto r = load_project_text(text, "homing.yaml", LoadOptions{});
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
  int state() { return cell("x.state").get<std::int16_t>(); }
  void scan() { clock_->run_until(now_ += 1'000'000); }

 private:
  std::unique_ptr<Program> prog_;
  std::unique_ptr<VirtualClock> clock_;
  std::int64_t now_ = 0;
};

// Powers the axis, starts MC_Home, and runs until it ends; the drive's
// position at the scan the switch came on (what the axis sees one scan later).
struct Homed {
  bool done = false, error = false;
  std::uint16_t error_id = 0;
  double edge_drive = NAN;
  int scans = 0;
  bool homing_seen = false;
};

Homed run_homing(HomingRun& run) {
  Homed h;
  run.cell("power").set<bool>(true);
  for (int i = 0; i < 5; ++i) run.scan();
  EXPECT_EQ(run.state(), static_cast<int>(AxisState::Standstill));
  run.cell("home").set<bool>(true);
  bool was_on = run.flag("drv.home_switch");
  for (h.scans = 0; h.scans < 20000; ++h.scans) {
    run.scan();
    h.homing_seen |= run.state() == static_cast<int>(AxisState::Homing);
    const bool on = run.flag("drv.home_switch");
    if (on && !was_on) h.edge_drive = run.real("drv.position");
    was_on = on;
    if (run.flag("hm.Done") || run.flag("hm.Error")) break;
  }
  h.done = run.flag("hm.Done");
  h.error = run.flag("hm.Error");
  h.error_id = run.cell("hm.ErrorID").get<std::uint16_t>();
  return h;
}

TEST(McHoming, TheSwitchEdgeBecomesThePosition) {
  HomingRun run("1", "0", "0");
  ASSERT_TRUE(run.ok());
  const Homed h = run_homing(run);
  ASSERT_TRUE(h.done);
  EXPECT_TRUE(h.homing_seen);
  ASSERT_FALSE(std::isnan(h.edge_drive));
  EXPECT_GE(h.edge_drive, 3.25);
  EXPECT_LT(h.edge_drive, 3.25 + 2 * 0.001 + 1e-12) << "the first position at or past the switch, at 2 u/s";
  run.scan();
  EXPECT_TRUE(run.flag("x.homed"));
  EXPECT_EQ(run.state(), static_cast<int>(AxisState::Standstill));
  EXPECT_EQ(run.real("x.set_velocity"), 0.0);
  // The axis stopped past the edge; where the edge was reads 100 now.
  EXPECT_NEAR(run.real("x.position") - (run.real("drv.position") - h.edge_drive), 100.0, 1e-9);
  EXPECT_GT(run.real("x.position"), 100.0) << "it braked past the edge, in +";
}

TEST(McHoming, ASwitchOnAtTheStartIsLeftFirst) {
  HomingRun run("1", "0", "5");
  ASSERT_TRUE(run.ok());
  const Homed h = run_homing(run);
  ASSERT_TRUE(h.done);
  ASSERT_FALSE(std::isnan(h.edge_drive)) << "it moved below the switch and came back to its edge";
  EXPECT_GE(h.edge_drive, 3.25);
  EXPECT_LT(h.edge_drive, 3.25 + 2 * 0.001 + 1e-12);
  run.scan();
  EXPECT_NEAR(run.real("x.position") - (run.real("drv.position") - h.edge_drive), 100.0, 1e-9);
}

TEST(McHoming, ASearchThatFindsNoSwitchIsHomingFailed) {
  // Moving in - from 0, the switch (on at >= 3.25) is never met.
  HomingRun run("2", "1.5", "0");
  ASSERT_TRUE(run.ok());
  const Homed h = run_homing(run);
  EXPECT_TRUE(h.error);
  EXPECT_EQ(h.error_id, static_cast<std::uint16_t>(AxisError::HomingFailed));
  EXPECT_EQ(run.state(), static_cast<int>(AxisState::ErrorStop));
  EXPECT_EQ(run.cell("x.error_id").get<std::uint16_t>(), static_cast<std::uint16_t>(AxisError::HomingFailed));
  EXPECT_FALSE(run.flag("x.homed"));
  EXPECT_LT(run.real("x.set_position"), -1.5) << "it went home_max_distance before giving up";
}

}  // namespace
}  // namespace syncplc
