// The HMI's door to an axis (MC_AXIS's hmi_enable and hmi_reset pins), as
// POST /api/v1/axes/{name}/enable|disable|reset use it: a write through the
// task's write queue, acted on in the next scan, run by the virtual clock.
#include <gtest/gtest.h>

#include <cstdint>
#include <memory>
#include <string>

#include "fblocks/plcopen/axis_block.hpp"
#include "fblocks/plcopen/axis_machine.hpp"
#include "runtime/core/virtual_clock.hpp"
#include "runtime/project/loader.hpp"
#include "tests/support/image_key.hpp"

namespace syncplc {
namespace mc_hmi_test {

using plcopen::AxisState;

constexpr std::int64_t kMs = 1'000'000;

const char* kProject = R"(
tasks: [{name: motion, period: 1ms}]
tags:
  - {name: power, type: BOOL}
  - {name: go, type: BOOL}
  - {name: fault, type: BOOL}
blocks:
  - {name: x, type: MC_AXIS, params: {v_max: 100, a_max: 1000, d_max: 1000}}
  - {name: drv, type: SIM_SERVO}
  - {name: pwr, type: MC_Power, params: {Axis: x}}
  - {name: mv, type: MC_MoveAbsolute, params: {Axis: x}, inputs: {Position: 50, Velocity: 10}}
connections:
  - x.enable -> drv.enable
  - x.reset -> drv.reset
  - x.drive_position -> drv.target
  - drv.position -> x.actual_position
  - drv.power_on -> x.power_on
  - drv.fault -> x.fault
  - drv.fault_code -> x.fault_code
  - power -> pwr.Enable
  - go -> mv.Execute
  - fault -> drv.inject_fault
)";

// An axis without a power_on input: the ideal drive of MC_AXIS, on one scan
// after the enable output asked for it.
const char* kIdealDriveProject = R"(
tasks: [{name: motion, period: 1ms}]
blocks:
  - {name: x, type: MC_AXIS, params: {v_max: 100, a_max: 1000, d_max: 1000}}
  - {name: drv, type: SIM_SERVO, inputs: {enable: TRUE}}
  - {name: pwr, type: MC_Power, params: {Axis: x}, inputs: {Enable: TRUE}}
  - {name: mv, type: MC_MoveAbsolute, params: {Axis: x}, inputs: {Position: 50, Velocity: 10}}
connections:
  - x.drive_position -> drv.target
  - drv.position -> x.actual_position
  - pwr.Status -> mv.Execute
)";

class HmiAxisRun {
 public:
  explicit HmiAxisRun(const char* project = kProject) {
    auto r = load_project_text(project, "hmi_axis.yaml", LoadOptions{});
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
  AxisState state() { return static_cast<AxisState>(cell("x.state").get<std::int16_t>()); }
  bool flag(const std::string& ref) { return cell(ref).get<bool>(); }
  void set(const std::string& tag, bool v) { cell(tag).set<bool>(v); }
  // What the HTTP API does: one write of an HMI pin, queued for the task's next scan.
  void hmi_write(const std::string& pin, bool v) {
    auto r = prog_->resolve("x." + pin);
    ASSERT_TRUE(r);
    QueuedWrite w;
    w.cell = r->cell;
    w.value.set<bool>(v);
    ASSERT_TRUE(prog_->tasks[r->task]->enqueue(&w, 1));
  }
  void scan() {
    now_ += kMs;
    clock_->run_until(now_);
  }
  template <class F>
  int until(F f, int limit) {
    for (int i = 1; i <= limit; ++i) {
      scan();
      if (f()) return i;
    }
    return -1;
  }

 private:
  std::unique_ptr<Program> prog_;
  std::unique_ptr<VirtualClock> clock_;
  std::int64_t now_ = 0;
};

TEST(McHmi, DisableFromTheHmiTakesAMovingAxisToDisabledAtTheNextScan) {
  HmiAxisRun run;
  ASSERT_TRUE(run.ok());
  run.set("power", true);
  ASSERT_GT(run.until([&] { return run.state() == AxisState::Standstill; }, 20), 0);
  run.set("go", true);
  ASSERT_GT(run.until([&] { return run.state() == AxisState::DiscreteMotion; }, 5), 0);
  EXPECT_TRUE(run.flag("x.powered"));

  run.hmi_write("hmi_enable", false);
  run.scan();
  EXPECT_EQ(run.state(), AxisState::Disabled) << "MC_Power.Enable is still TRUE: the permissive alone disables";
  EXPECT_TRUE(run.flag("mv.CommandAborted")) << "as MC_Power.Enable FALSE aborts the active move";
  EXPECT_FALSE(run.flag("x.enable")) << "the power stage is switched off";
  // It stays down while the program goes on asking for power.
  for (int i = 0; i < 20; ++i) run.scan();
  EXPECT_EQ(run.state(), AxisState::Disabled);
  EXPECT_FALSE(run.flag("x.powered"));

  // Enable permits MC_Power again: the program's Enable TRUE powers the axis.
  run.hmi_write("hmi_enable", true);
  EXPECT_GT(run.until([&] { return run.state() == AxisState::Standstill; }, 20), 0);
}

TEST(McHmi, EnableFromTheHmiNeverPowersAnAxisTheProgramDoesNot) {
  HmiAxisRun run;
  ASSERT_TRUE(run.ok());
  run.hmi_write("hmi_enable", false);
  run.scan();
  run.hmi_write("hmi_enable", true);
  for (int i = 0; i < 20; ++i) run.scan();
  EXPECT_EQ(run.state(), AxisState::Disabled);
  EXPECT_FALSE(run.flag("x.enable"));
  EXPECT_FALSE(run.flag("x.powered"));
}

TEST(McHmi, ResetFromTheHmiAcknowledgesADriveFaultAsMcResetDoes) {
  HmiAxisRun run;
  ASSERT_TRUE(run.ok());
  run.set("power", true);
  ASSERT_GT(run.until([&] { return run.state() == AxisState::Standstill; }, 20), 0);
  run.set("fault", true);
  ASSERT_GT(run.until([&] { return run.state() == AxisState::ErrorStop; }, 5), 0);
  EXPECT_EQ(run.cell("x.error_id").get<std::uint16_t>(), static_cast<std::uint16_t>(plcopen::AxisError::DriveFault));
  run.set("fault", false);
  for (int i = 0; i < 5; ++i) run.scan();
  EXPECT_EQ(run.state(), AxisState::ErrorStop) << "nothing resets it by itself";

  run.hmi_write("hmi_reset", true);
  // The drive's fault is acknowledged first (x.reset), then the axis leaves
  // ErrorStop to Standstill since MC_Power asks for power.
  const int took = run.until([&] { return run.state() == AxisState::Standstill; }, 10);
  EXPECT_GT(took, 0);
  EXPECT_FALSE(run.flag("x.hmi_reset")) << "the request is consumed";
  EXPECT_EQ(run.cell("x.error_id").get<std::uint16_t>(), 0);
}

TEST(McHmi, AResetOutsideErrorStopChangesNothingAndIsConsumed) {
  HmiAxisRun run;
  ASSERT_TRUE(run.ok());
  run.set("power", true);
  ASSERT_GT(run.until([&] { return run.state() == AxisState::Standstill; }, 20), 0);
  run.hmi_write("hmi_reset", true);
  run.scan();
  EXPECT_EQ(run.state(), AxisState::Standstill);
  EXPECT_FALSE(run.flag("x.hmi_reset"));
  // A later fault is not reset by the old request.
  run.set("fault", true);
  ASSERT_GT(run.until([&] { return run.state() == AxisState::ErrorStop; }, 5), 0);
  run.set("fault", false);
  for (int i = 0; i < 10; ++i) run.scan();
  EXPECT_EQ(run.state(), AxisState::ErrorStop);
}

TEST(McHmi, DisableSwitchesOffAnIdealDriveTooWhileMcPowerStillAsks) {
  // MC_Power asks again after the axis's cycle every scan; the ideal drive
  // (power_on unwired) must follow the enable the axis sent, not that request.
  HmiAxisRun run(kIdealDriveProject);
  ASSERT_TRUE(run.ok());
  ASSERT_GT(run.until([&] { return run.state() == AxisState::DiscreteMotion; }, 20), 0);
  run.hmi_write("hmi_enable", false);
  run.scan();
  EXPECT_EQ(run.state(), AxisState::Disabled);
  run.scan();
  EXPECT_FALSE(run.flag("x.powered")) << "the ideal drive's power stage follows the enable sent";
  EXPECT_FALSE(run.flag("pwr.Status"));
  for (int i = 0; i < 20; ++i) run.scan();
  EXPECT_EQ(run.state(), AxisState::Disabled);
  run.hmi_write("hmi_enable", true);
  EXPECT_GT(run.until([&] { return run.state() != AxisState::Disabled; }, 20), 0);
}

}  // namespace mc_hmi_test
}  // namespace syncplc
