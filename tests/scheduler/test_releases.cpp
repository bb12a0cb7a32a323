// Task releases in virtual time: counts, grids, phases, priorities, no drift.
#include <gtest/gtest.h>

#include <map>

#include "runtime/core/virtual_clock.hpp"
#include "tests/support/project_fixture.hpp"

namespace syncplc {
namespace {

using testing::records;

std::map<std::string, std::vector<std::int64_t>> releases_by_instance() {
  std::map<std::string, std::vector<std::int64_t>> m;
  for (const auto& r : records()) m[r.instance].push_back(r.now_ns);
  return m;
}

// Over a duration D the scheduler releases the scans whose planned time lies
// in [0, D): ceil((D - phase) / period) of them, the one at t = phase
// included and none at t = D.
TEST(Releases, CountIsCeilOfDurationMinusPhaseOverPeriod) {
  records().clear();
  auto p = load_test_project(R"(
tasks:
  - {name: a, period: 1ms, priority: 50}
  - {name: b, period: 19ms, priority: 40}
  - {name: c, period: 20ms, priority: 30}
  - {name: d, period: 7ms, phase: 3ms, priority: 20}
  - {name: e, period: 250us, priority: 60}
  - {name: f, period: 10s, priority: 10}
blocks:
  - {name: ra, type: RECORD, task: a}
  - {name: rb, type: RECORD, task: b}
  - {name: rc, type: RECORD, task: c}
  - {name: rd, type: RECORD, task: d}
  - {name: re, type: RECORD, task: e}
  - {name: rf, type: RECORD, task: f}
)");
  ASSERT_TRUE(p);
  VirtualClock clock(*p);
  const std::int64_t D = 1'900'000'000;  // 1.9 s
  clock.run_until(D);
  auto m = releases_by_instance();
  EXPECT_EQ(m["ra"].size(), 1900u);  // 1900 / 1
  EXPECT_EQ(m["rb"].size(), 100u);   // ceil(1900 / 19) = 100: 0 .. 1881 ms
  EXPECT_EQ(m["rc"].size(), 95u);    // 1900 / 20
  EXPECT_EQ(m["rd"].size(), 271u);   // ceil(1897 / 7) = 271: 3 .. 1893 ms
  EXPECT_EQ(m["re"].size(), 7600u);  // 1900 / 0.25
  EXPECT_EQ(m["rf"].size(), 1u);     // only t = 0
  EXPECT_EQ(clock.scans(0), 1900u);
}

// Each task keeps its own grid: the n-th release is exactly phase + n·period
// (no common tick, no accumulated rounding), also for periods that are not
// multiples of each other.
TEST(Releases, EveryTaskStaysOnItsOwnGridWithoutDrift) {
  records().clear();
  auto p = load_test_project(R"(
tasks:
  - {name: a, period: 19ms, priority: 50}
  - {name: b, period: 20ms, priority: 40}
  - {name: c, period: 333us, phase: 111us, priority: 30}
blocks:
  - {name: ra, type: RECORD, task: a}
  - {name: rb, type: RECORD, task: b}
  - {name: rc, type: RECORD, task: c}
)");
  ASSERT_TRUE(p);
  VirtualClock clock(*p);
  clock.run_until(60'000'000'000);  // one virtual minute
  auto m = releases_by_instance();
  auto check = [](const std::vector<std::int64_t>& v, std::int64_t phase, std::int64_t period) {
    for (std::size_t n = 0; n < v.size(); ++n) ASSERT_EQ(v[n], phase + static_cast<std::int64_t>(n) * period) << n;
  };
  check(m["ra"], 0, 19'000'000);
  check(m["rb"], 0, 20'000'000);
  check(m["rc"], 111'000, 333'000);
  EXPECT_EQ(m["ra"].back(), 59'983'000'000);  // 3157 × 19 ms
  EXPECT_EQ(m["rc"].size(), 180'180u);         // ceil((60 s − 111 us) / 333 us)
  // dt is the distance between planned releases: the period, always.
  for (const auto& r : records())
    if (r.instance == "rc") {
      ASSERT_EQ(r.dt_ns, 333'000);
    }
}

TEST(Releases, HigherPriorityRunsFirstAtEqualReleaseThenDeclarationOrder) {
  records().clear();
  auto p = load_test_project(R"(
tasks:
  - {name: low, period: 2ms, priority: 10}
  - {name: high, period: 4ms, priority: 90}
  - {name: mid1, period: 1ms, priority: 50}
  - {name: mid2, period: 1ms, priority: 50}
blocks:
  - {name: r_low, type: RECORD, task: low}
  - {name: r_high, type: RECORD, task: high}
  - {name: r_mid1, type: RECORD, task: mid1}
  - {name: r_mid2, type: RECORD, task: mid2}
)");
  ASSERT_TRUE(p);
  VirtualClock clock(*p);
  clock.run_until(4'000'000, true);  // t = 0 .. 4 ms inclusive
  std::vector<std::string> got;
  for (const auto& r : records()) got.push_back(std::to_string(r.now_ns / 1'000'000) + ":" + r.instance);
  std::vector<std::string> want = {
      "0:r_high", "0:r_mid1", "0:r_mid2", "0:r_low",
      "1:r_mid1", "1:r_mid2",
      "2:r_mid1", "2:r_mid2", "2:r_low",
      "3:r_mid1", "3:r_mid2",
      "4:r_high", "4:r_mid1", "4:r_mid2", "4:r_low"};
  EXPECT_EQ(got, want);
}

TEST(Releases, RunUntilExclusiveAndInclusive) {
  records().clear();
  auto p = load_test_project(R"(
tasks: [{name: a, period: 10ms}]
blocks: [{name: ra, type: RECORD}]
)");
  ASSERT_TRUE(p);
  VirtualClock clock(*p);
  clock.run_until(20'000'000, false);
  EXPECT_EQ(records().size(), 2u);  // 0 and 10 ms
  clock.run_until(20'000'000, true);
  EXPECT_EQ(records().size(), 3u);  // and 20 ms
  clock.run_until(20'000'000, true);
  EXPECT_EQ(records().size(), 3u);  // nothing twice
}

}  // namespace
}  // namespace syncplc
