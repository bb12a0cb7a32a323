// What a dds subscription shows the program (runtime/io/dds/subscription_latch.*):
// fresh values only from new samples, age in scans, ok, and the reactions
// hold, safe and stop after stale_after scans.
#include <gtest/gtest.h>

#include <vector>

#include "runtime/io/dds/subscription_latch.hpp"

namespace syncplc::dds {
namespace {

struct LatchRig {
  explicit LatchRig(Subscription s) : sub(std::move(s)), latch(sub, make_subscription_texts("net", sub)) {
    cells.assign(SubscriptionCells::kValues + sub.values, Cell{});
    values.assign(sub.values, Cell{});
    latch.reset();
  }
  // A sample from the publisher's scan `pub_scan` arrives.
  void arrive(std::uint64_t pub_scan, double v) {
    cells[SubscriptionCells::kReceived].set<std::uint64_t>(++received);
    cells[SubscriptionCells::kScan].set<std::uint64_t>(pub_scan);
    for (std::uint32_t i = 0; i < sub.values; ++i) cells[SubscriptionCells::kValues + i].set<double>(v + i);
  }
  const SubscriptionStatus& scan() {
    ctx.scan = next++;
    ctx.stop_request = nullptr;
    return latch.latch(cells.data(), ctx, values.data());
  }
  Subscription sub;
  SubscriptionLatch latch;
  std::vector<Cell> cells, values;
  std::uint64_t received = 0, next = 0;
  ScanContext ctx;
};

Subscription make(std::uint32_t stale_after, StaleReaction r) {
  Subscription s;
  s.topic = "ref";
  s.values = 2;
  s.stale_after = stale_after;
  s.reaction = r;
  s.safe = {-1, -2};
  return s;
}

TEST(DdsLatch, NotOkBeforeTheFirstSampleAndAgeCountsFromTheStart) {
  LatchRig r(make(2, StaleReaction::Hold));
  for (int k = 0; k < 3; ++k) {
    const auto& st = r.scan();
    EXPECT_FALSE(st.ok);
    EXPECT_EQ(st.age, static_cast<std::uint32_t>(k));
    EXPECT_FALSE(st.reacting) << k;  // stale only past stale_after = 2
  }
  EXPECT_TRUE(r.scan().reacting);
}

TEST(DdsLatch, NewSamplesAreFreshAndAgeCountsScansWithoutOne) {
  LatchRig r(make(2, StaleReaction::Hold));
  r.arrive(10, 5.0);
  auto st = r.scan();
  EXPECT_TRUE(st.ok);
  EXPECT_TRUE(st.fresh);
  EXPECT_EQ(st.age, 0u);
  EXPECT_EQ(st.scan, 10u);
  EXPECT_EQ(r.values[1].get<double>(), 6.0);
  st = r.scan();  // nothing new
  EXPECT_FALSE(st.fresh);
  EXPECT_EQ(st.age, 1u);
  EXPECT_TRUE(st.ok);
  r.scan();
  st = r.scan();
  EXPECT_EQ(st.age, 3u);
  EXPECT_FALSE(st.ok);
  EXPECT_TRUE(st.reacting);
  EXPECT_EQ(r.values[0].get<double>(), 5.0) << "hold: the last values stay";
  r.arrive(11, 7.0);
  st = r.scan();
  EXPECT_TRUE(st.ok);
  EXPECT_FALSE(st.reacting);
  EXPECT_EQ(r.values[0].get<double>(), 7.0);
}

TEST(DdsLatch, SafeTakesTheSafeValuesWhileStaleAndStopAsksTheTaskToStop) {
  LatchRig safe(make(0, StaleReaction::Safe));
  safe.arrive(1, 3.0);
  safe.scan();
  EXPECT_EQ(safe.values[0].get<double>(), 3.0);
  const auto& st = safe.scan();  // stale_after 0: the first scan without a sample reacts
  EXPECT_TRUE(st.reacting);
  EXPECT_EQ(safe.values[0].get<double>(), -1.0);
  EXPECT_EQ(safe.values[1].get<double>(), -2.0);
  EXPECT_EQ(safe.ctx.stop_request, nullptr);

  LatchRig stop(make(1, StaleReaction::Stop));
  stop.arrive(1, 3.0);
  stop.scan();
  stop.scan();
  EXPECT_EQ(stop.ctx.stop_request, nullptr);
  stop.scan();
  ASSERT_NE(stop.ctx.stop_request, nullptr);
  EXPECT_STREQ(stop.ctx.stop_request, "dds net.ref: stale past stale_after, stopping the task");
}

TEST(DdsLatch, LossAndLatenessCountersComeFromTheReceiver) {
  LatchRig r(make(5, StaleReaction::Hold));
  r.arrive(3, 1.0);
  r.cells[SubscriptionCells::kLost].set<std::uint64_t>(2);
  r.cells[SubscriptionCells::kLate].set<std::uint64_t>(1);
  const auto& st = r.scan();
  EXPECT_EQ(st.lost, 2u);
  EXPECT_EQ(st.late, 1u);
}

}  // namespace
}  // namespace syncplc::dds
