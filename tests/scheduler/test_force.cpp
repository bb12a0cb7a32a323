// Forcing in virtual time (runtime/core/force_table.hpp, Program::force):
// each place a force holds (driver input, a block's output tag, input pin,
// output pin, a tag bound to a driver output), against the program and
// against outside writes, release at the next scan, the limits and errors,
// what readers see, and online change.
#include <gtest/gtest.h>

#include <algorithm>

#include "runtime/core/program_change.hpp"
#include "runtime/core/virtual_clock.hpp"
#include "runtime/io/memory_driver.hpp"
#include "runtime/project/online_change.hpp"
#include "tests/support/project_fixture.hpp"

namespace syncplc {
namespace {

using testing::records;

// sensor (driver input) -> a -> mid -> r -> actuator (driver output);
// setpoint (nobody writes it) -> s; c has a constant input.
std::string project(const std::string& extra_project = "") {
  return R"(
project: {name: forcing)" + extra_project + R"(}
tasks: [{name: t, period: 1ms}]
tags:
  - {name: sensor, type: LREAL}
  - {name: mid, type: LREAL}
  - {name: actuator, type: LREAL}
  - {name: setpoint, type: LREAL, hmi: readwrite, unit: m}
  - {name: levels, type: "ARRAY[1..3] OF LREAL", hmi: readwrite}
blocks:
  - {name: a, type: RECORD, task: t}
  - {name: r, type: RECORD, task: t}
  - {name: s, type: RECORD, task: t}
  - {name: c, type: RECORD, task: t, inputs: {IN: 7.0}}
connections:
  - sensor -> a.IN
  - a.OUT -> mid
  - mid -> r.IN
  - r.OUT -> actuator
  - setpoint -> s.IN
drivers:
  - name: io
    type: memory
    task: t
    channels:
      - {name: in, dir: in, type: LREAL}
      - {name: out, dir: out, type: LREAL}
    bind: {in: sensor, out: actuator}
)";
}

MemoryDriver& memory(Program& p) { return dynamic_cast<MemoryDriver&>(*p.drivers[0].driver); }

void set_input(Program& p, double v) {
  Cell c;
  c.set<double>(v);
  memory(p).force_input(0, &c);
}

double output(Program& p) {
  Cell c;
  memory(p).read_output(1, &c);
  return c.get<double>();
}

double published(Program& p, const std::string& tag) {
  Cell c;
  p.read_tag(*p.find_tag(tag), &c);
  return c.get<double>();
}

// What block `name` saw on its IN in the last scan.
double seen(const std::string& name) {
  for (auto it = records().rbegin(); it != records().rend(); ++it)
    if (it->instance == name) return it->in;
  ADD_FAILURE() << "no record of " << name;
  return -1;
}

struct Plc {
  std::unique_ptr<Program> p;
  std::unique_ptr<VirtualClock> clock;
  std::int64_t t = 0;
  explicit Plc(const std::string& yaml = project()) {
    records().clear();
    p = load_test_project(yaml);
    clock = std::make_unique<VirtualClock>(*p);
  }
  void scans(int n) {
    t += n * 1'000'000LL;
    clock->run_until(t);
  }
};

TEST(Force, ADriverInputHoldsAfterTheInputsAreLatched) {
  Plc run;
  set_input(*run.p, 1.0);
  run.scans(2);
  EXPECT_EQ(seen("a"), 1.0);
  auto res = run.p->force("sensor", "5");
  ASSERT_TRUE(res.ok) << res.error;
  EXPECT_EQ(res.task, "t");
  run.scans(1);
  set_input(*run.p, 2.0);  // the field changes: the program still sees the forced value
  run.scans(2);
  EXPECT_EQ(seen("a"), 5.0);
  EXPECT_EQ(published(*run.p, "sensor"), 5.0);
  EXPECT_EQ(output(*run.p), 5.0) << "the value flows on through the program";
  ASSERT_TRUE(run.p->unforce("sensor").ok);
  run.scans(1);
  EXPECT_EQ(seen("a"), 2.0) << "the next latch after the unforce is the field's value again";
}

TEST(Force, ATagABlockWritesHoldsForEveryLaterReaderInTheScan) {
  Plc run;
  set_input(*run.p, 1.0);
  ASSERT_TRUE(run.p->force("mid", "9").ok);
  run.scans(3);
  EXPECT_EQ(seen("a"), 1.0);
  EXPECT_EQ(run.p->live_cell(*run.p->resolve("a.OUT"), ::syncplc::testing::image_key())->get<double>(), 1.0) << "the writer's own pin is not forced";
  EXPECT_EQ(seen("r"), 9.0);
  EXPECT_EQ(published(*run.p, "mid"), 9.0);
  EXPECT_EQ(output(*run.p), 9.0);
}

TEST(Force, AnInputPinHoldsAfterItsInputCopy) {
  Plc run;
  set_input(*run.p, 1.0);
  ASSERT_TRUE(run.p->force("r.IN", "3").ok);
  run.scans(2);
  EXPECT_EQ(seen("r"), 3.0);
  EXPECT_EQ(published(*run.p, "mid"), 1.0) << "the tag feeding the pin is not forced";
  EXPECT_EQ(output(*run.p), 3.0);
}

TEST(Force, AnOutputPinHoldsAfterTheBlockExecutes) {
  Plc run;
  set_input(*run.p, 1.0);
  ASSERT_TRUE(run.p->force("a.OUT", "4").ok);
  run.scans(2);
  EXPECT_EQ(seen("a"), 1.0) << "the block itself computes as ever";
  EXPECT_EQ(published(*run.p, "mid"), 4.0) << "its output copy takes the forced value";
  EXPECT_EQ(seen("r"), 4.0);
  EXPECT_EQ(output(*run.p), 4.0);
  ASSERT_TRUE(run.p->unforce("a.OUT").ok);
  run.scans(1);
  EXPECT_EQ(seen("r"), 1.0) << "the block writes its output again at the next scan";
}

TEST(Force, ATagBoundToADriverOutputIsWrittenWithItsForcedValue) {
  Plc run;
  set_input(*run.p, 1.0);
  ASSERT_TRUE(run.p->force("actuator", "11").ok);
  run.scans(2);
  EXPECT_EQ(seen("r"), 1.0);
  EXPECT_EQ(output(*run.p), 11.0);
  EXPECT_EQ(published(*run.p, "actuator"), 11.0);
}

TEST(Force, WritesFromOutsideChangeNothingWhileForced) {
  Plc run;
  ASSERT_TRUE(run.p->force("setpoint", "2").ok);
  run.scans(1);
  Cell w;
  w.set<double>(8.0);
  ASSERT_TRUE(run.p->write_tag(*run.p->find_tag("setpoint"), 0, &w, 1));
  run.scans(2);
  EXPECT_EQ(seen("s"), 2.0);
  EXPECT_EQ(published(*run.p, "setpoint"), 2.0);
  // Released: a tag nothing in the scan writes keeps the forced value until something does.
  ASSERT_TRUE(run.p->unforce("setpoint").ok);
  run.scans(1);
  EXPECT_EQ(seen("s"), 2.0);
  ASSERT_TRUE(run.p->write_tag(*run.p->find_tag("setpoint"), 0, &w, 1));
  run.scans(1);
  EXPECT_EQ(seen("s"), 8.0);
}

TEST(Force, TakesEffectAtTheNextScanStartAndAForcedElementTakesANewValue) {
  Plc run;
  run.scans(1);
  auto first = run.p->force("levels[2]", "1.5");
  ASSERT_TRUE(first.ok) << first.error;
  EXPECT_EQ(first.ref, "levels[2]");
  EXPECT_EQ(first.previous, "");
  Cell v[3];
  run.p->read_tag(*run.p->find_tag("levels"), v);
  EXPECT_EQ(v[1].get<double>(), 0.0) << "queued, not yet held";
  run.scans(1);
  run.p->read_tag(*run.p->find_tag("levels"), v);
  EXPECT_EQ(v[1].get<double>(), 1.5);
  EXPECT_EQ(v[0].get<double>(), 0.0);
  auto second = run.p->force("levels[2]", "2.5");
  ASSERT_TRUE(second.ok);
  EXPECT_EQ(second.previous, "1.5");
  EXPECT_EQ(second.event_text(), "forced levels[2] to 2.5 (was forced to 1.5)");
  EXPECT_EQ(run.p->force_count(), 1u);
  run.scans(1);
  run.p->read_tag(*run.p->find_tag("levels"), v);
  EXPECT_EQ(v[1].get<double>(), 2.5);
}

TEST(Force, AnUnconnectedInputGetsItsConstantBackWhenReleased) {
  Plc run;
  ASSERT_TRUE(run.p->force("c.IN", "-1").ok);
  run.scans(2);
  EXPECT_EQ(seen("c"), -1.0);
  auto res = run.p->unforce("c.IN");
  ASSERT_TRUE(res.ok);
  EXPECT_EQ(res.event_text(), "unforced c.IN (was forced to -1)");
  run.scans(1);
  EXPECT_EQ(seen("c"), 7.0);
}

TEST(Force, ValuesAreParsedAsAProjectWritesThemWithUnits) {
  Plc run;
  auto res = run.p->force("setpoint", "1500 mm");
  ASSERT_TRUE(res.ok) << res.error;
  EXPECT_EQ(res.value, "1.5");
  run.scans(1);
  EXPECT_EQ(published(*run.p, "setpoint"), 1.5);
  auto bad = run.p->force("setpoint", "2 s");
  EXPECT_FALSE(bad.ok);
  EXPECT_NE(bad.error.find("value '2 s' for LREAL"), std::string::npos) << bad.error;
}

TEST(Force, RefusalsSayWhy) {
  Plc run;
  auto e = [&](const std::string& ref, const std::string& v) { return run.p->force(ref, v).error; };
  EXPECT_NE(e("nothing", "1").find("unknown tag"), std::string::npos);
  EXPECT_NE(e("a.NOPE", "1").find("has no pin 'NOPE'"), std::string::npos);
  EXPECT_NE(e("levels", "1").find("levels is an array of 3 elements: force one element, levels[i]"), std::string::npos);
  EXPECT_NE(e("levels[4]", "1").find("outside levels[1..3]"), std::string::npos);
  EXPECT_NE(e("mid", "abc").find("value 'abc'"), std::string::npos);
  EXPECT_EQ(run.p->unforce("mid").error, "mid is not forced");
  EXPECT_EQ(run.p->force_count(), 0u);
  EXPECT_EQ(run.p->forces_version(), 0u) << "a refusal changes nothing";
}

TEST(Force, AFullTableIsAClearError) {
  Plc run(project(", max_forces: 2"));
  ASSERT_TRUE(run.p->force("mid", "1").ok);
  ASSERT_TRUE(run.p->force("setpoint", "1").ok);
  auto third = run.p->force("actuator", "1");
  EXPECT_FALSE(third.ok);
  EXPECT_EQ(third.error, "2 elements are forced, the project's max_forces: unforce one first");
  EXPECT_TRUE(run.p->force("mid", "3").ok) << "a forced element takes a new value";
  ASSERT_TRUE(run.p->unforce("mid").ok);
  EXPECT_TRUE(run.p->force("actuator", "1").ok);
  run.scans(2);
  EXPECT_EQ(run.p->tasks[0]->force_table().size(), 2u);
}

TEST(Force, MaxForcesIsCheckedAtLoad) {
  LoadOptions o;
  o.blocks = &testing::test_blocks();
  auto r = load_project_text(project(", max_forces: 0"), "test.yaml", o);
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.diagnostics.list()[0].text().find("max_forces: 1..4096"), std::string::npos) << r.diagnostics.list()[0].text();
}

TEST(Force, ReadersSeeWhatIsForcedAndAtWhatValue) {
  Plc run;
  const auto v0 = run.p->forces_version();
  ASSERT_TRUE(run.p->force("r.IN", "3").ok);
  ASSERT_TRUE(run.p->force("actuator", "TRUE").ok == false);  // not an LREAL literal
  ASSERT_TRUE(run.p->force("actuator", "11").ok);
  EXPECT_GT(run.p->forces_version(), v0);
  auto list = run.p->forces();
  ASSERT_EQ(list.size(), 2u);
  EXPECT_EQ(list[0].ref, "actuator");
  EXPECT_EQ(list[0].value_text, "11");
  EXPECT_EQ(list[1].ref, "r.IN");
  EXPECT_EQ(list[1].task, "t");
  auto fv = run.p->forced_value(*run.p->resolve("actuator"));
  ASSERT_TRUE(fv);
  EXPECT_EQ(fv->get<double>(), 11.0);
  EXPECT_FALSE(run.p->forced_value(*run.p->resolve("mid")));
  auto all = run.p->unforce_all();
  ASSERT_EQ(all.size(), 2u);
  EXPECT_TRUE(all[0].ok && all[1].ok);
  EXPECT_EQ(run.p->force_count(), 0u);
  run.scans(1);
  EXPECT_EQ(run.p->tasks[0]->force_table().size(), 0u) << "released in one scan";
}

TEST(Force, AStoppedTaskRefusesForces) {
  Plc run;
  run.p->tasks[0]->stop_from_supervisor();
  auto res = run.p->force("mid", "1");
  EXPECT_FALSE(res.ok);
  EXPECT_EQ(res.error, "task t is stopped: a force would not take effect");
}

TEST(Force, NothingForcedLeavesEveryScanAsItWas) {
  // Bit for bit: a run that monitors pins, lists forces and is refused a
  // force sees exactly the values of a plain run.
  Plc plain;
  set_input(*plain.p, 1.25);
  plain.scans(50);
  const auto want = records();
  Plc other;
  set_input(*other.p, 1.25);
  Cell pin;
  for (int k = 0; k < 50; ++k) {
    other.p->read_value(*other.p->resolve("r.OUT"), &pin);
    EXPECT_FALSE(other.p->force("mid", "x").ok);
    other.p->forces();
    other.scans(1);
  }
  ASSERT_EQ(records().size(), want.size());
  for (std::size_t i = 0; i < want.size(); ++i) {
    EXPECT_EQ(records()[i].instance, want[i].instance);
    EXPECT_EQ(records()[i].in, want[i].in);
    EXPECT_EQ(records()[i].now_ns, want[i].now_ns);
  }
}

// Online change: forces on elements the new program has, with the same
// type, hold on; the others are dropped and reported.
TEST(Force, AnOnlineChangeKeepsForcesOnKeptElementsAndReportsTheDropped) {
  Plc run;
  set_input(*run.p, 1.0);
  ASSERT_TRUE(run.p->force("mid", "9").ok);
  ASSERT_TRUE(run.p->force("c.IN", "-1").ok);
  ASSERT_TRUE(run.p->force("levels[3]", "4").ok);
  run.scans(5);
  // The new program: c is gone, levels has become INT, mid and the rest stay.
  std::string next = project();
  next.replace(next.find("  - {name: c, type: RECORD, task: t, inputs: {IN: 7.0}}\n"),
               std::string("  - {name: c, type: RECORD, task: t, inputs: {IN: 7.0}}\n").size(), "");
  next.replace(next.find("ARRAY[1..3] OF LREAL"), std::string("ARRAY[1..3] OF LREAL").size(), "ARRAY[1..3] OF INT");
  auto to = load_test_project(next);
  ASSERT_TRUE(to);
  auto change = plan_change(*run.p, *to);
  change->switch_ns = run.t + 10'000'000;
  run.clock->begin_change(*change);
  ASSERT_EQ(change->forces.size(), 3u);
  EXPECT_EQ(change->forces[0].ref, "c.IN");
  EXPECT_FALSE(change->forces[0].kept);
  EXPECT_EQ(change->forces[0].detail, "unknown block instance 'c'");
  EXPECT_EQ(change->forces[1].ref, "levels[3]");
  EXPECT_FALSE(change->forces[1].kept);
  EXPECT_EQ(change->forces[1].detail, "type LREAL -> INT");
  EXPECT_TRUE(change->forces[2].kept);
  EXPECT_EQ(change_report(*change).back(), "force mid: kept (held at 9)");
  EXPECT_NE(change_summary(*change).find("forces: 1 kept, 2 dropped"), std::string::npos);
  EXPECT_EQ(run.p->force("setpoint", "1").error, "an online change is under way: force again once the new program runs");
  // A force given to the new program before the switch holds from the switch on.
  ASSERT_TRUE(to->force("actuator", "6").ok);
  run.scans(20);
  ASSERT_TRUE(run.clock->change_complete());
  EXPECT_EQ(&run.clock->program(), to.get());
  EXPECT_EQ(published(*to, "mid"), 9.0);
  EXPECT_EQ(seen("r"), 9.0);
  EXPECT_EQ(output(*to), 6.0);
  EXPECT_EQ(to->force_count(), 2u);
  EXPECT_EQ(to->tasks[0]->force_table().size(), 2u);
  ASSERT_TRUE(to->unforce("mid").ok);
  run.scans(1);
  EXPECT_EQ(seen("r"), 1.0);
}

}  // namespace
}  // namespace syncplc
