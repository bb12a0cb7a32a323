// Watchdog and overrun handling in virtual time. BURN blocks consume virtual
// execution time, set per scan through the tag `burn`.
#include <gtest/gtest.h>

#include "runtime/core/virtual_clock.hpp"
#include "runtime/io/memory_driver.hpp"
#include "runtime/project/report.hpp"
#include "tests/support/project_fixture.hpp"

namespace syncplc {
namespace {

using testing::records;

constexpr std::int64_t ms = 1'000'000;

std::string project(const std::string& task_extra) {
  return R"(
tasks:
  - {name: t, period: 10ms, )" + task_extra + R"(}
tags:
  - {name: burn, type: TIME}
  - {name: cmd, type: BOOL, init: TRUE}
  - {name: motor, type: BOOL, safe: FALSE}
  - {name: speed, type: LREAL, safe: 0.0}
blocks:
  - {name: r, type: RECORD}
  - {name: load, type: BURN}
  - {name: drive, type: MOVE}
  - {name: spd, type: MOVE, inputs: {IN: 12.5}}
connections:
  - burn -> load.EXEC
  - cmd -> drive.IN
  - drive.OUT -> motor
  - spd.OUT -> speed
drivers:
  - name: io
    type: memory
    channels: [{name: motor, dir: out, type: BOOL}]
    bind: {motor: motor}
)";
}

// Runs scan by scan, setting the burn time of scan n to burn_of(n).
template <class F>
void run_scans(Program& p, VirtualClock& clock, int n, F burn_of) {
  for (int k = 0; k < n; ++k) {
    clock.run_until(k * 10 * ms, false);
    tag_cell(p, "burn").set<std::int64_t>(burn_of(k));
    clock.run_until(k * 10 * ms, true);
  }
}

std::vector<EventKind> events_of(Program& p) {
  std::vector<EventKind> v;
  Event e;
  while (p.tasks[0]->pop_event(e)) v.push_back(e.kind);
  return v;
}

TEST(Watchdog, TheNthConsecutiveOverrunTripsAndStopsTheTask) {
  records().clear();
  auto p = load_test_project(project("watchdog: {time: 2ms, sensitivity: 3, action: stop}"));
  ASSERT_TRUE(p);
  VirtualClock clock(*p);
  // Scans 5, 6, 7 take 3 ms (> 2 ms): the third trips at its end.
  run_scans(*p, clock, 20, [](int k) { return k >= 5 ? 3 * ms : 0; });
  auto s = p->tasks[0]->stats.summary();
  EXPECT_EQ(s.scans, 8u);
  EXPECT_EQ(s.watchdog_trips, 1u);
  EXPECT_TRUE(p->tasks[0]->stopped());
  EXPECT_EQ(records().size(), 8u);
  EXPECT_EQ(records().back().now_ns, 70 * ms);
  auto ev = events_of(*p);
  ASSERT_EQ(ev.size(), 2u);
  EXPECT_EQ(ev[0], EventKind::WatchdogTrip);
  EXPECT_EQ(ev[1], EventKind::TaskStopped);
}

TEST(Watchdog, AnInterruptedSeriesDoesNotTrip) {
  auto p = load_test_project(project("watchdog: {time: 2ms, sensitivity: 3, action: stop}"));
  ASSERT_TRUE(p);
  VirtualClock clock(*p);
  // Two long scans, one short, two long, one short ...: never three in a row.
  run_scans(*p, clock, 30, [](int k) { return k % 3 == 2 ? 0 : 3 * ms; });
  auto s = p->tasks[0]->stats.summary();
  EXPECT_EQ(s.scans, 30u);
  EXPECT_EQ(s.watchdog_trips, 0u);
  EXPECT_FALSE(p->tasks[0]->stopped());
}

TEST(Watchdog, OneScanLongerThanTimeTimesSensitivityTripsAtOnce) {
  auto p = load_test_project(project("watchdog: {time: 2ms, sensitivity: 3, action: stop}"));
  ASSERT_TRUE(p);
  VirtualClock clock(*p);
  // 6 ms = time × sensitivity does not trip by itself; 6.001 ms does.
  run_scans(*p, clock, 5, [](int k) { return k == 2 ? 6 * ms : 0; });
  EXPECT_EQ(p->tasks[0]->stats.summary().watchdog_trips, 0u);
  run_scans(*p, clock, 20, [](int k) { return k == 7 ? 6 * ms + 1000 : 0; });
  auto s = p->tasks[0]->stats.summary();
  EXPECT_EQ(s.watchdog_trips, 1u);
  EXPECT_EQ(s.scans, 8u);
  EXPECT_TRUE(p->tasks[0]->stopped());
}

TEST(Watchdog, ActionLogKeepsRunningAndCountsEveryTrip) {
  auto p = load_test_project(project("watchdog: {time: 2ms, sensitivity: 3, action: log}"));
  ASSERT_TRUE(p);
  VirtualClock clock(*p);
  // Ten long scans in a row (5..14): trips after the 3rd, 6th and 9th.
  run_scans(*p, clock, 30, [](int k) { return k >= 5 && k < 15 ? 3 * ms : 0; });
  auto s = p->tasks[0]->stats.summary();
  EXPECT_EQ(s.scans, 30u);
  EXPECT_EQ(s.watchdog_trips, 3u);
  EXPECT_FALSE(p->tasks[0]->stopped());
  auto ev = events_of(*p);
  EXPECT_EQ(std::count(ev.begin(), ev.end(), EventKind::WatchdogTrip), 3);
  EXPECT_EQ(std::count(ev.begin(), ev.end(), EventKind::TaskStopped), 0);
}

TEST(Watchdog, SafeStopDrivesOutputsToTheirSafeValuesThenStops) {
  auto p = load_test_project(project("watchdog: {time: 2ms, sensitivity: 1, action: safe_stop}"));
  ASSERT_TRUE(p);
  auto& io = dynamic_cast<MemoryDriver&>(*p->drivers[0].driver);
  VirtualClock clock(*p);
  run_scans(*p, clock, 3, [](int) { return 0; });
  Cell out;
  io.read_output(0, &out);
  EXPECT_TRUE(out.get<bool>());  // running: motor on
  Cell v;
  p->read_tag(*p->find_tag("speed"), &v);
  EXPECT_EQ(v.get<double>(), 12.5);
  run_scans(*p, clock, 10, [](int k) { return k == 4 ? 5 * ms : 0; });
  EXPECT_TRUE(p->tasks[0]->stopped());
  io.read_output(0, &out);
  EXPECT_FALSE(out.get<bool>());  // the driver got the safe value
  p->read_tag(*p->find_tag("motor"), &v);
  EXPECT_FALSE(v.get<bool>());     // and the published tag shows it
  p->read_tag(*p->find_tag("speed"), &v);
  EXPECT_EQ(v.get<double>(), 0.0);
  auto ev = events_of(*p);
  EXPECT_EQ(ev, (std::vector<EventKind>{EventKind::WatchdogTrip, EventKind::SafeStateApplied, EventKind::TaskStopped}));
  EXPECT_EQ(p->tasks[0]->stats.summary().scans, 5u);
}

// Runs 80 ms of a 10 ms task whose scan at 10 ms takes 25 ms (it ends at 35 ms);
// returns the planned release of every scan, in ms.
std::vector<std::int64_t> planned_around_one_long_scan(Program& p) {
  records().clear();
  VirtualClock clock(p);
  clock.run_until(10 * ms);
  tag_cell(p, "burn").set<std::int64_t>(25 * ms);
  clock.run_until(10 * ms, true);
  tag_cell(p, "burn").set<std::int64_t>(0);
  clock.run_until(80 * ms);
  std::vector<std::int64_t> planned;
  for (const auto& r : records()) planned.push_back(r.now_ns / ms);
  return planned;
}

TEST(Overrun, SkipGoesToTheNextGridPointAfterTheLateScan) {
  auto p = load_test_project(project("missed_cycles: skip"));
  ASSERT_TRUE(p);
  // 20 and 30 are skipped.
  EXPECT_EQ(planned_around_one_long_scan(*p), (std::vector<std::int64_t>{0, 10, 40, 50, 60, 70}));
  auto s = p->tasks[0]->stats.summary();
  EXPECT_EQ(s.overruns, 1u);
  EXPECT_EQ(s.skipped, 2u);
  EXPECT_EQ(s.jitter.max, 0);  // every scan started on its grid point
  EXPECT_EQ(records()[2].dt_ns, 30 * ms);  // IEC time follows real time across the gap
}

TEST(Overrun, ImmediateRunsOnceAtOnceThenReturnsToTheGrid) {
  auto p = load_test_project(project("missed_cycles: immediate"));
  ASSERT_TRUE(p);
  // One catch-up scan (planned 30 ms, started at 35 ms), never a burst for 20 and 30.
  EXPECT_EQ(planned_around_one_long_scan(*p), (std::vector<std::int64_t>{0, 10, 30, 40, 50, 60, 70}));
  auto s = p->tasks[0]->stats.summary();
  EXPECT_EQ(s.overruns, 1u);
  EXPECT_EQ(s.skipped, 1u);
  EXPECT_EQ(s.jitter.max, 5 * ms);
  EXPECT_EQ(s.exec.max, 25 * ms);
}

TEST(Overrun, AScanEndingExactlyOnTheNextReleaseIsNotAnOverrun) {
  auto p = load_test_project(project("missed_cycles: skip"));
  ASSERT_TRUE(p);
  VirtualClock clock(*p);
  tag_cell(*p, "burn").set<std::int64_t>(10 * ms);
  clock.run_until(100 * ms);
  auto s = p->tasks[0]->stats.summary();
  EXPECT_EQ(s.scans, 10u);
  EXPECT_EQ(s.overruns, 0u);
  EXPECT_EQ(s.jitter.max, 0);
}

// Issue 21: an overrun caused by a late start (a busy CPU in real time) is
// reported as such, not as a scan that "overran its period" in 200 µs.
TEST(Overrun, ALateStartIsReportedAsTheCause) {
  auto p = load_test_project(project("missed_cycles: skip"));
  ASSERT_TRUE(p);
  Task& t = *p->tasks[0];
  // Released at 0, started 9.9 ms late, a 0.2 ms scan: it ends after the release at 10 ms.
  t.account(0, 0, 9'900'000, 10'100'000);
  Event e;
  ASSERT_TRUE(t.pop_event(e));
  EXPECT_EQ(e.kind, EventKind::ScanLate);
  EXPECT_EQ(event_kind_name(e.kind), "overrun") << "logged with the other overruns";
  EXPECT_DOUBLE_EQ(e.value, 0.0099);
  EXPECT_EQ(format_event(*p, e), "[0.000000s] overrun        t: scan started late and ended after its next release (started 9.9ms after its release)");
  // A scan on time ends the series of overruns; then one longer than its
  // period is an overrun of its own.
  t.account(1, 10'000'000, 10'100'000, 10'200'000);
  EXPECT_FALSE(t.pop_event(e));
  t.account(2, 20'000'000, 20'000'000, 45'000'000);
  ASSERT_TRUE(t.pop_event(e));
  EXPECT_EQ(e.kind, EventKind::ScanOverrun);
  EXPECT_EQ(format_event(*p, e), "[0.020000s] overrun        t: scan overran its period (scan took 25ms)");
}

}  // namespace
}  // namespace syncplc
