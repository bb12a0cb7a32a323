// The supervisor with real threads: a scan that never ends (a HANG block) is
// given up on, its task's drivers take their safe outputs while the scan
// thread is still stuck, the other task keeps running, and a stop reports the
// thread it cannot join. Asserts behaviour, not timing; runs under
// ThreadSanitizer.
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <thread>

#include "runtime/core/program_change.hpp"
#include "runtime/core/supervisor.hpp"
#include "runtime/io/memory_driver.hpp"
#include "runtime/io/safe_output_latch.hpp"
#include "tests/realtime/quiet_options.hpp"
#include "tests/support/project_fixture.hpp"

namespace syncplc {
namespace {

std::string project(const std::string& watchdog) {
  return R"(
tasks:
  - {name: stuck, period: 1ms, watchdog: )" + watchdog + R"(}
  - {name: other, period: 2ms}
tags:
  - {name: motor, type: BOOL, safe: FALSE}
  - {name: speed, type: LREAL, safe: 0.0}
  - {name: level, type: LREAL}
  - {name: beat, type: LREAL, task: other}
blocks:
  - {name: h, type: HANG, task: stuck}
  - {name: on, type: MOVE, datatype: BOOL, task: stuck, inputs: {IN: TRUE}}
  - {name: spd, type: MOVE, task: stuck, inputs: {IN: 12.5}}
  - {name: lvl, type: MOVE, task: stuck, inputs: {IN: 3.0}}
  - {name: b, type: MOVE, task: other, inputs: {IN: 1.0}}
connections:
  - on.OUT -> motor
  - spd.OUT -> speed
  - lvl.OUT -> level
  - b.OUT -> beat
drivers:
  - name: io
    type: memory
    task: stuck
    channels:
      - {name: motor, dir: out, type: BOOL}
      - {name: speed, dir: out, type: LREAL}
      - {name: level, dir: out, type: LREAL}
    bind: {motor: motor, speed: speed, level: level}
)";
}

template <class F>
bool eventually(F f, std::chrono::milliseconds limit = std::chrono::milliseconds(60000)) {  // a hang guard only
  const auto until = std::chrono::steady_clock::now() + limit;
  while (!f()) {
    if (std::chrono::steady_clock::now() > until) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  return true;
}

struct Outputs {
  bool motor;
  double speed, level;
};

Outputs outputs(Program& p) {
  auto* d = dynamic_cast<MemoryDriver*>(p.drivers[0].driver.get());
  Cell c;
  Outputs o;
  d->read_output(d->channel_index("motor"), &c);
  o.motor = c.get<bool>();
  d->read_output(d->channel_index("speed"), &c);
  o.speed = c.get<double>();
  d->read_output(d->channel_index("level"), &c);
  o.level = c.get<double>();
  return o;
}

std::vector<EventKind> kinds(Supervisor& s) {
  std::vector<EventKind> v;
  SupervisorEvent e;
  while (s.pop_event(e)) v.push_back(e.event.kind);
  return v;
}

class SupervisorTest : public ::testing::Test {
 protected:
  void TearDown() override {
    testing::hang_release().store(true);  // whatever happened, let the thread go
    if (runner) {
      runner->request_stop();
      runner->join();
    }
    testing::hang_armed().store(false);
    testing::hang_release().store(false);
  }
  void start(const std::string& watchdog) {
    program = load_test_project(project(watchdog));
    ASSERT_TRUE(program);
    std::string err;
    ASSERT_TRUE(program->open_drivers(&err)) << err;
    runner = std::make_unique<RealtimeRunner>(*program, quiet_options());
    supervisor = std::make_unique<Supervisor>(*program, *runner);
    runner->start();
    ASSERT_TRUE(eventually([&] { return outputs(*program).speed == 12.5; })) << "the stuck task never wrote";
  }
  std::unique_ptr<Program> program;
  std::unique_ptr<RealtimeRunner> runner;
  std::unique_ptr<Supervisor> supervisor;
};

TEST_F(SupervisorTest, AScanThatDoesNotEndIsGivenUpOnAndItsOutputsMadeSafe) {
  start("{time: 2ms, sensitivity: 2, action: stop}");
  EXPECT_EQ(Supervisor::hang_limit_ns(program->tasks[0]->config()), 4'000'000);
  testing::hang_armed().store(true);
  ASSERT_TRUE(eventually([&] {
    supervisor->check();
    return supervisor->hung(program->tasks[0].get());
  }));
  EXPECT_TRUE(program->tasks[0]->stopped());
  EXPECT_FALSE(program->tasks[1]->stopped());
  EXPECT_FALSE(supervisor->all_stopped());
  EXPECT_GT(runner->scan_running_ns(0), 0) << "the scan is still stuck";
  Outputs o = outputs(*program);
  EXPECT_FALSE(o.motor);
  EXPECT_EQ(o.speed, 0.0);
  EXPECT_EQ(o.level, 3.0) << "no safe value: held at the last value";
  EXPECT_EQ(kinds(*supervisor), (std::vector<EventKind>{EventKind::ScanHung, EventKind::SafeStateApplied}));
  const auto beats = program->tasks[1]->stats.scans.load();
  ASSERT_TRUE(eventually([&] { return program->tasks[1]->stats.scans.load() > beats + 5; })) << "the other task runs on";

  EXPECT_FALSE(supervisor->stop(50'000'000)) << "the stuck thread cannot be joined";
  EXPECT_TRUE(kinds(*supervisor).empty()) << "given up on once";

  // Released (a test can; a real hang never is), the scan ends late: its outputs must not undo the safe state.
  const auto scans = program->tasks[0]->stats.scans.load();
  testing::hang_release().store(true);
  ASSERT_TRUE(eventually([&] { return !runner->running(); }));
  runner->join();
  EXPECT_EQ(program->tasks[0]->stats.scans.load(), scans + 1) << "the late scan ends, and no other starts";
  o = outputs(*program);
  EXPECT_FALSE(o.motor);
  EXPECT_EQ(o.speed, 0.0);
}

TEST_F(SupervisorTest, ALogWatchdogReportsALongScanAndWaitsLongerBeforeGivingUp) {
  start("{time: 2ms, sensitivity: 1, action: log}");
  EXPECT_EQ(Supervisor::hang_limit_ns(program->tasks[0]->config()), 1'000'000'000);
  testing::hang_armed().store(true);
  std::vector<EventKind> seen;
  ASSERT_TRUE(eventually([&] {
    supervisor->check();
    for (auto k : kinds(*supervisor)) seen.push_back(k);
    return !seen.empty();
  }));
  EXPECT_EQ(seen, std::vector<EventKind>{EventKind::ScanHung});
  EXPECT_FALSE(supervisor->hung(program->tasks[0].get()));
  EXPECT_EQ(outputs(*program).speed, 12.5) << "reported only";
  supervisor->check();
  EXPECT_TRUE(kinds(*supervisor).empty()) << "once a scan";
  testing::hang_release().store(true);
  EXPECT_TRUE(supervisor->stop());
}

TEST_F(SupervisorTest, AStopOfHealthyTasksJoinsEveryThread) {
  start("{time: 50ms, sensitivity: 1, action: stop}");
  supervisor->check();
  EXPECT_TRUE(supervisor->stop());
  EXPECT_FALSE(runner->running());
  EXPECT_FALSE(supervisor->any_hung());
  EXPECT_TRUE(kinds(*supervisor).empty());
}

// Issue 21: a scan that hangs while an online change is under way, in the
// old task before its switch, whose driver the change replaces. The outputs
// made safe are those of the driver the stuck task really uses, not those of
// the new program's driver (which no task has used yet).
TEST_F(SupervisorTest, AScanThatHangsDuringAnOnlineChangeMakesTheDriverInUseSafe) {
  start("{time: 2ms, sensitivity: 2, action: stop}");
  // The same project with a driver whose settings differ (a spare channel):
  // the change replaces it, opened beside the running one as `run` does.
  std::string b = project("{time: 2ms, sensitivity: 2, action: stop}");
  b.replace(b.find("      - {name: level, dir: out, type: LREAL}"), 0, "      - {name: spare, dir: out, type: LREAL}\n");
  auto next = load_test_project(b);
  ASSERT_TRUE(next);
  auto change = plan_change(*program, *next);
  ASSERT_EQ(change->new_drivers.size(), 1u) << "the driver is replaced";
  std::string err;
  ASSERT_TRUE(next->drivers[0].driver->open(&err)) << err;
  change->switch_ns = runner->now_ns() + 60'000'000'000;  // far ahead: the old task hangs before its switch
  runner->begin_change(*change);
  supervisor->watch(*next);
  testing::hang_armed().store(true);
  ASSERT_TRUE(eventually([&] {
    supervisor->check();
    return supervisor->hung(program->tasks[0].get());
  }));
  const Outputs in_use = outputs(*program);
  EXPECT_FALSE(in_use.motor) << "the driver the stuck task uses took its safe outputs";
  EXPECT_EQ(in_use.speed, 0.0);
  EXPECT_EQ(outputs(*next).speed, 0.0);
  EXPECT_EQ(kinds(*supervisor), (std::vector<EventKind>{EventKind::ScanHung, EventKind::SafeStateApplied}));
  testing::hang_release().store(true);
  runner->request_stop();
  runner->join();
  runner.reset();
  next->drivers[0].driver->close();
}

TEST(SupervisorLimits, HangLimitOfTasksWithoutAStoppingWatchdog) {
  TaskConfig c;
  c.period_ns = 500'000'000;
  EXPECT_EQ(Supervisor::hang_limit_ns(c), 5'000'000'000) << "10 periods";
  c.period_ns = 1'000'000;
  EXPECT_EQ(Supervisor::hang_limit_ns(c), 1'000'000'000) << "at least 1 s";
  c.watchdog = true;
  c.watchdog_ns = 800'000'000;
  c.sensitivity = 3;
  c.action = WatchdogAction::Log;
  EXPECT_EQ(Supervisor::hang_limit_ns(c), 2'400'000'000) << "never before a log watchdog's limit";
  c.action = WatchdogAction::SafeStop;
  EXPECT_EQ(Supervisor::hang_limit_ns(c), 2'400'000'000);
}

TEST(SafeOutputLatch, NoWriteOverlapsOrFollowsTheEngagement) {
  // A scan thread writes a two-word value as fast as it can; the supervisor
  // engages and then writes its own: its value must be the last one and never
  // be half overwritten.
  for (int round = 0; round < 30; ++round) {
    SafeOutputLatch latch;
    std::atomic<std::uint64_t> word[2] = {0, 0};
    std::atomic<bool> done{false};
    std::thread scan([&] {
      for (std::uint64_t k = 1; !done.load(); ++k) {
        if (!latch.begin_write()) continue;
        word[0].store(k, std::memory_order_relaxed);
        word[1].store(k, std::memory_order_relaxed);
        latch.end_write();
      }
    });
    std::this_thread::yield();
    ASSERT_TRUE(latch.engage());
    word[0].store(0, std::memory_order_relaxed);
    word[1].store(0, std::memory_order_relaxed);
    for (int i = 0; i < 10; ++i) std::this_thread::yield();
    done.store(true);
    scan.join();
    EXPECT_EQ(word[0].load(), 0u);
    EXPECT_EQ(word[1].load(), 0u);
  }
}

TEST(SafeOutputLatch, GivesUpOnAWriteThatDoesNotEnd) {
  SafeOutputLatch latch;
  ASSERT_TRUE(latch.begin_write());  // a scan stuck inside write_outputs
  EXPECT_FALSE(latch.engage(std::chrono::milliseconds(5)));
  EXPECT_TRUE(latch.engaged());
  latch.end_write();
  EXPECT_FALSE(latch.begin_write());
}

}  // namespace
}  // namespace syncplc
