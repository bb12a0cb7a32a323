// The PLCopen blocks in a project, run by the virtual clock: MC_AXIS bound
// to a SIM_SERVO, the MC_* blocks linked to it by `Axis`, the links' load
// errors, the order of the scan, and the output rules of §2.4.1 as a
// program sees them.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>

#include "fblocks/plcopen/axis_machine.hpp"
#include "runtime/core/virtual_clock.hpp"
#include "runtime/project/loader.hpp"
#include "tests/support/image_key.hpp"

namespace syncplc {
namespace {

using ::testing::HasSubstr;
using plcopen::AxisError;
using plcopen::AxisState;

constexpr std::int64_t kMs = 1'000'000;

// One axis on a simulated drive, the blocks a program needs, and tags that
// play the program's logic.
const char* kAxisProject = R"(
tasks: [{name: motion, period: 1ms}]
tags:
  - {name: power, type: BOOL}
  - {name: go, type: BOOL}
  - {name: go2, type: BOOL}
  - {name: target, type: LREAL}
  - {name: target2, type: LREAL}
  - {name: mode2, type: INT}
  - {name: stop, type: BOOL}
  - {name: fault, type: BOOL}
  - {name: reset, type: BOOL}
  - {name: vlim, type: LREAL, init: 100}
blocks:
  - {name: mv, type: MC_MoveAbsolute, params: {Axis: x}, inputs: {Velocity: 50, Acceleration: 500, Deceleration: 500}}
  - {name: mv2, type: MC_MoveAbsolute, params: {Axis: x}, inputs: {Velocity: 50}}
  - {name: stp, type: MC_Stop, params: {Axis: x}}
  - {name: pwr, type: MC_Power, params: {Axis: x}}
  - {name: rst, type: MC_Reset, params: {Axis: x}}
  - {name: st, type: MC_ReadStatus, params: {Axis: x}, inputs: {Enable: TRUE}}
  - {name: pos, type: MC_ReadActualPosition, params: {Axis: x}, inputs: {Enable: TRUE}}
  - {name: err, type: MC_ReadAxisError, params: {Axis: x}, inputs: {Enable: TRUE}}
  - {name: drv, type: SIM_SERVO}
  - {name: x, type: MC_AXIS, params: {v_max: 100, a_max: 1000, d_max: 1000}}
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
  - target -> mv.Position
  - go2 -> mv2.Execute
  - target2 -> mv2.Position
  - mode2 -> mv2.BufferMode
  - stop -> stp.Execute
  - fault -> drv.inject_fault
  - reset -> rst.Execute
  - vlim -> x.v_max_in
)";

class AxisRun {
 public:
  explicit AxisRun(const char* text) {
    auto r = load_project_text(text, "axis.yaml", LoadOptions{});
    for (const auto& d : r.diagnostics.list()) ADD_FAILURE() << d.text();
    prog_ = std::move(r.program);
    if (prog_) clock_ = std::make_unique<VirtualClock>(*prog_);
  }
  bool ok() const { return prog_ != nullptr; }
  // Loaded, MC_Power enabled and the axis in Standstill within 20 scans.
  bool powered() {
    if (!ok()) return false;
    set("power", true);
    return until([&] { return state() == static_cast<int>(AxisState::Standstill); }, 20) > 0;
  }
  Cell& cell(const std::string& ref) {
    auto r = prog_->resolve(ref);
    EXPECT_TRUE(r) << ref;
    return *prog_->live_cell(*r, testing::image_key());
  }
  bool flag(const std::string& ref) { return cell(ref).get<bool>(); }
  double real(const std::string& ref) { return cell(ref).get<double>(); }
  int state() { return cell("x.state").get<std::int16_t>(); }
  std::uint16_t word(const std::string& ref) { return cell(ref).get<std::uint16_t>(); }
  void set(const std::string& tag, bool v) { cell(tag).set<bool>(v); }
  void set_real(const std::string& tag, double v) { cell(tag).set<double>(v); }
  // One scan more.
  void scan() {
    now_ += kMs;
    clock_->run_until(now_);
  }
  void scans(int n) {
    for (int i = 0; i < n; ++i) scan();
  }
  // Scans until the condition holds (at most `limit`); how many it took, -1 if never.
  template <class F>
  int until(F f, int limit = 100000) {
    for (int i = 1; i <= limit; ++i) {
      scan();
      if (f()) return i;
    }
    return -1;
  }
  Program& program() { return *prog_; }

 private:
  std::unique_ptr<Program> prog_;
  std::unique_ptr<VirtualClock> clock_;
  std::int64_t now_ = 0;
};

int as_int(AxisState s) { return static_cast<int>(s); }

TEST(McProject, TheAxisRunsFirstAndItsBlocksAfterItWhateverTheirPlaceInTheFile) {
  AxisRun run(kAxisProject);
  ASSERT_TRUE(run.ok());
  const auto& blocks = run.program().tasks[0]->blocks;
  ASSERT_FALSE(blocks.empty());
  EXPECT_EQ(blocks[0].name, "x");
  // Every MC block names x and has its link resolved to x's place.
  for (const auto& b : blocks) {
    if (b.type->links.empty()) continue;
    ASSERT_EQ(b.links.size(), 1u) << b.name;
    EXPECT_EQ(b.links[0].target, 0u) << b.name;
    EXPECT_EQ(b.signature.links, std::vector<std::string>{"x"}) << b.name;
  }
}

TEST(McProject, PowerMoveAndTheOutputRulesOfExecute) {
  AxisRun run(kAxisProject);
  ASSERT_TRUE(run.ok());
  run.scans(3);
  EXPECT_EQ(run.state(), as_int(AxisState::Disabled));
  EXPECT_TRUE(run.flag("st.Disabled"));
  // A move to a disabled axis is refused (§2.1).
  run.set("go", true);
  run.scan();
  EXPECT_TRUE(run.flag("mv.Error"));
  EXPECT_EQ(run.word("mv.ErrorID"), static_cast<std::uint16_t>(AxisError::Disabled));
  run.set("go", false);
  run.scan();
  EXPECT_FALSE(run.flag("mv.Error")) << "Error falls with Execute";

  run.set("power", true);
  const int on = run.until([&] { return run.state() == as_int(AxisState::Standstill); }, 20);
  ASSERT_GT(on, 0);
  EXPECT_TRUE(run.flag("pwr.Status"));
  EXPECT_TRUE(run.flag("st.Standstill"));

  run.set_real("target", 10.0);
  run.set("go", true);
  run.scan();
  EXPECT_TRUE(run.flag("mv.Busy"));
  EXPECT_TRUE(run.flag("mv.Active"));
  EXPECT_FALSE(run.flag("mv.Done"));
  EXPECT_EQ(run.state(), as_int(AxisState::Standstill)) << "the axis takes the command at its next scan";
  run.scan();
  EXPECT_EQ(run.state(), as_int(AxisState::DiscreteMotion));
  const std::int64_t predicted = run.cell("x.remaining_scans").get<std::int64_t>();
  ASSERT_GT(predicted, 0);
  const int took = run.until([&] { return run.flag("mv.Done"); });
  EXPECT_EQ(took, predicted) << "Done in the scan the axis's prediction said";
  EXPECT_FALSE(run.flag("mv.Busy"));
  EXPECT_FALSE(run.flag("mv.Active"));
  EXPECT_EQ(run.real("x.set_position"), 10.0);
  EXPECT_EQ(run.state(), as_int(AxisState::Standstill));
  // The drive follows one scan later; the actual position then is the target.
  run.scan();
  EXPECT_EQ(run.real("pos.Position"), 10.0);
  EXPECT_TRUE(run.flag("pos.Valid"));
  // Done stays while Execute does, and falls with it.
  run.scans(5);
  EXPECT_TRUE(run.flag("mv.Done"));
  run.set("go", false);
  run.scan();
  EXPECT_FALSE(run.flag("mv.Done"));
}

TEST(McProject, DoneIsShownForOneScanWhenExecuteFellBeforeIt) {
  AxisRun run(kAxisProject);
  ASSERT_TRUE(run.powered());
  run.set_real("target", 1.0);
  run.set("go", true);
  run.scan();
  run.set("go", false);  // a one-scan pulse
  int done_scans = 0, busy_scans = 0;
  for (int i = 0; i < 2000; ++i) {
    run.scan();
    done_scans += run.flag("mv.Done");
    busy_scans += run.flag("mv.Busy");
  }
  EXPECT_EQ(done_scans, 1) << "§2.4.1: at least one scan, and only one with Execute low";
  EXPECT_GT(busy_scans, 0) << "the command goes on after Execute fell";
  EXPECT_EQ(run.real("x.set_position"), 1.0);
}

TEST(McProject, AnAbortingMoveTakesOverAndTheFirstReportsCommandAborted) {
  AxisRun run(kAxisProject);
  ASSERT_TRUE(run.powered());
  run.set_real("target", 100.0);
  run.set("go", true);
  run.scans(50);
  ASSERT_TRUE(run.flag("mv.Active"));
  run.set_real("target2", -5.0);
  run.set("go2", true);
  run.scan();
  EXPECT_TRUE(run.flag("mv2.Active"));
  // mv runs before mv2 in the scan: it sees the take-over at its next call.
  EXPECT_TRUE(run.flag("mv.Busy"));
  run.scan();
  EXPECT_TRUE(run.flag("mv.CommandAborted"));
  EXPECT_FALSE(run.flag("mv.Busy"));
  EXPECT_FALSE(run.flag("mv.Active"));
  ASSERT_GT(run.until([&] { return run.flag("mv2.Done"); }), 0);
  EXPECT_EQ(run.real("x.set_position"), -5.0);
  EXPECT_TRUE(run.flag("mv.CommandAborted")) << "held while its Execute is TRUE";
}

TEST(McProject, ABufferedMoveStartsWhenTheOneBeforeIsDone) {
  AxisRun run(kAxisProject);
  ASSERT_TRUE(run.powered());
  run.set_real("target", 2.0);
  run.set("go", true);
  run.scans(3);
  run.cell("mode2").set<std::int16_t>(1);  // Buffered
  run.set_real("target2", 3.0);
  run.set("go2", true);
  run.scan();
  EXPECT_TRUE(run.flag("mv2.Busy"));
  EXPECT_FALSE(run.flag("mv2.Active")) << "buffered: busy, not yet active";
  bool overlap = false;
  const int first = run.until([&] {
    overlap |= run.flag("mv.Active") && run.flag("mv2.Active");
    return run.flag("mv.Done");
  });
  ASSERT_GT(first, 0);
  EXPECT_TRUE(run.flag("mv2.Active")) << "takes over in the scan the first is Done";
  EXPECT_FALSE(overlap) << "one Active command per axis (§2.4.1)";
  ASSERT_GT(run.until([&] { return run.flag("mv2.Done"); }), 0);
  EXPECT_EQ(run.real("x.set_position"), 3.0);
}

TEST(McProject, StopHoldsTheAxisUntilItsExecuteFalls) {
  AxisRun run(kAxisProject);
  ASSERT_TRUE(run.powered());
  run.set_real("target", 100.0);
  run.set("go", true);
  run.scans(100);
  run.set("stop", true);
  run.scans(2);
  EXPECT_TRUE(run.flag("mv.CommandAborted"));
  ASSERT_GT(run.until([&] { return run.flag("stp.Done"); }), 0);
  EXPECT_EQ(run.state(), as_int(AxisState::Stopping));
  EXPECT_EQ(run.real("x.set_velocity"), 0.0);
  // A move while the stop holds the axis: refused.
  run.set("go2", true);
  run.scan();
  EXPECT_TRUE(run.flag("mv2.Error"));
  EXPECT_EQ(run.word("mv2.ErrorID"), static_cast<std::uint16_t>(AxisError::Stopping));
  run.set("go2", false);
  run.scans(10);
  EXPECT_EQ(run.state(), as_int(AxisState::Stopping));
  run.set("stop", false);
  run.scans(2);
  EXPECT_EQ(run.state(), as_int(AxisState::Standstill));
}

TEST(McProject, ADriveFaultStopsTheAxisAndMcResetBringsItBack) {
  AxisRun run(kAxisProject);
  ASSERT_TRUE(run.powered());
  run.set_real("target", 100.0);
  run.set("go", true);
  run.scans(20);
  run.set("fault", true);
  ASSERT_GT(run.until([&] { return run.state() == as_int(AxisState::ErrorStop); }, 5), 0);
  EXPECT_TRUE(run.flag("mv.Error")) << "§2.2.2: the active command gets Error, not CommandAborted";
  EXPECT_EQ(run.word("mv.ErrorID"), static_cast<std::uint16_t>(AxisError::DriveFault));
  EXPECT_EQ(run.word("err.AxisErrorID"), static_cast<std::uint16_t>(AxisError::DriveFault));
  EXPECT_EQ(run.word("err.DriveErrorID"), 0x7500);
  EXPECT_TRUE(run.flag("pwr.Error"));
  run.set("fault", false);
  run.set("reset", true);
  ASSERT_GT(run.until([&] { return run.flag("rst.Done"); }, 50), 0);
  // The fault switched the power stage off: the reset leads to Disabled
  // (§2.1 note 3), and MC_Power, still enabled, brings it to Standstill.
  EXPECT_EQ(run.state(), as_int(AxisState::Disabled));
  ASSERT_GT(run.until([&] { return run.state() == as_int(AxisState::Standstill); }, 20), 0);
  EXPECT_EQ(run.word("err.AxisErrorID"), 0);
  // Moves again.
  run.set("go", false);
  run.set("reset", false);
  run.scan();
  run.set_real("target", 0.0);
  run.set("go", true);
  ASSERT_GT(run.until([&] { return run.flag("mv.Done"); }), 0);
  EXPECT_EQ(run.real("x.set_position"), 0.0);
}

TEST(McProject, PowerOffAbortsTheMoveAndDisablesTheAxis) {
  AxisRun run(kAxisProject);
  ASSERT_TRUE(run.powered());
  run.set_real("target", 100.0);
  run.set("go", true);
  run.scans(20);
  run.set("power", false);
  run.scans(2);  // pwr runs after mv and x: both see it at their next scan
  EXPECT_TRUE(run.flag("mv.CommandAborted"));
  EXPECT_EQ(run.state(), as_int(AxisState::Disabled));
  EXPECT_FALSE(run.flag("x.enable"));
}

TEST(McProject, ALowerVelocityLimitOnTheTuningInputActsOnTheRunningMove) {
  AxisRun run(kAxisProject);
  ASSERT_TRUE(run.powered());
  run.set_real("target", 40.0);
  run.set("go", true);
  ASSERT_GT(run.until([&] { return run.real("x.set_velocity") == 50.0; }), 0) << "cruising at the move's 50";
  run.set_real("vlim", 20.0);
  run.scans(80);  // from 50 to 20 u/s with the move's deceleration 500 u/s^2: 60 scans
  double fastest = 0;
  const int left = run.until([&] {
    fastest = std::max(fastest, run.real("x.set_velocity"));
    return run.flag("mv.Done");
  });
  ASSERT_GT(left, 0);
  EXPECT_LE(fastest, 20.0);
  EXPECT_EQ(run.real("x.set_position"), 40.0);
  EXPECT_EQ(run.state(), static_cast<int>(AxisState::Standstill)) << "kept its state: no re-creation";
  // A limit the axis cannot take (0) is refused: ENO FALSE, the last one holds.
  run.set_real("vlim", 0.0);
  run.scans(2);
  EXPECT_FALSE(run.flag("x.ENO"));
  run.set_real("target", 0.0);
  run.set("go", false);
  run.scan();
  run.set("go", true);
  run.scan();
  // The last valid limit, 20, holds: a move at 50 is refused.
  EXPECT_TRUE(run.flag("mv.Error"));
  EXPECT_EQ(run.word("mv.ErrorID"), static_cast<std::uint16_t>(AxisError::BadVelocity));
}

// ---- links: the load errors ----------------------------------------------------

std::string load_errors(const std::string& text) {
  auto r = load_project_text(text, "p.yaml", LoadOptions{});
  std::string s;
  for (const auto& d : r.diagnostics.sorted()) s += d.text() + "\n";
  return s;
}

TEST(McProjectLinks, AMisspeltAxisIsALoadErrorWithTheClosestName) {
  EXPECT_THAT(load_errors(R"(tasks: [{name: t, period: 1ms}]
blocks:
  - {name: axis_x, type: MC_AXIS, inputs: {actual_position: 0}}
  - {name: p, type: MC_Power, params: {Axis: axis_y}}
)"),
              HasSubstr("p.yaml:4:46: p.Axis: no MC_AXIS instance 'axis_y' (did you mean 'axis_x'?)"));
}

TEST(McProjectLinks, AnAxisOfAnotherTypeOrTaskOrNoneIsALoadError) {
  const std::string errs = load_errors(R"(tasks: [{name: a, period: 1ms}, {name: b, period: 2ms}]
blocks:
  - {name: x, type: MC_AXIS, task: a, inputs: {actual_position: 0}}
  - {name: n, type: UNIT_DELAY, task: a, inputs: {IN: 0.0}}
  - {name: p1, type: MC_Power, task: a, params: {Axis: n}}
  - {name: p2, type: MC_Power, task: b, params: {Axis: x}}
  - {name: p3, type: MC_Power, task: a}
  - {name: p4, type: MC_Power, task: a, params: {Axis: [x]}}
  - {name: p5, type: MC_Power, task: a, params: {Axis: x}}
  - {name: p6, type: MC_Power, task: a, params: {Axis: x}}
)");
  EXPECT_THAT(errs, HasSubstr("p.yaml:5:56: p1.Axis: n is a UNIT_DELAY, not an instance of MC_AXIS"));
  EXPECT_THAT(errs, HasSubstr("p.yaml:6:56: p2.Axis: x runs in task a, p2 in b"));
  EXPECT_THAT(errs, HasSubstr("p.yaml:7:5: block instance p3 needs parameter Axis (the MC_AXIS instance it works on)"));
  EXPECT_THAT(errs, HasSubstr("p.yaml:8:56: MC_Power.Axis: expected the name of an instance of MC_AXIS"));
  EXPECT_THAT(errs, ::testing::Not(HasSubstr("p4 needs"))) << "no follow-on error";
  EXPECT_THAT(errs, HasSubstr("p.yaml:10:56: p6.Axis: x is already named by p5 (one MC_Power per axis, PLCopen Part 1 section 3.1)"));
}

}  // namespace
}  // namespace syncplc
