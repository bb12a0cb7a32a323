// The real-time runner with real threads. These tests assert behaviour, never
// timing (timing is tested in virtual time); they run under ThreadSanitizer.
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <thread>

#include "runtime/core/monotonic_clock.hpp"
#include "runtime/core/realtime.hpp"
#include "tests/realtime/quiet_options.hpp"
#include "tests/support/project_fixture.hpp"

namespace syncplc {
namespace {

// A fast task publishes four equal values; a slower task counts scans in
// which they differ; the test thread reads the published array concurrently
// and writes a setpoint through the queue.
const char* kRealtimeProject = R"(
tasks:
  - {name: fast, period: 200us, priority: 60}
  - {name: slow, period: 1ms, priority: 50}
tags:
  - {name: stamp, type: "ARRAY[0..3] OF LREAL", hmi: read}
  - {name: torn, type: INT, hmi: read}
  - {name: setpoint, type: LREAL, hmi: readwrite}
  - {name: echo, type: LREAL, hmi: read}
blocks:
  - {name: st, type: STAMP, task: fast}
  - {name: same01, type: EQ, task: slow}
  - {name: same23, type: EQ, task: slow}
  - {name: same03, type: EQ, task: slow}
  - {name: all_same, type: AND, task: slow}
  - {name: differ, type: NOT, task: slow}
  - {name: count, type: CTU, task: slow, inputs: {PV: 32767}}
  - {name: copy, type: MOVE, task: fast}
connections:
  - st.A -> stamp[0]
  - st.B -> stamp[1]
  - st.C -> stamp[2]
  - st.D -> stamp[3]
  - stamp[0] -> same01.IN1
  - stamp[1] -> same01.IN2
  - stamp[2] -> same23.IN1
  - stamp[3] -> same23.IN2
  - stamp[0] -> same03.IN1
  - stamp[3] -> same03.IN2
  - same01.OUT -> all_same.IN1
  - same23.OUT -> all_same.IN2
  - same03.OUT -> all_same.IN3
  - all_same.OUT -> differ.IN
  - differ.OUT -> count.CU
  - count.CV -> torn
  - setpoint -> copy.IN
  - copy.OUT -> echo
)";

TEST(Realtime, SnapshotsAreNeverTornAcrossThreadsAndQueuedWritesArrive) {
  auto p = load_test_project(kRealtimeProject);
  ASSERT_TRUE(p);
  RealtimeRunner runner(*p, quiet_options());
  runner.start();
  const Tag* stamp = p->find_tag("stamp");
  const Tag* setpoint = p->find_tag("setpoint");
  const Tag* echo = p->find_tag("echo");
  int torn_reads = 0, reads = 0;
  double last_written = 0;
  // 400 scans of fast and at least 200 reads, however long a loaded machine
  // takes; every wait below is for a condition, its time only a hang guard.
  const auto guard = std::chrono::steady_clock::now() + std::chrono::minutes(2);
  auto counted = [&] { return p->tasks[0]->stats.scans.load() >= 400 && reads >= 200; };
  while (!counted() && std::chrono::steady_clock::now() < guard) {
    Cell v[4];
    p->read_tag(*stamp, v);
    ++reads;
    if (!(v[0].get<double>() == v[1].get<double>() && v[1].get<double>() == v[2].get<double>() &&
          v[2].get<double>() == v[3].get<double>()))
      ++torn_reads;
    Cell w;
    last_written += 1;
    w.set<double>(last_written);
    while (!p->write_tag(*setpoint, 0, &w, 1)) std::this_thread::yield();
    std::this_thread::sleep_for(std::chrono::microseconds(100));
  }
  // The queue drains at the next scans: wait until every write was applied
  // and echoed, then stop.
  Cell seen;
  while (std::chrono::steady_clock::now() < guard &&
         (p->tasks[0]->stats.writes_applied.load() < static_cast<std::uint64_t>(last_written) ||
          (p->read_tag(*echo, &seen), seen.get<double>() != last_written)))
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  runner.request_stop();
  runner.join();
  EXPECT_FALSE(runner.running());
  EXPECT_GE(reads, 200);
  EXPECT_EQ(torn_reads, 0);
  Cell torn;
  p->read_tag(*p->find_tag("torn"), &torn);
  EXPECT_EQ(torn.get<std::int16_t>(), 0);
  Cell e;
  p->read_tag(*echo, &e);
  EXPECT_EQ(e.get<double>(), last_written);
  auto fast = p->tasks[0]->stats.summary();
  auto slow = p->tasks[1]->stats.summary();
  EXPECT_GT(fast.scans, 0u);
  EXPECT_GT(slow.scans, 0u);
  EXPECT_EQ(fast.writes_applied, static_cast<std::uint64_t>(last_written));
  // Every scan is accounted for: the grid points passed equal scans + skipped.
  EXPECT_GE(fast.exec.count, fast.scans - 1);
}

TEST(Realtime, WatchdogStopsATaskThatBurnsTooLong) {
  auto p = load_test_project(R"(
tasks:
  - {name: hog, period: 5ms, priority: 50, watchdog: {time: 500us, sensitivity: 1, action: stop}}
  - {name: fine, period: 1ms, priority: 40}
blocks:
  - {name: b, type: BURN, task: hog, inputs: {EXEC: 2ms}}
  - {name: idle, type: MOVE, task: fine, inputs: {IN: 1.0}}
)");
  ASSERT_TRUE(p);
  RealtimeRunner runner(*p, quiet_options());
  runner.start();
  // Until the watchdog stopped hog and fine ran a few scans (a hang guard only).
  const auto guard = std::chrono::steady_clock::now() + std::chrono::minutes(1);
  while ((!p->tasks[0]->stopped() || p->tasks[1]->stats.scans.load() < 5) && std::chrono::steady_clock::now() < guard)
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  runner.request_stop();
  runner.join();
  EXPECT_TRUE(p->tasks[0]->stopped());
  EXPECT_EQ(p->tasks[0]->stats.summary().scans, 1u);  // the first 2 ms scan tripped it
  EXPECT_EQ(p->tasks[0]->stats.summary().watchdog_trips, 1u);
  EXPECT_FALSE(p->tasks[1]->stopped());
  EXPECT_GT(p->tasks[1]->stats.summary().scans, 1u);
  // A loaded machine may also report the scan as an overrun; the trip must be there.
  Event e;
  bool tripped = false;
  while (p->tasks[0]->pop_event(e)) tripped |= e.kind == EventKind::WatchdogTrip;
  EXPECT_TRUE(tripped);
}

TEST(Realtime, StopIsPromptEvenForALongPeriod) {
  auto p = load_test_project(R"(
tasks: [{name: slow, period: 10s}]
blocks: [{name: m, type: MOVE, inputs: {IN: 1.0}}]
)");
  ASSERT_TRUE(p);
  RealtimeRunner runner(*p, quiet_options());
  runner.start();
  std::this_thread::sleep_for(std::chrono::milliseconds(50));
  auto t0 = std::chrono::steady_clock::now();
  runner.request_stop();
  runner.join();
  auto waited = std::chrono::steady_clock::now() - t0;
  // The stop does not sleep out the 10 s period (it polls every 100 ms):
  // one that did would wait 9.95 s; half the period is fifty polls.
  EXPECT_LT(waited, std::chrono::seconds(5));
  EXPECT_EQ(p->tasks[0]->stats.summary().scans, 1u);
}

// --align: the epoch sits on a whole multiple of the alignment on
// CLOCK_REALTIME, and the monotonic epoch the threads sleep to is the same
// instant (the two clocks' offset, read now, agrees to within a millisecond:
// no bound on speed, only on the two clocks being read a moment apart).
TEST(Realtime, AlignedEpochSitsOnTheRealtimeGrid) {
  auto p = load_test_project(R"(
tasks: [{name: t, period: 10ms}]
blocks: [{name: m, type: MOVE, inputs: {IN: 1.0}}]
)");
  ASSERT_TRUE(p);
  RealtimeRunner::Options o = quiet_options();
  o.align_ns = 50'000'000;
  RealtimeRunner runner(*p, o);
  runner.start();
  const std::int64_t offset_now = realtime_ns() - monotonic_ns();
  EXPECT_EQ(runner.epoch_realtime_ns() % o.align_ns, 0);
  EXPECT_NEAR(static_cast<double>(runner.epoch_realtime_ns() - runner.epoch_ns()), static_cast<double>(offset_now), 1e6);
  while (p->tasks[0]->stats.summary().scans < 3) std::this_thread::sleep_for(std::chrono::milliseconds(5));
  runner.request_stop();
  runner.join();
}

}  // namespace
}  // namespace syncplc
