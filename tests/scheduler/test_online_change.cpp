// Online change in virtual time (runtime/core/program_change.hpp): each task
// switches at its first release at or after T, keeps its grid and scan count,
// unchanged instances keep their state, tunable changes retune bumplessly,
// structural changes start fresh, and a change that changes nothing gives,
// scan by scan, the values of a run without a change.
#include <gtest/gtest.h>

#include <map>

#include "runtime/core/program_change.hpp"
#include "runtime/core/virtual_clock.hpp"
#include "tests/support/project_fixture.hpp"

namespace syncplc {
namespace {

using testing::records;

std::string project(const std::string& acc_params, const std::string& extra_tasks = "",
                    const std::string& extra_blocks = "") {
  return R"(
tasks:
  - {name: fast, period: 1ms}
  - {name: slow, period: 5ms, phase: 500us}
)" + extra_tasks + R"(
tags:
  - {name: total, type: LREAL}
  - {name: seen, type: LREAL}
blocks:
  - {name: acc, type: ACC, task: fast, params: {)" + acc_params + R"(}, inputs: {IN: 1.0}}
  - {name: rec, type: RECORD, task: slow}
)" + extra_blocks + R"(
connections:
  - acc.SUM -> total
  - total -> rec.IN
  - rec.OUT -> seen
)";
}

struct Change {
  std::unique_ptr<Program> a, b;
  std::unique_ptr<ProgramChange> change;
};

// Runs `first` until t0, changes to `second` with T = switch_ns, runs to `end`.
void run_with_change(Change& r, const std::string& first, const std::string& second, std::int64_t t0,
                     std::int64_t switch_ns, std::int64_t end, VirtualClock*& clock_out,
                     std::unique_ptr<VirtualClock>& clock) {
  r.a = load_test_project(first);
  ASSERT_TRUE(r.a);
  clock = std::make_unique<VirtualClock>(*r.a);
  clock->run_until(t0);
  r.b = load_test_project(second);
  ASSERT_TRUE(r.b);
  r.change = plan_change(*r.a, *r.b);
  r.change->switch_ns = switch_ns;
  clock->begin_change(*r.change);
  clock->run_until(end);
  clock_out = clock.get();
}

double tag(Program& p, const char* name) { return tag_cell(p, name).get<double>(); }

TEST(OnlineChange, AnUnchangedInstanceKeepsItsStateAndTheTaskItsGrid) {
  Change r;
  VirtualClock* c = nullptr;
  std::unique_ptr<VirtualClock> own;
  run_with_change(r, project("K: 1"), project("K: 1") + "# edited\n", 100'000'000, 120'000'000, 200'000'000, c, own);
  ASSERT_TRUE(c->change_complete());
  EXPECT_EQ(&c->program(), r.b.get());
  EXPECT_EQ(r.change->count(InstanceFate::Kept), 2u);
  // 200 scans of fast in 200 ms, none skipped or repeated; the sum never restarted.
  EXPECT_EQ(c->scans(0), 200u);
  EXPECT_EQ(tag(*r.b, "total"), 200.0);
  EXPECT_EQ(r.b->tasks[0]->stats.scans.load(), 200u) << "statistics go on";
}

TEST(OnlineChange, ATunableChangeRetunesWithoutLosingState) {
  Change r;
  VirtualClock* c = nullptr;
  std::unique_ptr<VirtualClock> own;
  run_with_change(r, project("K: 1"), project("K: 2"), 100'000'000, 120'000'000, 200'000'000, c, own);
  ASSERT_EQ(r.change->instances[0].name, "acc");
  EXPECT_EQ(r.change->instances[0].fate, InstanceFate::Retuned);
  EXPECT_EQ(r.change->instances[0].detail, "K 1 -> 2");
  // 120 scans at K = 1 (releases 0..119 ms), then 80 at K = 2.
  EXPECT_EQ(tag(*r.b, "total"), 120.0 + 2 * 80.0);
}

TEST(OnlineChange, AStructuralChangeStartsTheInstanceFresh) {
  Change r;
  VirtualClock* c = nullptr;
  std::unique_ptr<VirtualClock> own;
  run_with_change(r, project("K: 1"), project("K: 1, MODE: 1"), 100'000'000, 120'000'000, 200'000'000, c, own);
  EXPECT_EQ(r.change->instances[0].fate, InstanceFate::New);
  EXPECT_EQ(r.change->instances[0].detail, "MODE 0 -> 1");
  EXPECT_EQ(tag(*r.b, "total"), 80.0);
}

TEST(OnlineChange, ANoOpChangeGivesEveryScanTheValuesOfARunWithoutOne) {
  // The consumer (slow) reads the producer (fast) across the switch: LET and
  // mirroring make every value identical to a run without a change, at every
  // switch instant tried (on and off both grids).
  records().clear();
  auto plain = load_test_project(project("K: 1"));
  ASSERT_TRUE(plain);
  VirtualClock pc(*plain);
  pc.run_until(300'000'000);
  const auto want = records();
  for (std::int64_t T : {100'000'000LL, 100'500'000LL, 101'000'000LL, 100'250'000LL}) {
    records().clear();
    Change r;
    VirtualClock* c = nullptr;
    std::unique_ptr<VirtualClock> own;
    run_with_change(r, project("K: 1"), project("K: 1"), 90'000'000, T, 300'000'000, c, own);
    ASSERT_EQ(records().size(), want.size()) << "T " << T;
    for (std::size_t i = 0; i < want.size(); ++i) {
      EXPECT_EQ(records()[i].now_ns, want[i].now_ns) << "T " << T << " record " << i;
      EXPECT_EQ(records()[i].in, want[i].in) << "T " << T << " at " << want[i].now_ns;
      EXPECT_EQ(records()[i].scan, want[i].scan) << "T " << T;
    }
  }
}

TEST(OnlineChange, AddedRemovedAndRetimedTasks) {
  const std::string extra = "  - {name: extra, period: 2ms}\n";
  Change r;
  VirtualClock* c = nullptr;
  std::unique_ptr<VirtualClock> own;
  std::string second = project("K: 1", extra, "  - {name: acc2, type: ACC, task: extra, inputs: {IN: 1.0}}\n");
  // slow re-timed 5 ms -> 4 ms (same phase).
  second.replace(second.find("period: 5ms"), 11, "period: 4ms");
  run_with_change(r, project("K: 1"), second, 100'000'000, 120'000'000, 200'000'000, c, own);
  ASSERT_TRUE(c->change_complete());
  std::map<std::string, TaskFate> fate;
  for (const auto& t : r.change->tasks) fate[t.name] = t.fate;
  EXPECT_EQ(fate["fast"], TaskFate::Kept);
  EXPECT_EQ(fate["slow"], TaskFate::Retimed);
  EXPECT_EQ(fate["extra"], TaskFate::Added);
  // extra runs from T on its grid: releases 120, 122, ..., 198 ms.
  EXPECT_EQ(tag(*r.b, "total"), 200.0);
  auto acc2 = r.b->resolve("acc2.SUM");
  ASSERT_TRUE(acc2);
  EXPECT_EQ(r.b->live_cell(*acc2, ::syncplc::testing::image_key())->get<double>(), 40.0);

  // And back: extra removed, its last scan the one before T.
  auto third = load_test_project(project("K: 1"));
  auto change2 = plan_change(*r.b, *third);
  change2->switch_ns = 250'000'000;
  c->begin_change(*change2);
  c->run_until(300'000'000);
  ASSERT_TRUE(c->change_complete());
  bool removed = false;
  for (const auto& t : change2->tasks) removed |= t.name == "extra" && t.fate == TaskFate::Removed;
  EXPECT_TRUE(removed);
  EXPECT_EQ(tag(*third, "total"), 300.0);
  EXPECT_EQ(c->scans(0), 300u);
}

// A task whose period changes starts its new grid at the switch instant T,
// not at its first old release after T (issue 21: 1 s -> 10 ms lost up to a
// second of scans, uncounted).
std::string retimed_project(const char* period, const char* extra = "") {
  return std::string("tasks:\n  - {name: t, period: ") + period + "}\n" + extra +
         "blocks:\n  - {name: rec, type: RECORD, task: t, inputs: {IN: 1.0}}\n";
}

std::vector<std::int64_t> record_times() {
  std::vector<std::int64_t> out;
  for (const auto& r : records()) out.push_back(r.now_ns);
  return out;
}

TEST(OnlineChange, ARetimedTaskStartsItsNewGridAtTheSwitchInstant) {
  for (std::int64_t T : {2'500'000'000LL, 2'505'000'000LL}) {
    records().clear();
    auto a = load_test_project(retimed_project("1s"));
    VirtualClock c(*a);
    c.run_until(1'200'000'000);
    auto b = load_test_project(retimed_project("10ms"));
    auto change = plan_change(*a, *b);
    change->switch_ns = T;
    c.begin_change(*change);
    c.run_until(3'500'000'000);
    ASSERT_TRUE(c.change_complete());
    EXPECT_EQ(change->tasks[0].fate, TaskFate::Retimed);
    // Old scans at 0, 1 and 2 s; from the first 10 ms point at or after T on.
    const std::int64_t first_new = (T + 9'999'999) / 10'000'000 * 10'000'000;
    std::vector<std::int64_t> want{0, 1'000'000'000, 2'000'000'000};
    for (std::int64_t t = first_new; t < 3'500'000'000; t += 10'000'000) want.push_back(t);
    EXPECT_EQ(record_times(), want) << "T " << T;
    EXPECT_EQ(b->tasks[0]->stats.skipped.load(), 0u);
    // The first new scan's dt is the time since the last old one.
    EXPECT_EQ(records()[3].dt_ns, first_new - 2'000'000'000);
  }
}

TEST(OnlineChange, ARetimedTaskWhoseLastScanRanPastTCountsTheGapAsSkipped) {
  records().clear();
  // The old task's scan at 2 s takes 0.53 s (BURN): it ends at 2.53 s, past T = 2.5 s.
  auto a = load_test_project(std::string("tasks:\n  - {name: t, period: 1s}\n") +
                             "blocks:\n  - {name: rec, type: RECORD, task: t, inputs: {IN: 1.0}}\n"
                             "  - {name: b, type: BURN, task: t, inputs: {EXEC: 530ms}}\n");
  ASSERT_TRUE(a);
  VirtualClock c(*a);
  c.run_until(1'200'000'000);
  auto b = load_test_project(retimed_project("10ms"));
  auto change = plan_change(*a, *b);
  change->switch_ns = 2'500'000'000;
  c.begin_change(*change);
  c.run_until(3'000'000'000);
  ASSERT_TRUE(c.change_complete());
  const auto t = record_times();
  ASSERT_GE(t.size(), 4u);
  EXPECT_EQ(t[3], 2'530'000'000) << "the first new grid point after the old scan ended";
  EXPECT_EQ(b->tasks[0]->stats.skipped.load(), 3u) << "2.50, 2.51 and 2.52 s got no scan";
}

TEST(OnlineChange, AWriteQueuedToTheNewProgramTakesEffectAtTheNextScan) {
  Change r;
  r.a = load_test_project(project("K: 1"));
  VirtualClock c(*r.a);
  c.run_until(100'000'000);
  r.b = load_test_project(project("K: 1"));
  r.change = plan_change(*r.a, *r.b);
  r.change->switch_ns = 150'000'000;
  c.begin_change(*r.change);
  // An HMI writes `seen`'s source... the slow task's own tag, to the new program.
  const Tag* seen = r.b->find_tag("seen");
  Cell v;
  v.set<double>(-7.0);
  ASSERT_TRUE(r.b->write_tag(*seen, 0, &v, 1));
  c.run_until(100'500'000, true);  // slow's next scan (old program) applies it, then RECORD overwrites it
  EXPECT_EQ(r.b->tasks[1]->stats.writes_applied.load(), 0u);
  EXPECT_EQ(r.a->tasks[1]->stats.writes_applied.load(), 1u) << "applied by the old task, at its next scan";
}

}  // namespace
}  // namespace syncplc
