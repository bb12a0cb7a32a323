// The PLCopen blocks called from Structured Text (docs/st.md, "Motion
// control blocks"): a PROGRAM names its axes with VAR_EXTERNAL X : AXIS_REF
// and passes them as `Axis := X`. The same program built from YAML blocks
// gives bit-identical traces; a group move from ST arrives on one scan;
// wrong or missing axes are load errors at their place; an online change
// keeps an ST program reaching its axis; the scan path does not allocate.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <atomic>
#include <bit>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <new>
#include <string>
#include <vector>

#include <unistd.h>

#include "fblocks/plcopen/axis_machine.hpp"
#include "runtime/core/program_change.hpp"
#include "runtime/core/virtual_clock.hpp"
#include "runtime/project/loader.hpp"
#include "tests/support/image_key.hpp"

// The scan path never allocates: this binary's operator new counts while
// mc_st_counting is set (the test at the end).
#include "tests/support/allocation_counter.hpp"

// The scan-path test below counts this binary's operator new
// (tests/support/allocation_counter.*).
namespace {
std::atomic<bool>& mc_st_counting = syncplc::test::counting_allocations;
std::atomic<long>& mc_st_allocations = syncplc::test::allocations_counted;
}  // namespace

namespace syncplc {
namespace mc_st {

using ::testing::HasSubstr;
using plcopen::AxisState;

constexpr std::int64_t kMs = 1'000'000;

std::string write_source(const std::string& name, const std::string& text) {
  const auto dir = std::filesystem::temp_directory_path() / ("syncplc-mc-st-" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  const auto path = dir / name;
  std::ofstream(path) << text;
  return path.string();
}

// One axis on a simulated drive, the tags of the program's logic, and
// `blocks`, `connections` and `rest` (top-level keys) added.
std::string axis_project(const std::string& scale, const std::string& blocks, const std::string& connections,
                         const std::string& rest) {
  return R"(
tasks: [{name: motion, period: 1ms}, {name: slow, period: 10ms}]
tags:
  - {name: power, type: BOOL, task: motion}
  - {name: go, type: BOOL, task: motion}
  - {name: target, type: LREAL, init: 40, task: motion}
  - {name: done, type: BOOL, task: motion}
  - {name: standstill, type: BOOL, task: motion}
blocks:
  - {name: x, type: MC_AXIS, task: motion, params: {v_max: 100, a_max: 1000, d_max: 1000, scale: )" +
         scale + R"(}}
  - {name: drv, type: SIM_SERVO, task: motion, params: {tau: 0.002}}
)" + blocks + R"(connections:
  - x.enable -> drv.enable
  - x.drive_position -> drv.target
  - drv.position -> x.actual_position
  - drv.power_on -> x.power_on
)" + connections + rest;
}

// The program's blocks as YAML blocks.
std::string yaml_project() {
  return axis_project("1", R"(  - {name: pwr, type: MC_Power, task: motion, params: {Axis: x}}
  - {name: mv, type: MC_MoveAbsolute, task: motion, params: {Axis: x}, inputs: {Velocity: 50, Acceleration: 500, Deceleration: 500}}
  - {name: st, type: MC_ReadStatus, task: motion, params: {Axis: x}, inputs: {Enable: TRUE}}
)",
                      R"(  - power -> pwr.Enable
  - go -> mv.Execute
  - target -> mv.Position
  - mv.Done -> done
  - st.Standstill -> standstill
)",
                      "");
}

const char* kMotionSt = R"(PROGRAM Motion
VAR_EXTERNAL x : AXIS_REF; power, go : BOOL; target : LREAL; done, standstill : BOOL; END_VAR
VAR pwr : MC_Power; mv : MC_MoveAbsolute; st : MC_ReadStatus; END_VAR
pwr(Axis := x, Enable := power);
mv(Axis := x, Execute := go, Position := target, Velocity := 50.0, Acceleration := 500.0, Deceleration := 500.0);
st(Axis := x, Enable := TRUE);
done := mv.Done;
standstill := st.Standstill;
END_PROGRAM
)";

// The same program in ST.
std::string st_project(const std::string& source, const std::string& scale = "1", const std::string& more = "") {
  return axis_project(scale, more, "",
                      "sources: [" + write_source("motion.st", source) +
                          "]\nprograms:\n  - {name: prog, type: Motion, task: motion}\n");
}

std::string load_errors(const std::string& text) {
  auto r = load_project_text(text, "axis.yaml", LoadOptions{});
  std::string s;
  for (const auto& d : r.diagnostics.sorted()) s += d.text() + "\n";
  return s;
}

class McRun {
 public:
  explicit McRun(const std::string& text) {
    auto r = load_project_text(text, "axis.yaml", LoadOptions{});
    for (const auto& d : r.diagnostics.list()) ADD_FAILURE() << d.text();
    prog_ = std::move(r.program);
    if (prog_) clock_ = std::make_unique<VirtualClock>(*prog_);
  }
  bool ok() const { return prog_ != nullptr; }
  Cell& cell(const std::string& ref) {
    auto r = clock_->program().resolve(ref);
    EXPECT_TRUE(r) << ref;
    static Cell none;
    return r ? *clock_->program().live_cell(*r, testing::image_key()) : none;
  }
  double real(const std::string& ref) { return cell(ref).get<double>(); }
  bool flag(const std::string& ref) { return cell(ref).get<bool>(); }
  int state(const std::string& axis = "x") { return cell(axis + ".state").get<std::int16_t>(); }
  void scan() { clock_->run_until(now_ += kMs); }
  VirtualClock& clock() { return *clock_; }
  std::int64_t now() const { return now_; }

 private:
  std::unique_ptr<Program> prog_;
  std::unique_ptr<VirtualClock> clock_;
  std::int64_t now_ = 0;
};

// Power on, a move to 40, a move back to -15: the axis's set and actual
// position, its state and the move's outputs, scan by scan.
std::vector<double> move_trace(McRun& r) {
  std::vector<double> t;
  r.cell("power").set<bool>(true);
  for (int k = 0; k < 3000; ++k) {
    if (k == 10) r.cell("go").set<bool>(true);
    if (k == 1200) {
      r.cell("go").set<bool>(false);
      r.cell("target").set<double>(-15.0);
    }
    if (k == 1202) r.cell("go").set<bool>(true);
    r.scan();
    t.push_back(r.real("x.set_position"));
    t.push_back(r.real("x.set_velocity"));
    t.push_back(r.real("x.position"));
    t.push_back(r.state());
    t.push_back(r.flag("done"));
    t.push_back(r.flag("standstill"));
  }
  return t;
}

TEST(McSt, AProgramPowersMovesAndReadsTheStatusOfItsAxis) {
  McRun r(st_project(kMotionSt));
  ASSERT_TRUE(r.ok());
  EXPECT_EQ(r.state(), static_cast<int>(AxisState::Disabled));
  r.cell("power").set<bool>(true);
  for (int k = 0; k < 5; ++k) r.scan();
  EXPECT_EQ(r.state(), static_cast<int>(AxisState::Standstill));
  EXPECT_TRUE(r.flag("prog.pwr.Status"));
  EXPECT_TRUE(r.flag("standstill"));
  r.cell("go").set<bool>(true);
  r.scan();
  EXPECT_TRUE(r.flag("prog.mv.Busy"));
  int scans = 0;
  while (!r.flag("done") && scans < 5000) {
    r.scan();
    ++scans;
    EXPECT_TRUE(r.flag("prog.st.DiscreteMotion") || r.flag("done"));
  }
  ASSERT_TRUE(r.flag("done"));
  EXPECT_EQ(r.real("x.set_position"), 40.0) << "exactly on the goal";
  r.scan();
  EXPECT_TRUE(r.flag("standstill"));
}

TEST(McSt, TheSameProgramFromYamlBlocksGivesBitIdenticalTraces) {
  // The ST program on native code and on the interpreter (LINK_BLOCK is
  // the interpreter's handler on both).
  McRun st(st_project(kMotionSt)), yaml(yaml_project());
  McRun interp("project: {st_engine: interpreter}\n" + st_project(kMotionSt));
  ASSERT_TRUE(st.ok());
  ASSERT_TRUE(yaml.ok());
  ASSERT_TRUE(interp.ok());
  const std::vector<double> a = move_trace(st), b = move_trace(yaml), c = move_trace(interp);
  ASSERT_EQ(a.size(), b.size());
  ASSERT_EQ(c.size(), b.size());
  for (std::size_t i = 0; i < a.size(); ++i) {
    ASSERT_EQ(std::bit_cast<std::uint64_t>(a[i]), std::bit_cast<std::uint64_t>(b[i]))
        << "scan " << i / 6 << ", value " << i % 6 << ": " << a[i] << " vs " << b[i];
    ASSERT_EQ(std::bit_cast<std::uint64_t>(c[i]), std::bit_cast<std::uint64_t>(b[i]))
        << "interpreter, scan " << i / 6 << ", value " << i % 6;
  }
  // The trace went somewhere: both moves were done.
  EXPECT_EQ(st.real("x.set_position"), -15.0);
}

// Three axes of different limits; the group move either from ST or from a
// YAML block (`blocks` and `connections` added).
std::string group_part(const std::string& blocks, const std::string& connections) {
  std::string t = R"(
tasks: [{name: motion, period: 1ms}]
tags:
  - {name: go, type: BOOL}
  - {name: targets, type: "ARRAY[1..3] OF LREAL", init: [30, -20, 7]}
  - {name: remaining, type: LINT}
  - {name: done, type: BOOL}
blocks:
)";
  const char* limits[] = {"v_max: 40, a_max: 300, d_max: 200", "v_max: 25, a_max: 500, d_max: 500",
                          "v_max: 60, a_max: 100, d_max: 400"};
  std::string wires;
  for (int i = 1; i <= 3; ++i) {
    const std::string x = "x" + std::to_string(i), d = "d" + std::to_string(i);
    t += "  - {name: " + x + ", type: MC_AXIS, params: {" + limits[i - 1] + "}}\n";
    t += "  - {name: " + d + ", type: SIM_SERVO, params: {position0: " + std::to_string(i * 3 - 5) + "}}\n";
    wires += "  - " + x + ".enable -> " + d + ".enable\n  - " + x + ".drive_position -> " + d + ".target\n  - " + d +
             ".position -> " + x + ".actual_position\n  - " + d + ".power_on -> " + x + ".power_on\n";
  }
  return t + blocks + "connections:\n" + wires + connections;
}

std::string group_yaml() {
  return group_part(R"(  - {name: p1, type: MC_Power, params: {Axis: x1}, inputs: {Enable: TRUE}}
  - {name: p2, type: MC_Power, params: {Axis: x2}, inputs: {Enable: TRUE}}
  - {name: p3, type: MC_Power, params: {Axis: x3}, inputs: {Enable: TRUE}}
  - {name: grp, type: MC_GroupMoveAbsolute, params: {n: 3, Axes: [x1, x2, x3]}}
)",
                    R"(  - go -> grp.Execute
  - targets -> grp.Position
  - grp.RemainingScans -> remaining
  - grp.Done -> done
)");
}

const char* kGroupSt = R"(PROGRAM Group
VAR_EXTERNAL x1, x2, x3 : AXIS_REF; go : BOOL; targets : ARRAY[1..3] OF LREAL; remaining : LINT; done : BOOL; END_VAR
VAR
  p1, p2, p3 : MC_Power;
  grp : MC_GroupMoveAbsolute := (n := 3);
  axes : ARRAY[1..3] OF AXIS_REF;
END_VAR
axes[1] := x1; axes[2] := x2; axes[3] := x3;
p1(Axis := x1, Enable := TRUE);
p2(Axis := x2, Enable := TRUE);
p3(Axis := x3, Enable := TRUE);
grp(Axes := axes, Execute := go, Position := targets);
remaining := grp.RemainingScans;
done := grp.Done;
END_PROGRAM
)";

std::string group_st() {
  return group_part("", "") + "sources: [" + write_source("group.st", kGroupSt) +
         "]\nprograms:\n  - {name: prog, type: Group}\n";
}

TEST(McSt, AGroupMoveFromStArrivesTogetherAsTheYamlBlockDoes) {
  McRun st(group_st()), yaml(group_yaml());
  ASSERT_TRUE(st.ok());
  ASSERT_TRUE(yaml.ok());
  int arrived[2] = {-1, -1};
  std::int64_t predicted[2] = {0, 0};
  McRun* runs[2] = {&st, &yaml};
  for (int k = 0; k < 3000; ++k)
    for (int j = 0; j < 2; ++j) {
      McRun& r = *runs[j];
      if (k == 10) r.cell("go").set<bool>(true);
      r.scan();
      if (k == 10) predicted[j] = r.cell("remaining").get<std::int64_t>();
      if (arrived[j] < 0 && r.flag("done")) arrived[j] = k;
      if (j == 1)
        for (int i = 1; i <= 3; ++i) {
          const std::string p = "x" + std::to_string(i) + ".set_position";
          ASSERT_EQ(std::bit_cast<std::uint64_t>(st.real(p)), std::bit_cast<std::uint64_t>(yaml.real(p)))
              << "scan " << k << ", " << p;
        }
    }
  ASSERT_GT(arrived[0], 10);
  EXPECT_EQ(arrived[0], arrived[1]);
  EXPECT_EQ(predicted[0], predicted[1]);
  EXPECT_EQ(arrived[0] - 10, predicted[0]) << "on the scan RemainingScans said at the start";
  EXPECT_EQ(st.real("x1.set_position"), 30.0);
  EXPECT_EQ(st.real("x2.set_position"), -20.0);
  EXPECT_EQ(st.real("x3.set_position"), 7.0);
}

TEST(McSt, AWrongAxisIsALoadErrorAtItsDeclaration) {
  auto with = [](const std::string& external, const std::string& more = "") {
    const std::string src = "PROGRAM Motion\nVAR_EXTERNAL " + external +
                            " : AXIS_REF; END_VAR\nVAR pwr : MC_Power; END_VAR\npwr(Axis := " + external +
                            ", Enable := TRUE);\nEND_PROGRAM\n";
    return load_errors(st_project(src, "1", more));
  };
  // Unknown, with the closest MC_AXIS suggested (the project's names are
  // case-sensitive; ST's are not: the VAR_EXTERNAL names the instance as spelt).
  EXPECT_THAT(with("X"), HasSubstr("motion.st:2:14: prog.X: no MC_AXIS instance 'X' (did you mean 'x'?)"));
  EXPECT_THAT(with("z"), HasSubstr("motion.st:2:14: prog.z: no MC_AXIS instance 'z'\n"));
  // An instance of another type.
  EXPECT_THAT(with("drv"), HasSubstr("motion.st:2:14: prog.drv: drv is a SIM_SERVO, not an instance of MC_AXIS"));
  // An axis of another task.
  EXPECT_THAT(with("y", "  - {name: y, type: MC_AXIS, task: slow, params: {v_max: 1, a_max: 1, d_max: 1}}\n"),
              HasSubstr("prog.y: y runs in task slow, prog in motion: a block works only on an instance of its own task"));
}

TEST(McSt, OneMcPowerPerAxisAlsoAcrossStCalls) {
  const std::string two = R"(PROGRAM Motion
VAR_EXTERNAL x : AXIS_REF; END_VAR
VAR pwr, pwr2 : MC_Power; END_VAR
pwr(Axis := x, Enable := TRUE);
pwr(Axis := x, Enable := TRUE);
pwr2(Axis := x, Enable := FALSE);
END_PROGRAM
)";
  const std::string errors = load_errors(st_project(two));
  EXPECT_THAT(errors, HasSubstr("motion.st:6:14: prog.pwr2.Axis: x is already named by prog.pwr (one MC_Power per axis"));
  EXPECT_THAT(errors, ::testing::Not(HasSubstr("motion.st:5:"))) << "one instance may be called twice";
  // A YAML MC_Power and one called from ST.
  const std::string one = "PROGRAM Motion\nVAR_EXTERNAL x : AXIS_REF; END_VAR\nVAR pwr : MC_Power; END_VAR\n"
                          "pwr(Axis := x, Enable := TRUE);\nEND_PROGRAM\n";
  EXPECT_THAT(load_errors(st_project(one, "1", "  - {name: yaml_pwr, type: MC_Power, task: motion, params: {Axis: x}}\n")),
              HasSubstr("motion.st:4:13: prog.pwr.Axis: x is already named by yaml_pwr (one MC_Power per axis"));
}

TEST(McSt, AnAxisRefThatNamesNoAxisFaultsAndTheBlockReportsAnError) {
  // A variable never given an axis: the call faults at its place, and the
  // block, which has no axis, refuses the command (0x0101, as a Disabled axis).
  const std::string src = R"(PROGRAM Motion
VAR_EXTERNAL go : BOOL; END_VAR
VAR nowhere : AXIS_REF; mv : MC_MoveAbsolute; END_VAR
mv(Axis := nowhere, Execute := go, Position := 1.0, Velocity := 1.0);
END_PROGRAM
)";
  McRun r(st_project(src));
  ASSERT_TRUE(r.ok());
  r.cell("go").set<bool>(true);
  r.scan();
  EXPECT_TRUE(r.flag("prog.mv.Error"));
  EXPECT_EQ(r.cell("prog.mv.ErrorID").get<std::uint16_t>(), 0x0101);
  std::string faults;
  Event e;
  while (r.clock().program().tasks[0]->pop_event(e)) faults += std::string(e.message) + "\n";
  EXPECT_THAT(faults, HasSubstr("Axis: the AXIS_REF passed names no MC_AXIS at "));
}

// An online change that keeps the ST program (its source unchanged) and the
// axis: the move it gave goes on to its goal, its status reader sees the kept
// axis. One that re-creates the axis: the program's move ends CommandAborted
// and the program reaches the new axis (powered again, it moves).
TEST(McSt, AnOnlineChangeKeepsTheProgramReachingItsAxis) {
  for (const bool recreate : {false, true}) {
    SCOPED_TRACE(recreate ? "axis re-created" : "axis kept");
    McRun r(st_project(kMotionSt));
    ASSERT_TRUE(r.ok());
    r.cell("power").set<bool>(true);
    for (int k = 0; k < 5; ++k) r.scan();
    r.cell("go").set<bool>(true);
    for (int k = 0; k < 200; ++k) r.scan();
    ASSERT_TRUE(r.flag("prog.mv.Busy"));
    auto b = load_project_text(st_project(kMotionSt, recreate ? "2" : "1",
                                          "  - {name: extra, type: MC_ReadStatus, task: motion, params: {Axis: x}, "
                                          "inputs: {Enable: TRUE}}\n"),
                               "axis.yaml", LoadOptions{});
    for (const auto& d : b.diagnostics.list()) ADD_FAILURE() << d.text();
    ASSERT_TRUE(b.program);
    auto change = plan_change(r.clock().program(), *b.program);
    bool kept = false;
    for (const auto& c : change->instances) kept |= c.name == "prog" && c.fate == InstanceFate::Kept;
    EXPECT_TRUE(kept) << "the ST program is kept";
    change->switch_ns = r.now() + 10 * kMs;
    r.clock().begin_change(*change);
    for (int k = 0; k < 30; ++k) r.scan();
    ASSERT_TRUE(r.clock().change_complete());
    ASSERT_EQ(&r.clock().program(), b.program.get());
    if (!recreate) {
      EXPECT_TRUE(r.flag("prog.mv.Busy")) << "the kept move goes on";
      EXPECT_TRUE(r.flag("prog.st.DiscreteMotion")) << "the reader sees the kept axis, moving";
      int scans = 0;
      while (!r.flag("done") && scans++ < 5000) r.scan();
      EXPECT_TRUE(r.flag("done"));
      EXPECT_EQ(r.real("x.set_position"), 40.0);
      continue;
    }
    EXPECT_TRUE(r.flag("prog.mv.CommandAborted")) << "its axis went away with the command";
    EXPECT_EQ(r.state(), static_cast<int>(AxisState::Standstill)) << "MC_Power of the program powered the new axis";
    r.cell("go").set<bool>(false);
    r.scan();
    r.cell("go").set<bool>(true);
    int scans = 0;
    while (!r.flag("done") && scans++ < 5000) r.scan();
    EXPECT_TRUE(r.flag("done")) << "the program moves the new axis";
    EXPECT_EQ(r.real("x.set_position"), 40.0);
  }
}

TEST(McSt, TheExampleProjectMovesItsAxesToTheCornerTogetherAndHomeAgain) {
  auto r = load_project(std::string(SYNCPLC_SOURCE_DIR) + "/projects/plcopen_st/cell.yaml");
  for (const auto& d : r.diagnostics.list()) ADD_FAILURE() << d.text();
  ASSERT_TRUE(r.program);
  VirtualClock clock(*r.program);
  auto cell = [&](const std::string& ref) -> Cell& {
    return *r.program->live_cell(*r.program->resolve(ref), testing::image_key());
  };
  int at_corner[2] = {-1, -1};
  std::int64_t now = 0;
  for (int k = 0; k < 10000; ++k) {
    clock.run_until(now += kMs);
    if (at_corner[0] < 0 && cell("x.set_position").get<double>() == 120.0) at_corner[0] = k;
    if (at_corner[1] < 0 && cell("y.set_position").get<double>() == 80.0) at_corner[1] = k;
  }
  ASSERT_GT(at_corner[0], 0);
  EXPECT_EQ(at_corner[0], at_corner[1]) << "x and y reach the corner on the same scan";
  EXPECT_GE(cell("cycles").get<std::int32_t>(), 2) << "corner and home, over and over";
}

TEST(McSt, TheScanPathDoesNotAllocate) {
  McRun r(group_st());
  ASSERT_TRUE(r.ok());
  for (int k = 0; k < 20; ++k) r.scan();
  r.cell("go").set<bool>(true);
  for (int k = 0; k < 5; ++k) r.scan();
  mc_st_allocations = 0;
  mc_st_counting = true;
  for (int k = 0; k < 500; ++k) r.scan();
  mc_st_counting = false;
  EXPECT_EQ(mc_st_allocations.load(), 0);
}

}  // namespace mc_st
}  // namespace syncplc
