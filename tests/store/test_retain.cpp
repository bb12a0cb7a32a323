// Retain and persistent variables: which stored values come back at a warm,
// cold or origin start, and after the project changed; matched by name and
// type (block instances: type, datatype and state layout), never by a hash of
// the program. Each "start" loads the project file and restores from the
// database as `syncplc run` does; a "stop" is the retain job's final run.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <fstream>

#include "tests/support/image_key.hpp"
#include "runtime/core/monotonic_clock.hpp"
#include "runtime/core/program_change.hpp"
#include "runtime/core/virtual_clock.hpp"
#include "runtime/project/loader.hpp"
#include "runtime/store/retain.hpp"
#include "tests/store/store_test_util.hpp"

namespace syncplc::store {
namespace {

using ::testing::AllOf;
using ::testing::Contains;
using ::testing::HasSubstr;

struct Plc {
  LoadResult loaded;
  std::unique_ptr<Database> db;
  std::unique_ptr<RetainJob> job;

  Program& program() { return *loaded.program; }
  Cell* cell(const std::string& tag) {
    const Tag* t = program().find_tag(tag);
    return &program().tasks[t->owner]->image(::syncplc::testing::image_key())[t->cell];
  }
  std::int64_t dint(const std::string& tag) { return cell(tag)->get<std::int32_t>(); }
  // The scans released at 0 .. ns of virtual time.
  void scan(std::int64_t ns) { VirtualClock(program()).run_until(ns, true); }
  // A clean stop: the last scan's publication (real time publishes at the
  // end of the scan), then the job's final run takes the snapshots.
  void stop() {
    for (auto& t : program().tasks) t->publish();
    job->run(*db, monotonic_ns(), true);
  }
  const std::vector<std::string>& notices() const { return job->start_notices(); }
};

class Retain : public ::testing::Test {
 protected:
  std::string dir = testing::fresh_dir(::testing::UnitTest::GetInstance()->current_test_info()->name());
  std::string project = dir + "/p.yaml";
  std::string db_path = dir + "/plc.db";

  void write(const std::string& text) { std::ofstream(project, std::ios::trunc) << text; }
  Plc start(StartMode mode = StartMode::Warm) {
    Plc p;
    p.loaded = load_project(project);
    EXPECT_TRUE(p.loaded.ok()) << (p.loaded.diagnostics.empty() ? "" : p.loaded.diagnostics.list().front().text());
    std::string err;
    p.db = Database::open(db_path, nullptr, &err);
    EXPECT_TRUE(p.db) << err;
    p.job = std::make_unique<RetainJob>(p.program(), p.loaded.store, mode);
    EXPECT_TRUE(p.job->prepare(*p.db, &err)) << err;
    return p;
  }
};

constexpr const char* kBase = R"(
tasks: [{name: main, period: 1ms}]
tags:
  - {name: r, type: DINT, retain: true, init: 1}
  - {name: keep, type: DINT, persistent: true, init: 2}
  - {name: plain, type: DINT, init: 3}
)";

void set_values(Plc& p) {
  p.cell("r")->set<std::int32_t>(100);
  p.cell("keep")->set<std::int32_t>(200);
  p.cell("plain")->set<std::int32_t>(300);
  p.scan(2'000'000);
}

TEST_F(Retain, WarmStartOfTheSameProjectRestoresRetainAndPersistent) {
  write(kBase);
  {
    Plc a = start();
    set_values(a);
    a.stop();
  }
  Plc b = start();
  EXPECT_EQ(b.dint("r"), 100);
  EXPECT_EQ(b.dint("keep"), 200);
  EXPECT_EQ(b.dint("plain"), 3);  // not retained: its initial value
  EXPECT_THAT(b.notices(), Contains("retain: warm start: 2 of 2 retained values restored"));
}

TEST_F(Retain, AChangedProjectReinitialisesRetainAndKeepsPersistent) {
  write(kBase);
  {
    Plc a = start();
    set_values(a);
    a.stop();
  }
  write(std::string(kBase) + "  - {name: added, type: BOOL}\n");
  Plc b = start();
  EXPECT_EQ(b.dint("r"), 1);
  EXPECT_EQ(b.dint("keep"), 200);
  EXPECT_THAT(b.notices(), Contains(AllOf(HasSubstr("1 of 2 retained values restored"), HasSubstr("project changed"))));
  EXPECT_THAT(b.notices(), Contains(AllOf(HasSubstr("r: not restored"), HasSubstr("persistent"))));
  // The refused value is gone from the database too: a crash now brings back 1, not 100.
  b.job.reset();
  b.db.reset();
  Plc c = start();
  EXPECT_EQ(c.dint("r"), 1);
  EXPECT_EQ(c.dint("keep"), 200);
}

// "Changed" is the project store's content hash of every file the load
// read: an edit confined to an included file that declares no tag (only
// connections and blocks) is a changed project too; an unchanged one is not.
TEST_F(Retain, AnEditInAnIncludeWithoutTagsIsAChangedProject) {
  write(std::string(kBase) + "include: [logic.yaml]\n");
  std::ofstream(dir + "/logic.yaml") << "blocks: [{name: m, type: MOVE, datatype: DINT}]\n"
                                         "connections: [r -> m.IN, m.OUT -> plain]\n";
  {
    Plc a = start();
    EXPECT_EQ(a.loaded.store.content_hash.size(), 64u) << "SHA-256 in hex";
    set_values(a);
    a.stop();
  }
  {
    Plc same = start();
    EXPECT_EQ(same.dint("r"), 100) << "nothing changed: a warm start restores";
    same.stop();
  }
  std::ofstream(dir + "/logic.yaml", std::ios::trunc) << "blocks: [{name: m, type: MOVE, datatype: DINT}]\n"
                                                          "connections: [keep -> m.IN, m.OUT -> plain]\n";
  Plc b = start();
  EXPECT_EQ(b.dint("r"), 1);
  EXPECT_EQ(b.dint("keep"), 200);
  EXPECT_THAT(b.notices(), Contains(HasSubstr("project changed")));
}

TEST_F(Retain, ColdStartKeepsOnlyPersistentAndOriginNothing) {
  write(kBase);
  {
    Plc a = start();
    set_values(a);
    a.stop();
  }
  {
    Plc b = start(StartMode::Cold);
    EXPECT_EQ(b.dint("r"), 1);
    EXPECT_EQ(b.dint("keep"), 200);
    EXPECT_THAT(b.notices(), Contains(AllOf(HasSubstr("r: not restored"), HasSubstr("cold start"))));
  }
  {
    Plc c = start(StartMode::Origin);
    EXPECT_EQ(c.dint("r"), 1);
    EXPECT_EQ(c.dint("keep"), 2);
  }
  Plc d = start();  // the origin reset deleted the values: a warm start has nothing to restore
  EXPECT_EQ(d.dint("keep"), 2);
}

TEST_F(Retain, ATypeChangeIsNotRestoredAndTheLogSaysWhy) {
  write(kBase);
  {
    Plc a = start();
    set_values(a);
    a.stop();
  }
  write(R"(
tasks: [{name: main, period: 1ms}]
tags:
  - {name: r, type: DINT, retain: true, init: 1}
  - {name: keep, type: LINT, persistent: true, init: 2}
  - {name: plain, type: DINT, init: 3}
)");
  Plc b = start();
  EXPECT_EQ(b.cell("keep")->get<std::int64_t>(), 2);
  EXPECT_THAT(b.notices(), Contains("retain: keep: not restored: stored as DINT, now LINT"));
}

TEST_F(Retain, AnArrayOfAnotherLengthIsNotRestored) {
  write(R"(
tasks: [{name: main, period: 1ms}]
tags:
  - {name: table, type: "ARRAY[1..3] OF INT", persistent: true}
)");
  {
    Plc a = start();
    for (int k = 0; k < 3; ++k) a.cell("table")[k].set<std::int16_t>(static_cast<std::int16_t>(7 + k));
    a.scan(2'000'000);
    a.stop();
  }
  {
    Plc same = start();
    EXPECT_EQ(same.cell("table")[2].get<std::int16_t>(), 9);
  }
  write(R"(
tasks: [{name: main, period: 1ms}]
tags:
  - {name: table, type: "ARRAY[1..4] OF INT", persistent: true}
)");
  Plc b = start();
  EXPECT_EQ(b.cell("table")[0].get<std::int16_t>(), 0);
  EXPECT_THAT(b.notices(), Contains("retain: table: not restored: stored as ARRAY[1..3] OF INT, now ARRAY[1..4] OF INT"));
}

TEST_F(Retain, ARenamedVariableStartsFreshAndTheOldValueIsDropped) {
  write(kBase);
  {
    Plc a = start();
    set_values(a);
    a.stop();
  }
  write(R"(
tasks: [{name: main, period: 1ms}]
tags:
  - {name: r, type: DINT, retain: true, init: 1}
  - {name: kept, type: DINT, persistent: true, init: 2}
)");
  Plc b = start();
  EXPECT_EQ(b.dint("kept"), 2);
  EXPECT_THAT(b.notices(), Contains(HasSubstr("1 stored values of variables no longer retained dropped")));
  SQLite::Statement q(b.db->sql(), "SELECT count(*) FROM retain_value WHERE name = 'keep'");
  ASSERT_TRUE(q.executeStep());
  EXPECT_EQ(q.getColumn(0).getInt(), 0);
}

constexpr const char* kCounter = R"(
tasks: [{name: main, period: 1ms}]
tags:
  - {name: count, type: DINT}
blocks:
  - {name: last, type: UNIT_DELAY, datatype: DINT, retain: true}
  - {name: inc, type: ADD, datatype: DINT, inputs: {IN2: 1}}
connections:
  - last.OUT -> inc.IN1
  - inc.OUT -> count
  - count -> last.IN
)";

TEST_F(Retain, ARetainedBlockInstanceGoesOnFromItsState) {
  write(kCounter);
  {
    Plc a = start();
    a.scan(9'000'000);  // scans at 0 .. 9 ms: count 10
    EXPECT_EQ(a.dint("count"), 10);
    a.stop();
  }
  Plc b = start();
  EXPECT_THAT(b.notices(), Contains("retain: warm start: 1 of 1 retained values restored"));
  b.scan(0);  // one scan: the delay's restored state + 1
  EXPECT_EQ(b.dint("count"), 11);
}

TEST_F(Retain, ABlockStateOfAnotherDatatypeIsNotRestored) {
  write(R"(
tasks: [{name: main, period: 1ms}]
tags: [{name: pulse, type: BOOL}, {name: n, type: INT}]
blocks:
  - {name: c, type: CTU, persistent: true, inputs: {PV: 10}}
connections: [pulse -> c.CU, c.CV -> n]
)");
  {
    Plc a = start();
    for (int k = 0; k < 3; ++k) {
      a.cell("pulse")->set<bool>(k % 2 == 0);
      a.scan(0);
    }
    a.stop();
  }
  {
    Plc same = start();
    same.scan(0);
    EXPECT_EQ(same.cell("n")->get<std::int16_t>(), 2);
  }
  write(R"(
tasks: [{name: main, period: 1ms}]
tags: [{name: pulse, type: BOOL}, {name: n, type: DINT}]
blocks:
  - {name: c, type: CTU, datatype: DINT, persistent: true, inputs: {PV: 10}}
connections: [pulse -> c.CU, c.CV -> n]
)");
  Plc b = start();
  EXPECT_THAT(b.notices(), Contains("retain: c: not restored: stored as CTU<INT> state 1 (2 cells), now CTU<DINT> state 1 (2 cells)"));
}

TEST_F(Retain, ABlockWithoutStateCannotBeRetained) {
  write(R"(
tasks: [{name: main, period: 1ms}]
tags: [{name: x, type: DINT}]
blocks:
  - {name: inc, type: ADD, datatype: DINT, retain: true, inputs: {IN1: 1, IN2: 1}}
connections: [inc.OUT -> x]
)");
  auto r = load_project(project);
  ASSERT_FALSE(r.ok());
  EXPECT_THAT(r.diagnostics.list().front().text(), HasSubstr("p.yaml:5:52: inc (ADD) has no state to retain"));
}

TEST_F(Retain, OnlyChangedValuesAreWritten) {
  write(kBase);
  Plc a = start();
  a.stop();
  EXPECT_EQ(a.job->last_written(), 0u);  // what the start restored is already stored
  a.cell("r")->set<std::int32_t>(5);
  a.scan(2'000'000);
  a.stop();
  EXPECT_EQ(a.job->last_written(), 1u);
}

TEST_F(Retain, ARestartAfterAnOnlineChangeIsAWarmStartOfTheNewProject) {
  write(kBase);
  Plc a = start();
  set_values(a);
  a.stop();
  // The online change: the edited file is loaded and the job follows it.
  write(std::string(kBase) + "  - {name: added, type: BOOL}\n");
  LoadResult next = load_project(project);
  ASSERT_TRUE(next.ok());
  // What the handover carries over, and a change after it.
  next.program->tasks[0]->image(::syncplc::testing::image_key())[next.program->find_tag("keep")->cell].set<std::int32_t>(200);
  next.program->tasks[0]->image(::syncplc::testing::image_key())[next.program->find_tag("r")->cell].set<std::int32_t>(101);
  next.program->tasks[0]->publish();
  a.job->switch_program(*next.program, next.store);
  a.job->run(*a.db, monotonic_ns(), true);
  EXPECT_EQ(a.job->last_written(), 1u);  // r changed; keep was stored before the change
  a.job.reset();
  a.db.reset();
  Plc b = start();  // the edited file again: not a changed project
  EXPECT_EQ(b.dint("r"), 101);
  EXPECT_EQ(b.dint("keep"), 200);
}

// Issue 21: from the moment an online change begins the retain job reads
// the new program's snapshots; before the old task first mirrors into them
// they must already hold the running state, never the fresh instance's
// initial one (a kill -9 in that window restarted the counter from 0).
TEST_F(Retain, AnOnlineChangeNeverLetsTheJobStoreAFreshInstancesInitialState) {
  write(kCounter);
  Plc a = start();
  VirtualClock clock(a.program());
  clock.run_until(10'000'000);  // scans at 0 .. 9 ms: count 10
  ASSERT_EQ(a.dint("count"), 10);
  a.job->run(*a.db, monotonic_ns(), false);  // stored: the delay's state 10
  write(std::string(kCounter) + "# edited\n");
  LoadResult next = load_project(project);
  ASSERT_TRUE(next.ok());
  auto change = plan_change(a.program(), *next.program);
  change->switch_ns = 20'000'000;
  clock.begin_change(*change);
  a.job->switch_program(*next.program, next.store);
  a.job->run(*a.db, monotonic_ns() + 10'000'000'000, false);  // before the old task's next scan
  // kill -9 here: the next start restores what the job stored.
  a.job.reset();
  a.db.reset();
  Plc b = start();
  b.scan(0);
  EXPECT_EQ(b.dint("count"), 11) << "the stored state was the fresh instance's, not the running one's";
}

// Issue 21: a persistent instance re-created by an online change (a
// structural parameter changed) keeps its state, as a stop and start of the
// changed project would have restored it.
TEST_F(Retain, APersistentInstanceRecreatedByAnOnlineChangeKeepsItsState) {
  const auto pid = [](int anti_windup) {
    return std::string(R"(
tasks: [{name: main, period: 1ms}]
tags: [{name: y, type: LREAL}]
blocks:
  - {name: pid, type: PID, persistent: true, params: {Kp: 1.0, Ti: 1.0, anti_windup: )") +
           std::to_string(anti_windup) + R"(}, inputs: {setpoint: 1.0, actual: 0.0}}
connections: [pid.y -> y]
)";
  };
  write(pid(1));
  Plc a = start();
  VirtualClock clock(a.program());
  clock.run_until(100'000'000);  // 100 scans: the integral holds 0.1 (e = 1, Ti = 1 s)
  const double before = a.cell("y")->get<double>();
  ASSERT_GT(before, 1.05);
  write(pid(0));
  LoadResult next = load_project(project);
  ASSERT_TRUE(next.ok());
  auto change = plan_change(a.program(), *next.program);
  ASSERT_EQ(change->instances[0].fate, InstanceFate::New);
  EXPECT_THAT(change->instances[0].detail, HasSubstr("persistent state carried over"));
  change->switch_ns = 110'000'000;
  clock.begin_change(*change);
  clock.run_until(111'000'000);
  ASSERT_TRUE(clock.change_complete());
  const Tag* y = next.program->find_tag("y");
  const double after = next.program->tasks[0]->image(::syncplc::testing::image_key())[y->cell].get<double>();
  EXPECT_GT(after, before) << "the integral went on; a fresh PID would give 1.001";
}

TEST_F(Retain, ResetColdDeletesRetainValuesAndOriginEverything) {
  write(kBase);
  {
    Plc a = start();
    set_values(a);
    a.stop();
  }
  {
    std::string err;
    auto db = Database::open(db_path, nullptr, &err);
    EXPECT_EQ(reset_retain(db->sql(), StartMode::Cold), 1);
  }
  {
    Plc b = start();
    EXPECT_EQ(b.dint("r"), 1);
    EXPECT_EQ(b.dint("keep"), 200);
  }
  std::string err;
  auto db = Database::open(db_path, nullptr, &err);
  EXPECT_EQ(reset_retain(db->sql(), StartMode::Origin), 2);
}

// An ST instance with RETAIN variables is a retained instance by itself
// (IEC 61131-3 VAR RETAIN): those come back at a warm start, the others start
// at their initial values; a RETAIN FB instance inside keeps all of it.
TEST_F(Retain, StRetainVariablesComeBackAtAWarmStart) {
  std::ofstream(dir + "/count.st") << R"(
FUNCTION_BLOCK Tally
VAR_OUTPUT n : DINT; END_VAR
n := n + 1;
END_FUNCTION_BLOCK
PROGRAM Counting
VAR RETAIN count : DINT; kept : Tally; END_VAR
VAR plain : DINT := 5; t : Tally; END_VAR
count := count + 1;
plain := plain + 1;
kept();
t();
END_PROGRAM
)";
  write(R"(
tasks: [{name: main, period: 1ms}]
sources: [count.st]
programs: [{name: counting, type: Counting}]
)");
  auto var = [](Plc& p, const std::string& ref) {
    const auto r = p.program().resolve(ref);
    EXPECT_TRUE(r) << ref;
    return p.program().tasks[r->task]->image(::syncplc::testing::image_key())[r->cell].get<std::int32_t>();
  };
  {
    Plc a = start();
    a.scan(9'000'000);  // 10 scans
    EXPECT_EQ(var(a, "counting.count"), 10);
    a.stop();
  }
  Plc b = start();
  EXPECT_EQ(var(b, "counting.count"), 10);
  EXPECT_EQ(var(b, "counting.kept.n"), 10);
  EXPECT_EQ(var(b, "counting.plain"), 5);  // not retained: its initial value
  EXPECT_EQ(var(b, "counting.t.n"), 0);
  b.scan(0);
  EXPECT_EQ(var(b, "counting.count"), 11);
}

}  // namespace
}  // namespace syncplc::store
