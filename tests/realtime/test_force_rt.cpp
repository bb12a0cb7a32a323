// Forcing and pin monitoring from other threads while the real-time runner
// scans (runtime/core/force_table.hpp, pin_monitor.hpp). Behaviour only, no
// timing; run under ThreadSanitizer: the registry, the queue and the pin
// monitor's triple buffer are the only ways between the threads.
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <thread>

#include "runtime/core/realtime.hpp"
#include "tests/realtime/quiet_options.hpp"
#include "tests/support/project_fixture.hpp"

namespace syncplc {
namespace {

const char* kProject = R"(
tasks:
  - {name: fast, period: 200us, priority: 60}
  - {name: slow, period: 1ms, priority: 50}
tags:
  - {name: count, type: LREAL, hmi: read}
  - {name: setpoint, type: LREAL, hmi: readwrite}
  - {name: echo, type: LREAL, hmi: read}
blocks:
  - {name: acc, type: ACC, task: fast, inputs: {IN: 1.0}}
  - {name: copy, type: MOVE, task: slow}
connections:
  - acc.SUM -> count
  - setpoint -> copy.IN
  - copy.OUT -> echo
)";

// Waits until pred() holds; the minute is only a guard against a hang.
template <class F>
bool eventually(F pred) {
  auto until = std::chrono::steady_clock::now() + std::chrono::minutes(1);
  while (std::chrono::steady_clock::now() < until) {
    if (pred()) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  return pred();
}

double tag(Program& p, const char* name) {
  Cell c;
  p.read_tag(*p.find_tag(name), &c);
  return c.get<double>();
}

TEST(RealtimeForce, ForcesAndPinReadsFromOtherThreadsWhileTasksRun) {
  auto p = load_test_project(kProject);
  ASSERT_TRUE(p);
  RealtimeRunner runner(*p, quiet_options());
  runner.start();

  // A reader thread watches the forced flags and the pins the whole time.
  std::atomic<bool> stop{false};
  std::atomic<int> flagged{0}, pin_reads{0};
  std::thread reader([&] {
    const auto sum = *p->resolve("acc.SUM");
    const auto echo = *p->resolve("echo");
    double last = -1;
    while (!stop.load()) {
      Cell v;
      if (p->read_value(sum, &v)) {
        if (v.get<double>() < last) ADD_FAILURE() << "a pin went back in time: " << v.get<double>() << " < " << last;
        last = v.get<double>();
        pin_reads.fetch_add(1);
      }
      if (p->forced_value(echo)) flagged.fetch_add(1);
      for (const auto& f : p->forces()) (void)f.value_text;
      std::this_thread::sleep_for(std::chrono::microseconds(200));
    }
  });

  // A forced tag holds against the program (count grows every scan) ...
  ASSERT_TRUE(p->force("count", "-5").ok);
  EXPECT_TRUE(eventually([&] { return tag(*p, "count") == -5.0; }));
  std::this_thread::sleep_for(std::chrono::milliseconds(20));
  EXPECT_EQ(tag(*p, "count"), -5.0);
  // ... and against outside writes; a forced output pin feeds its tag.
  ASSERT_TRUE(p->force("echo", "42").ok);
  ASSERT_TRUE(p->force("copy.OUT", "43").ok);  // pin and tag: the tag's own force wins, it is applied after
  Cell w;
  w.set<double>(1.0);
  for (int k = 0; k < 50; ++k) {
    while (!p->write_tag(*p->find_tag("setpoint"), 0, &w, 1)) std::this_thread::yield();
    std::this_thread::sleep_for(std::chrono::microseconds(300));
  }
  EXPECT_TRUE(eventually([&] { return tag(*p, "echo") == 42.0; }));
  // Pins move while monitored.
  EXPECT_TRUE(eventually([&] {
    Cell a, b;
    if (!p->read_value(*p->resolve("acc.SUM"), &a)) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
    return p->read_value(*p->resolve("acc.SUM"), &b) && b.get<double>() > a.get<double>();
  }));

  const auto released = p->unforce_all();
  EXPECT_EQ(released.size(), 3u);
  EXPECT_TRUE(eventually([&] { return tag(*p, "count") > 0 && tag(*p, "echo") == 1.0; }))
      << "the program writes them again";
  stop = true;
  reader.join();
  runner.request_stop();
  runner.join();
  EXPECT_GT(flagged.load(), 0);
  EXPECT_GT(pin_reads.load(), 10);
  EXPECT_EQ(p->force_count(), 0u);
}

}  // namespace
}  // namespace syncplc
