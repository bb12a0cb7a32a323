// One timing semantics: the same project run by the real-time scheduler (a
// thread per task, on however many CPUs) and by the virtual clock gives the
// same values, scan by scan (logical execution time, snapshot_channel.hpp).
// The real-time side is a trace the running program keeps (LOG blocks write
// (release time, value) into memory sized at load); nothing here asserts on
// wall-clock timing: the real-time run lasts a number of scans, not seconds.
// A value may differ only where the run itself counted the reason for that
// difference — on a quiet machine, none: an older producer scan's value only
// where the producer overran or skipped a scan, a newer one only where the
// consumer counted a late read (it started after the producer's next scan
// was visible too, snapshot_channel.hpp); and at most a few per reason. A
// loaded machine makes the run longer, not the check looser.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <thread>

#include "runtime/core/realtime.hpp"
#include "runtime/core/virtual_clock.hpp"
#include "tests/realtime/quiet_options.hpp"
#include "tests/support/project_fixture.hpp"

namespace syncplc {
namespace {

using testing::LogBlock;

// fast (1 ms) publishes its release time (STAMP: ms), so a value names the
// producer scan it came from and a skipped scan changes only the values near
// it; mid (2 ms, harmonic) and odd (3 ms, phase
// 0.25 ms, non-harmonic, higher priority than the producer) read the count;
// mid doubles what it read, which odd reads too (a chain of two exchanges).
const char* kLetProject = R"(
tasks:
  - {name: fast, period: 1ms, priority: 60}
  - {name: mid, period: 2ms, priority: 50}
  - {name: odd, period: 3ms, phase: 250us, priority: 70}
tags:
  - {name: count, type: LREAL}
  - {name: doubled, type: LREAL}
blocks:
  - {name: st, type: STAMP, task: fast}
  - {name: mid_log, type: LOG, task: mid}
  - {name: twice, type: MUL, task: mid, inputs: {IN2: 2.0}}
  - {name: odd_log, type: LOG, task: odd}
  - {name: odd_log2, type: LOG, task: odd}
connections:
  - st.A -> count
  - count -> mid_log.IN
  - count -> odd_log.IN
  - mid_log.OUT -> twice.IN1
  - twice.OUT -> doubled
  - doubled -> odd_log2.IN
)";

std::vector<LogBlock::Sample> samples(Program& p, const std::string& instance) {
  auto [task, pos] = p.instances.at(instance);
  return static_cast<const LogBlock&>(*p.tasks[task]->blocks[pos].block).samples();
}

TEST(LetRealtime, RealTimeGivesTheVirtualClocksValuesScanByScan) {
  auto rt = load_test_project(kLetProject);
  ASSERT_TRUE(rt);
  {
    auto options = quiet_options();
    options.start_delay_ns = 50'000'000;  // every thread up before the first release
    RealtimeRunner runner(*rt, options);
    runner.start();
    // 750 scans of mid (1.5 s on a quiet machine); the guard only ends a hang.
    const auto guard = std::chrono::steady_clock::now() + std::chrono::minutes(2);
    while (rt->tasks[1]->stats.scans.load() < 750 && std::chrono::steady_clock::now() < guard)
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    runner.request_stop();
    runner.join();
  }
  ASSERT_EQ(rt->tasks[1]->config().name, "mid");
  ASSERT_GE(rt->tasks[1]->stats.scans.load(), 750u) << "the real-time run hung";
  std::uint64_t reasons = 0;
  for (const auto& t : rt->tasks) {
    auto s = t->stats.summary();
    reasons += s.overruns + s.late_reads + s.skipped;
  }
  // Per task (fast 0, mid 1, odd 2): a producer behind (overran, skipped),
  // a consumer late (read after the producer's next scan was visible).
  auto behind = [&](std::size_t t) { return rt->tasks[t]->stats.overruns.load() + rt->tasks[t]->stats.skipped.load(); };
  auto late = [&](std::size_t t) { return rt->tasks[t]->stats.late_reads.load(); };
  struct Edge {
    const char* log;
    std::uint64_t older_reasons, newer_reasons;
  };
  // odd_log2 reads mid's doubling of what mid read from fast: older through either.
  const Edge edges[] = {{"mid_log", behind(0), late(1)},
                        {"odd_log", behind(0), late(2)},
                        {"odd_log2", behind(0) + behind(1) + late(1), late(2)}};

  auto vt = load_test_project(kLetProject);
  ASSERT_TRUE(vt);
  std::int64_t last_release = 0;
  for (const char* log : {"mid_log", "odd_log", "odd_log2"})
    for (const auto& r : samples(*rt, log)) last_release = std::max(last_release, r.now_ns);
  VirtualClock clock(*vt);
  clock.run_until(last_release + 10'000'000);  // as long as the real-time run, however long that took

  std::size_t compared = 0, differ = 0;
  for (const Edge& edge : edges) {
    const char* log = edge.log;
    auto real = samples(*rt, log), virt = samples(*vt, log);
    ASSERT_GT(real.size(), 300u) << log;
    std::size_t j = 0;
    for (const auto& r : real) {
      while (j < virt.size() && virt[j].now_ns < r.now_ns) ++j;
      ASSERT_LT(j, virt.size()) << log;
      ASSERT_EQ(virt[j].now_ns, r.now_ns) << log << ": a release the virtual clock did not make";
      ++compared;
      if (virt[j].in != r.in) {
        ++differ;
        // Only the reason counted for its direction explains a difference
        // (the count rises: older is smaller).
        const bool older = r.in < virt[j].in;
        if ((older ? edge.older_reasons : edge.newer_reasons) == 0)
          ADD_FAILURE() << log << " at " << r.now_ns << " ns: real " << r.in << ", virtual " << virt[j].in << ": "
                        << (older ? "older, and its producer neither overran nor skipped"
                                  : "newer, and its consumer counted no late read");
      }
    }
  }
  RecordProperty("compared", static_cast<int>(compared));
  std::printf("compared %zu values, %zu differ, %llu overruns/late reads/skips\n", compared, differ,
              static_cast<unsigned long long>(reasons));
  EXPECT_GT(compared, 1000u);  // 375 + 250 + 250 per 750 scans of mid, at least
  // Differences only where the run counted why (overruns, late reads, skipped scans).
  EXPECT_LE(differ, reasons * 4) << compared << " values compared, " << reasons << " overruns/late reads/skips";
}

}  // namespace
}  // namespace syncplc
