// Online change of an instance whose wiring changed (issue 21, the critical
// defect): a block never runs its old wiring after the switch. Each case runs
// project A, changes to B at T, and compares every later scan with B run from
// the start, on inputs for which A's and B's state are the same before T: a
// kept or re-created instance must then give B's values bit for bit.
#include <gtest/gtest.h>

#include <cstring>
#include <map>

#include "runtime/core/program_change.hpp"
#include "runtime/core/virtual_clock.hpp"
#include "tests/support/project_fixture.hpp"

namespace syncplc {
namespace {

constexpr std::int64_t kT = 50'000'000;     // the switch instant
constexpr std::int64_t kEnd = 120'000'000;

using Trace = std::map<std::int64_t, std::vector<std::uint64_t>>;  // time -> raw cells of the watched tags

void watch(VirtualClock& c, const std::vector<std::string>& tags, Trace& out) {
  c.on_time_point([&c, &out, tags](std::int64_t t) {
    std::vector<std::uint64_t> row;
    for (const auto& name : tags) {
      auto r = c.program().resolve(name);
      ASSERT_TRUE(r) << name;
      row.push_back(c.program().live_cell(*r, ::syncplc::testing::image_key())->raw);
    }
    out[t] = row;
  });
}

struct Outcome {
  std::unique_ptr<Program> a, b;
  std::unique_ptr<ProgramChange> change;
  Trace trace;
};

// A until T, B from T on (online change); every time point's watched values.
Outcome changed_run(const std::string& a, const std::string& b, const std::vector<std::string>& tags,
                    const std::function<void(Program&, std::int64_t)>& inputs = {}) {
  Outcome o;
  o.a = load_test_project(a);
  EXPECT_TRUE(o.a);
  if (!o.a) return o;
  VirtualClock c(*o.a);
  watch(c, tags, o.trace);
  if (inputs) inputs(*o.a, 0);
  c.run_until(kT - 10'000'000);
  o.b = load_test_project(b);
  EXPECT_TRUE(o.b);
  if (!o.b) return o;
  o.change = plan_change(*o.a, *o.b);
  o.change->switch_ns = kT;
  c.begin_change(*o.change);
  c.run_until(kT);
  if (inputs) inputs(c.program(), kT);
  c.run_until(kEnd);
  EXPECT_TRUE(c.change_complete());
  return o;
}

Trace fresh_run(const std::string& b, const std::vector<std::string>& tags,
                const std::function<void(Program&, std::int64_t)>& inputs = {}) {
  Trace t;
  auto p = load_test_project(b);
  EXPECT_TRUE(p);
  if (!p) return t;
  VirtualClock c(*p);
  watch(c, tags, t);
  if (inputs) inputs(*p, 0);
  c.run_until(kT);
  if (inputs) inputs(*p, kT);
  c.run_until(kEnd);
  return t;
}

// Every time point from the first scan after the switch on is equal.
void expect_same_after_switch(const Trace& changed, const Trace& fresh, const std::vector<std::string>& tags) {
  std::size_t compared = 0;
  for (const auto& [t, row] : fresh) {
    if (t < kT) continue;
    auto it = changed.find(t);
    ASSERT_NE(it, changed.end()) << "no scan at " << t;
    for (std::size_t i = 0; i < row.size(); ++i) {
      double a, b;
      std::memcpy(&a, &it->second[i], sizeof a);
      std::memcpy(&b, &row[i], sizeof b);
      EXPECT_EQ(it->second[i], row[i]) << tags[i] << " at " << t * 1e-6 << " ms (as LREAL: changed " << a << ", fresh " << b << ")";
    }
    ++compared;
  }
  EXPECT_GT(compared, 50u);
}

const InstanceChange& fate_of(const ProgramChange& c, const std::string& name) {
  for (const auto& i : c.instances)
    if (i.name == name) return i;
  static InstanceChange none{"?", "?", "?", InstanceFate::Removed, "not in the report"};
  ADD_FAILURE() << name << " not in the change report";
  return none;
}

const char* kInterlockA = R"(
tasks: [{name: main, period: 1ms}]
tags:
  - {name: start_ok, type: BOOL, init: TRUE}
  - {name: guard_closed, type: BOOL, init: TRUE}
  - {name: estop_ok, type: BOOL, init: FALSE}
  - {name: motor_on, type: BOOL}
blocks:
  - {name: run_and, type: AND, task: main}
connections:
  - start_ok -> run_and.IN1
  - guard_closed -> run_and.IN2
  - run_and.OUT -> motor_on
)";

TEST(OnlineChangeWiring, AnInterlockWiredInByAnOnlineChangeHoldsAtOnce) {
  const std::string b = std::string(kInterlockA) + "  - estop_ok -> run_and.IN3\n";
  const std::vector<std::string> tags{"motor_on"};
  auto o = changed_run(kInterlockA, b, tags);
  ASSERT_TRUE(o.change);
  expect_same_after_switch(o.trace, fresh_run(b, tags), tags);
  EXPECT_FALSE(tag_cell(*o.b, "motor_on").get<bool>()) << "the new interlock (estop_ok FALSE) must stop the motor";
  const auto& f = fate_of(*o.change, "run_and");
  EXPECT_NE(f.detail.find("IN3"), std::string::npos) << "the report names the rewired pin: " << f.detail;
}

TEST(OnlineChangeWiring, AnInputUnwiredByAnOnlineChangeNoLongerTakesPart) {
  const std::string a = std::string(kInterlockA) + "  - estop_ok -> run_and.IN3\n";
  const std::vector<std::string> tags{"motor_on"};
  auto o = changed_run(a, kInterlockA, tags);
  ASSERT_TRUE(o.change);
  expect_same_after_switch(o.trace, fresh_run(kInterlockA, tags), tags);
  EXPECT_TRUE(tag_cell(*o.b, "motor_on").get<bool>());
}

TEST(OnlineChangeWiring, AnAddWithAThirdOperandAddsIt) {
  const std::string a = R"(
tasks: [{name: main, period: 1ms}]
tags:
  - {name: sum, type: LREAL}
blocks:
  - {name: add, type: ADD, task: main, datatype: LREAL, inputs: {IN1: 1.0, IN2: 2.0}}
connections:
  - add.OUT -> sum
)";
  std::string b = a;
  b.replace(b.find("IN2: 2.0}"), 9, "IN2: 2.0, IN3: 4.0}");
  const std::vector<std::string> tags{"sum"};
  auto o = changed_run(a, b, tags);
  ASSERT_TRUE(o.change);
  expect_same_after_switch(o.trace, fresh_run(b, tags), tags);
  EXPECT_EQ(tag_cell(*o.b, "sum").get<double>(), 7.0);
}

// PID as a P controller (Ti = Td = 0): y = Kp (setpoint - actual), no state.
std::string pid_project(bool kp_wired) {
  std::string s = R"(
tasks: [{name: main, period: 1ms}]
tags:
  - {name: kp_tag, type: LREAL, init: 5.0}
  - {name: y, type: LREAL}
blocks:
  - {name: pid, type: PID, task: main, params: {Kp: 2.0}, inputs: {setpoint: 1.0, actual: 0.0}}
connections:
  - pid.y -> y
)";
  if (kp_wired) s += "  - kp_tag -> pid.Kp_in\n";
  return s;
}

TEST(OnlineChangeWiring, RemovingATuningInputsWireGivesTheParameterBack) {
  const std::vector<std::string> tags{"y"};
  auto o = changed_run(pid_project(true), pid_project(false), tags);
  ASSERT_TRUE(o.change);
  expect_same_after_switch(o.trace, fresh_run(pid_project(false), tags), tags);
  EXPECT_EQ(tag_cell(*o.b, "y").get<double>(), 2.0) << "Kp is the parameter again, not 0 and not the old input";
}

TEST(OnlineChangeWiring, AddingATuningInputsWireTakesItsValue) {
  const std::vector<std::string> tags{"y"};
  auto o = changed_run(pid_project(false), pid_project(true), tags);
  ASSERT_TRUE(o.change);
  expect_same_after_switch(o.trace, fresh_run(pid_project(true), tags), tags);
  EXPECT_EQ(tag_cell(*o.b, "y").get<double>(), 5.0) << "Kp follows Kp_in";
}

// NONLINEAR_FILTER at rest on r = 0: its derived r_dot is 0, as the wired
// r_dot tag is until T. From T the tag says 0.5 m/s: a filter that still
// derives r_dot ignores it.
std::string filter_project(bool r_dot_wired) {
  std::string s = R"(
tasks: [{name: main, period: 1ms}]
tags:
  - {name: r, type: LREAL, init: 0.0}
  - {name: rd, type: LREAL, init: 0.0}
  - {name: x, type: LREAL}
  - {name: xd, type: LREAL}
blocks:
  - {name: f, type: NONLINEAR_FILTER, task: main, inputs: {v_min: -1.0, v_max: 1.0, a_min: -10.0, a_max: 10.0}}
connections:
  - r -> f.r
  - f.x -> x
  - f.x_dot -> xd
)";
  if (r_dot_wired) s += "  - rd -> f.r_dot\n";
  return s;
}

void set_rd(Program& p, std::int64_t t) {
  if (t == kT) tag_cell(p, "rd").set<double>(0.5);
}

TEST(OnlineChangeWiring, AFilterWhoseVelocityInputIsWiredInUsesIt) {
  const std::vector<std::string> tags{"x", "xd"};
  auto o = changed_run(filter_project(false), filter_project(true), tags, set_rd);
  ASSERT_TRUE(o.change);
  expect_same_after_switch(o.trace, fresh_run(filter_project(true), tags, set_rd), tags);
  EXPECT_NE(tag_cell(*o.b, "xd").get<double>(), 0.0) << "a filter that still derived r_dot would rest at 0";
}

TEST(OnlineChangeWiring, AFilterWhoseVelocityInputIsUnwiredDerivesIt) {
  const std::vector<std::string> tags{"x", "xd"};
  auto o = changed_run(filter_project(true), filter_project(false), tags, set_rd);
  ASSERT_TRUE(o.change);
  expect_same_after_switch(o.trace, fresh_run(filter_project(false), tags, set_rd), tags);
  EXPECT_EQ(tag_cell(*o.b, "xd").get<double>(), 0.0);
}

// PD_CONTROLLER: e_dot from v when v is wired, else the backward difference.
std::string pd_project(bool v_wired) {
  std::string s = R"(
tasks: [{name: main, period: 1ms}]
tags:
  - {name: xd, type: LREAL, init: 0.0}
  - {name: v, type: LREAL, init: 0.0}
  - {name: edot, type: LREAL}
blocks:
  - {name: pd, type: PD_CONTROLLER, task: main, inputs: {x: 0.0, v_d: 0.0}}
connections:
  - xd -> pd.x_d
  - pd.e_dot -> edot
)";
  if (v_wired) s += "  - v -> pd.v\n";
  return s;
}

void set_v(Program& p, std::int64_t t) {
  if (t == kT) tag_cell(p, "v").set<double>(-2.0);
}

TEST(OnlineChangeWiring, APdControllerWhoseVelocityIsWiredInUsesIt) {
  const std::vector<std::string> tags{"edot"};
  auto o = changed_run(pd_project(false), pd_project(true), tags, set_v);
  ASSERT_TRUE(o.change);
  expect_same_after_switch(o.trace, fresh_run(pd_project(true), tags, set_v), tags);
  EXPECT_EQ(tag_cell(*o.b, "edot").get<double>(), 2.0);
}

// TRANSIENT_SYNC: r_dot wired in, as NONLINEAR_FILTER.
std::string sync_project(bool r_dot_wired) {
  std::string s = R"(
tasks: [{name: main, period: 1ms}]
tags:
  - {name: r, type: "ARRAY[1..2] OF LREAL"}
  - {name: rd, type: "ARRAY[1..2] OF LREAL"}
  - {name: vmin, type: "ARRAY[1..2] OF LREAL", init: [-1.0, -1.0]}
  - {name: vmax, type: "ARRAY[1..2] OF LREAL", init: [1.0, 1.0]}
  - {name: amin, type: "ARRAY[1..2] OF LREAL", init: [-10.0, -10.0]}
  - {name: amax, type: "ARRAY[1..2] OF LREAL", init: [10.0, 10.0]}
  - {name: xdot, type: "ARRAY[1..2] OF LREAL"}
blocks:
  - {name: ts, type: TRANSIENT_SYNC, task: main, params: {n: 2}}
connections:
  - r -> ts.r
  - vmin -> ts.v_min
  - vmax -> ts.v_max
  - amin -> ts.a_min
  - amax -> ts.a_max
  - ts.x_dot -> xdot
)";
  if (r_dot_wired) s += "  - rd -> ts.r_dot\n";
  return s;
}

void set_rd2(Program& p, std::int64_t t) {
  if (t != kT) return;
  auto r = p.resolve("rd");
  ASSERT_TRUE(r);
  Cell* c = p.live_cell(*r, ::syncplc::testing::image_key());
  c[0].set<double>(0.5);
  c[1].set<double>(0.25);
}

TEST(OnlineChangeWiring, ATransientSyncWhoseVelocityInputIsWiredInUsesIt) {
  const std::vector<std::string> tags{"xdot[1]", "xdot[2]"};
  auto o = changed_run(sync_project(false), sync_project(true), tags, set_rd2);
  ASSERT_TRUE(o.change);
  expect_same_after_switch(o.trace, fresh_run(sync_project(true), tags, set_rd2), tags);
}

// A kept instance whose inputs come from elsewhere (same pins wired) keeps
// its state: a counter rewired from one pulse tag to another goes on counting.
TEST(OnlineChangeWiring, ACounterFedFromAnotherTagKeepsItsCount) {
  const std::string a = R"(
tasks: [{name: main, period: 1ms}]
tags:
  - {name: p1, type: BOOL}
  - {name: p2, type: BOOL}
  - {name: cv, type: INT}
blocks:
  - {name: n, type: CTU, task: main, inputs: {PV: 1000}}
connections:
  - p1 -> n.CU
  - n.CV -> cv
)";
  std::string b = a;
  b.replace(b.find("p1 -> n.CU"), 10, "p2 -> n.CU");
  auto pa = load_test_project(a);
  ASSERT_TRUE(pa);
  VirtualClock c(*pa);
  for (int k = 0; k < 10; ++k) {
    tag_cell(*pa, "p1").set<bool>(k % 2 == 0);
    c.run_until((k + 1) * 1'000'000);
  }
  const auto counted = tag_cell(*pa, "cv").get<std::int16_t>();
  ASSERT_EQ(counted, 5);
  auto pb = load_test_project(b);
  ASSERT_TRUE(pb);
  auto change = plan_change(*pa, *pb);
  change->switch_ns = 20'000'000;
  c.begin_change(*change);
  c.run_until(21'000'000);
  ASSERT_TRUE(c.change_complete());
  EXPECT_EQ(fate_of(*change, "n").fate, InstanceFate::Kept);
  for (int k = 0; k < 4; ++k) {
    tag_cell(*pb, "p2").set<bool>(k % 2 == 0);
    c.run_until(22'000'000 + k * 1'000'000);
  }
  EXPECT_EQ(tag_cell(*pb, "cv").get<std::int16_t>(), counted + 2);
}

}  // namespace
}  // namespace syncplc
