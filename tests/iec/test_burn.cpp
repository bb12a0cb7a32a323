// BURN: consumes execution time (virtual: consumed_ns; real: busy-wait).
#include <time.h>

#include <chrono>

#include "tests/iec/iec_test_util.hpp"

namespace syncplc::iectest {
namespace {

TEST(Burn, AddsExecToConsumedTimeInVirtualTime) {
  BlockHarness h(registry(), "BURN");
  ASSERT_HARNESS_OK(h);
  EXPECT_FALSE(h.get<bool>("DONE"));
  h.set<std::int64_t>("EXEC", 300 * kUs);
  h.scan();
  EXPECT_EQ(h.consumed_ns(), 300 * kUs);
  EXPECT_TRUE(h.get<bool>("DONE"));
  h.set<std::int64_t>("EXEC", ms(2));  // longer than the period: an overrun in virtual time
  h.scan();
  EXPECT_EQ(h.consumed_ns(), ms(2));
  EXPECT_TRUE(h.get<bool>("DONE"));
}

TEST(Burn, AccumulatesOntoTimeAlreadyConsumed) {
  BlockHarness h(registry(), "BURN");
  h.set<std::int64_t>("EXEC", 250);
  ScanContext ctx;
  ctx.virtual_time = true;
  ctx.consumed_ns = 1000;
  h.block().execute(ctx);
  EXPECT_EQ(ctx.consumed_ns, 1250);
  h.block().execute(ctx);
  EXPECT_EQ(ctx.consumed_ns, 1500);
}

TEST(Burn, ZeroOrNegativeExecConsumesNothing) {
  BlockHarness h(registry(), "BURN");
  h.scan();  // EXEC unconnected-default 0
  EXPECT_EQ(h.consumed_ns(), 0);
  EXPECT_TRUE(h.get<bool>("DONE"));
  h.set<std::int64_t>("EXEC", -ms(5));
  h.scan();
  EXPECT_EQ(h.consumed_ns(), 0);
}

TEST(Burn, BusyWaitsInRealTime) {
  BlockHarness h(registry(), "BURN");
  h.set<std::int64_t>("EXEC", ms(3));
  ScanContext ctx;
  ctx.virtual_time = false;
  // Not too long, measured in this thread's CPU time: a busy-wait on the
  // clock ends 3 ms of wall time after it began, so it cannot use much more
  // than 3 ms of CPU, however often a loaded machine takes the CPU away
  // (which makes the wall time longer, never the CPU time).
  const auto cpu = [] {
    timespec ts{};
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
    return std::int64_t{ts.tv_sec} * 1'000'000'000 + ts.tv_nsec;
  };
  const std::int64_t cpu0 = cpu();
  const auto t0 = std::chrono::steady_clock::now();
  h.block().execute(ctx);
  const auto took = std::chrono::steady_clock::now() - t0;
  const std::int64_t burnt = cpu() - cpu0;
  EXPECT_GE(std::chrono::duration_cast<std::chrono::nanoseconds>(took).count(), ms(3));
  EXPECT_LT(burnt, ms(3) + ms(50)) << "busy-wait far too long";
  EXPECT_EQ(ctx.consumed_ns, 0);  // real time: nothing virtual is added
  EXPECT_TRUE(h.get<bool>("DONE"));
}

}  // namespace
}  // namespace syncplc::iectest
