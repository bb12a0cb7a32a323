// The simulated network of virtual time (runtime/io/dds/virtual_bus.*): when
// a sample becomes visible (the publisher's next grid point plus the
// subscriber's delay), the ring that keeps every sample a subscriber has not
// taken, and the layout checks between the nodes.
#include <gtest/gtest.h>

#include <vector>

#include "runtime/io/dds/virtual_bus.hpp"

namespace syncplc {
namespace test_virtual_bus {

constexpr std::int64_t kMs = 1'000'000;

struct Taken {
  std::uint64_t scan;
  double value;
};

std::vector<Taken> take(VirtualBus& bus, int sub, std::int64_t now) {
  std::vector<Taken> out;
  bus.take(sub, now, [&](const VirtualBus::Sample& s) { out.push_back({s.scan, s.values[0]}); });
  return out;
}

void publish(VirtualBus& bus, int pub, std::uint64_t scan, std::int64_t release, double v) {
  Cell c[2];
  c[0].set<double>(v);
  c[1].set<double>(-v);
  bus.publish(pub, scan, release, c);
}

TEST(VirtualBus, ASampleIsSeenAtThePublishersNextGridPointPlusTheDelay) {
  VirtualBus bus;
  std::string err;
  const int pub = bus.advertise("x", 2, "a", kMs, &err);
  const int now_sub = bus.subscribe("x", 2, "b", 0, kMs, &err);
  const int late_sub = bus.subscribe("x", 2, "c", 2 * kMs, kMs, &err);
  ASSERT_GE(pub, 0);
  ASSERT_GE(late_sub, 0) << err;
  publish(bus, pub, 0, 0, 10.0);
  EXPECT_TRUE(take(bus, now_sub, 0).empty());                 // its own instant: not yet
  EXPECT_TRUE(take(bus, now_sub, kMs - 1).empty());
  auto got = take(bus, now_sub, kMs);                          // the next grid point
  ASSERT_EQ(got.size(), 1u);
  EXPECT_EQ(got[0].scan, 0u);
  EXPECT_EQ(got[0].value, 10.0);
  EXPECT_TRUE(take(bus, now_sub, 5 * kMs).empty());            // taken once
  EXPECT_TRUE(take(bus, late_sub, 3 * kMs - 1).empty());       // 2 ms more
  EXPECT_EQ(take(bus, late_sub, 3 * kMs).size(), 1u);
}

TEST(VirtualBus, ASlowSubscriberTakesEverySampleSinceItsLastScan) {
  VirtualBus bus;
  std::string err;
  const int pub = bus.advertise("x", 1, "fast", kMs, &err);
  // A 10 ms task: each of its scans finds the ten samples published since.
  const int sub = bus.subscribe("x", 1, "slow", 0, 10 * kMs, &err);
  for (std::uint64_t k = 0; k < 100; ++k) {
    publish(bus, pub, k, static_cast<std::int64_t>(k) * kMs, static_cast<double>(k));
    if ((k + 1) % 10 == 0) {
      const auto got = take(bus, sub, static_cast<std::int64_t>(k + 1) * kMs);
      ASSERT_EQ(got.size(), 10u) << "at scan " << k;
      EXPECT_EQ(got.front().scan, k - 9);
      EXPECT_EQ(got.back().scan, k);
    }
  }
}

TEST(VirtualBus, ASubscriberThatStoppedTakingFindsTheNewestOnlyWithTheGapLost) {
  VirtualBus bus;
  std::string err;
  const int pub = bus.advertise("x", 1, "a", kMs, &err);
  const int sub = bus.subscribe("x", 1, "b", 0, kMs, &err);
  for (std::uint64_t k = 0; k < 1000; ++k) publish(bus, pub, k, static_cast<std::int64_t>(k) * kMs, static_cast<double>(k));
  const auto got = take(bus, sub, 1000 * kMs);
  ASSERT_FALSE(got.empty());
  EXPECT_LT(got.size(), 1000u);          // the ring is bounded
  EXPECT_EQ(got.back().scan, 999u);      // and holds the newest
  for (std::size_t i = 1; i < got.size(); ++i) EXPECT_EQ(got[i].scan, got[i - 1].scan + 1);
}

TEST(VirtualBus, NodesThatDisagreeOnATopicAreRefusedWithBothNames) {
  VirtualBus bus;
  std::string err;
  ASSERT_GE(bus.advertise("ref", 12, "master", kMs, &err), 0);
  EXPECT_LT(bus.subscribe("ref", 3, "axis1", 0, kMs, &err), 0);
  EXPECT_EQ(err, "dds: topic ref: node 'master' publishes 12 values, node 'axis1' takes 3 values: the nodes' projects do not match");
  EXPECT_LT(bus.advertise("ref", 12, "other", kMs, &err), 0);
  EXPECT_EQ(err, "dds: topic ref: node 'master' publishes it already; node 'other' may not publish it too");
  // A subscriber first, then a publisher with another count.
  ASSERT_GE(bus.subscribe("state", 2, "master", 0, kMs, &err), 0);
  EXPECT_LT(bus.advertise("state", 3, "axis2", kMs, &err), 0);
  EXPECT_EQ(err, "dds: topic state: node 'master' takes 2 values, node 'axis2' publishes 3 values: the nodes' projects do not match");
}

TEST(VirtualBus, UnmatchedSubscriptionsAreListed) {
  VirtualBus bus;
  std::string err;
  ASSERT_GE(bus.subscribe("refx", 1, "axis1", 0, kMs, &err), 0);
  const auto u = bus.unmatched();
  ASSERT_EQ(u.size(), 1u);
  EXPECT_EQ(u[0], "dds: node 'axis1' subscribes topic refx, which no node of the system publishes");
}

TEST(VirtualBus, APublisherThatComesBackIsANewWriter) {
  VirtualBus bus;
  std::string err;
  const int pub = bus.advertise("x", 1, "a", kMs, &err);
  const int sub = bus.subscribe("x", 1, "b", 0, kMs, &err);
  publish(bus, pub, 7, 0, 1.0);
  std::uint64_t first = 0, second = 0;
  bus.take(sub, kMs, [&](const VirtualBus::Sample& s) { first = s.writer; });
  bus.withdraw_publisher(pub);
  EXPECT_EQ(bus.unmatched().size(), 1u);
  const int again = bus.advertise("x", 1, "a", kMs, &err);
  ASSERT_GE(again, 0);
  publish(bus, again, 0, 2 * kMs, 2.0);
  bus.take(sub, 3 * kMs, [&](const VirtualBus::Sample& s) { second = s.writer; });
  EXPECT_NE(first, 0u);
  EXPECT_NE(second, 0u);
  EXPECT_NE(first, second);
}

TEST(VirtualBus, AReplacedPublisherLeavesTheTopicToItsSuccessor) {
  // An online change: the new driver advertises before the old one closes.
  VirtualBus bus;
  std::string err;
  const int old_pub = bus.advertise("x", 1, "a", kMs, &err);
  const int sub = bus.subscribe("x", 1, "b", 0, kMs, &err);
  const int new_pub = bus.advertise("x", 1, "a", kMs, &err);
  ASSERT_GE(new_pub, 0) << err;
  publish(bus, old_pub, 5, 0, 1.0);  // the old one's last scan: no longer goes out
  bus.withdraw_publisher(old_pub);
  EXPECT_TRUE(bus.unmatched().empty());
  publish(bus, new_pub, 6, 0, 2.0);
  const auto got = take(bus, sub, kMs);
  ASSERT_EQ(got.size(), 1u);
  EXPECT_EQ(got[0].value, 2.0);
}

}  // namespace test_virtual_bus
}  // namespace syncplc
