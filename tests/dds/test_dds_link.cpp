// Two dds drivers in one process on Cyclone DDS (loopback, unicast
// discovery): samples cross in order with the publisher's scan count, lost
// scans are counted, a silent publisher goes stale and comes back, a
// restarted publisher is taken again, a topic whose layout differs is never
// shown, and the safe outputs go out as one more sample. Each test uses its
// own domain and topics (ctest runs test processes side by side).
#include <gtest/gtest.h>
#include <unistd.h>

#include <chrono>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "tests/dds/dds_nodes.hpp"
#include "tests/support/allocation_counter.hpp"

namespace syncplc {
namespace {

using ddstest::latch_until;
using ddstest::Node;
using ddstest::topic;

TEST(DdsLink, SamplesCrossInOrderWithThePublishersScan) {
  const std::string t = topic("state");
  Node a("node: a\npublish: [{topic: " + t + ", values: 2}]\n");
  Node b("node: b\nsubscribe: [{topic: " + t + ", values: 2, stale_after: 1000000}]\n");
  // Discovery: publish until the first sample is seen.
  std::uint64_t k = 0;
  ASSERT_TRUE(latch_until(b, [&] {
    ++k;
    a.scan(k, t, {1.0 * k, -1.0 * k});
    return b.at(t + "_ok").get<bool>();
  }));
  for (int i = 0; i < 100; ++i) {
    ++k;
    a.scan(k, t, {1.0 * k, -1.0 * k});
    ASSERT_TRUE(latch_until(b, [&] { return b.at(t + "_scan").get<std::uint64_t>() == k; })) << k;
    EXPECT_EQ(b.at(t, 0).get<double>(), 1.0 * k);
    EXPECT_EQ(b.at(t, 1).get<double>(), -1.0 * k);
    EXPECT_TRUE(b.at(t + "_ok").get<bool>());
  }
  EXPECT_EQ(b.at(t + "_late").get<std::uint32_t>(), 0u);
  EXPECT_GE(a.counter("samples_sent"), 100);
}

TEST(DdsLink, ScansThePublisherSkippedAreCountedLost) {
  const std::string t = topic("lossy");
  Node a("node: a\npublish: [{topic: " + t + ", values: 1}]\n");
  Node b("node: b\nsubscribe: [{topic: " + t + ", values: 1, stale_after: 1000000}]\n");
  std::uint64_t k = 0;
  ASSERT_TRUE(latch_until(b, [&] {
    a.scan(++k, t, {0.0});
    return b.at(t + "_ok").get<bool>();
  }));
  // Matched: the next sample arrives, and from there on every gap is the publisher's.
  a.scan(++k, t, {0.0});
  ASSERT_TRUE(latch_until(b, [&] { return b.at(t + "_scan").get<std::uint64_t>() == k; }));
  const std::uint32_t lost0 = b.at(t + "_lost").get<std::uint32_t>();
  // Ten samples, each 3 scans after the one before: 2 lost per sample.
  for (int i = 0; i < 10; ++i) {
    k += 3;
    a.scan(k, t, {1.0});
    ASSERT_TRUE(latch_until(b, [&] { return b.at(t + "_scan").get<std::uint64_t>() == k; }));
  }
  EXPECT_EQ(b.at(t + "_lost").get<std::uint32_t>() - lost0, 20u);
}

TEST(DdsLink, ASilentPublisherGoesStaleAndComesBack) {
  const std::string t = topic("silent");
  Node a("node: a\npublish: [{topic: " + t + ", values: 1}]\n");
  Node b("node: b\nsubscribe: [{topic: " + t + ", values: 1, stale_after: 5, reaction: safe, safe: -7}]\n");
  std::uint64_t k = 0, kb = 0;
  ASSERT_TRUE(latch_until(b, [&] {
    a.scan(++k, t, {3.0});
    return b.at(t + "_ok").get<bool>();
  }));
  // Everything a sent has arrived; now b scans on and a sends nothing: after
  // 5 scans without a sample b reacts.
  ASSERT_TRUE(latch_until(b, [&] { return b.at(t + "_scan").get<std::uint64_t>() == k; }));
  kb = 1000;
  for (int i = 0; i <= 5; ++i) b.scan(++kb);
  EXPECT_TRUE(b.at(t + "_reaction").get<bool>());
  EXPECT_FALSE(b.at(t + "_ok").get<bool>());
  EXPECT_EQ(b.at(t).get<double>(), -7.0) << "safe: the values take the safe value while stale";
  EXPECT_GE(b.at(t + "_age").get<std::uint32_t>(), 6u);
  a.scan(++k, t, {4.0});
  ASSERT_TRUE(latch_until(b, [&] { return b.at(t + "_ok").get<bool>(); }));
  EXPECT_EQ(b.at(t).get<double>(), 4.0);
  EXPECT_FALSE(b.at(t + "_reaction").get<bool>());
}

TEST(DdsLink, ARestartedPublisherIsTakenAgainFromItsFirstScan) {
  const std::string t = topic("restart");
  Node b("node: b\nsubscribe: [{topic: " + t + ", values: 1, stale_after: 1000000}]\n");
  {
    Node a("node: a\npublish: [{topic: " + t + ", values: 1}]\n");
    std::uint64_t k = 500;
    ASSERT_TRUE(latch_until(b, [&] {
      a.scan(++k, t, {1.0});
      return b.at(t + "_ok").get<bool>() && b.at(t).get<double>() == 1.0;
    }));
  }
  Node a2("node: a\npublish: [{topic: " + t + ", values: 1}]\n");
  std::uint64_t k = 0;  // a new run counts its scans from 0 again
  ASSERT_TRUE(latch_until(b, [&] {
    a2.scan(k++, t, {2.0});
    return b.at(t).get<double>() == 2.0;
  }));
  EXPECT_EQ(b.at(t + "_late").get<std::uint32_t>(), 0u) << "not late: another writer, counted as one";
  EXPECT_GE(b.counter("writers_changed"), 1);
}

TEST(DdsLink, ATopicWhoseLayoutDiffersIsNeverShown) {
  const std::string t = topic("layout");
  Node a("node: a\npublish: [{topic: " + t + ", values: 2}]\n");
  Node b("node: b\nsubscribe: [{topic: " + t + ", values: 3, stale_after: 1000000}]\n");
  std::uint64_t k = 0;
  ASSERT_TRUE(latch_until(b, [&] {
    a.scan(++k, t, {1.0, 2.0});
    return b.counter("samples_mismatched") >= 5;
  }));
  EXPECT_FALSE(b.at(t + "_ok").get<bool>());
  EXPECT_EQ(b.at(t, 0).get<double>(), 0.0);
}

TEST(DdsLink, SafeOutputsGoOutAsOneMoreSampleAndHold) {
  const std::string t = topic("safe");
  Node a("node: a\npublish: [{topic: " + t + ", values: 2}]\n");
  Node b("node: b\nsubscribe: [{topic: " + t + ", values: 2, stale_after: 1000000}]\n");
  std::uint64_t k = 0;
  ASSERT_TRUE(latch_until(b, [&] {
    a.scan(++k, t, {5.0, 6.0});
    return b.at(t + "_ok").get<bool>();
  }));
  SafeOutput safe{a.channel(t), 1, Cell{}};
  safe.value.set<double>(-1.0);
  ASSERT_TRUE(a.drv->write_safe_outputs(&safe, 1));
  ASSERT_TRUE(latch_until(b, [&] { return b.at(t, 1).get<double>() == -1.0; }));
  EXPECT_EQ(b.at(t, 0).get<double>(), 5.0) << "the other element keeps its last value";
  EXPECT_EQ(b.at(t + "_scan").get<std::uint64_t>(), k + 1);
  // Held: a scan that ends afterwards sends nothing.
  a.scan(k + 2, t, {9.0, 9.0});
  std::this_thread::sleep_for(std::chrono::milliseconds(50));
  b.drv->latch_inputs(b.ctx);
  EXPECT_EQ(b.at(t, 0).get<double>(), 5.0);
}

// A node whose project gives a topic another size than its peer's is
// refused at start with both sizes named; one that agrees starts.
TEST(DdsLink, ANodeWhoseTopicsDoNotMatchItsPeersIsRefusedAtStart) {
  const std::string t = topic("mismatch");
  Node a("node: a\npublish: [{topic: " + t + ", values: 2}]\n");
  Node bad("node: b\nstartup_check: 20s\nsubscribe: [{topic: " + t + ", values: 3}]\n", false);
  EXPECT_FALSE(bad.opened);
  EXPECT_EQ(bad.open_error, "dds: topic " + t + ": node 'a' publishes 2 values, this node takes 3: the nodes' projects "
                            "do not match; this node is not started");
  Node good("node: c\nstartup_check: 20s\nsubscribe: [{topic: " + t + ", values: 2}]\n");
  EXPECT_TRUE(good.opened);
  // The check goes both ways: a publisher that starts after a subscriber of another size.
  const std::string u = topic("mismatch_pub");
  Node sub("node: d\nsubscribe: [{topic: " + u + ", values: 1}]\n");
  Node pub("node: e\nstartup_check: 20s\npublish: [{topic: " + u + ", values: 4}]\n", false);
  EXPECT_EQ(pub.open_error, "dds: topic " + u + ": node 'd' takes 1 value, this node publishes 4: the nodes' projects "
                            "do not match; this node is not started");
}

// latch_inputs and write_outputs of both nodes, with samples crossing: no
// operator new anywhere in the process meanwhile (Cyclone's own C
// allocations happen in the driver's threads, which call no operator new).
TEST(DdsLink, TheScanPathDoesNotAllocate) {
  const std::string t = topic("alloc");
  Node a("node: a\npublish: [{topic: " + t + ", values: 4}]\nsubscribe: [{topic: " + t + "_back, values: 1, stale_after: 2}]\n");
  Node b("node: b\npublish: [{topic: " + t + "_back, values: 1}]\nsubscribe: [{topic: " + t + ", values: 4, stale_after: 2, reaction: safe}]\n");
  std::uint64_t k = 0;
  ASSERT_TRUE(latch_until(b, [&] {
    ++k;
    a.scan(k, t, {1, 2, 3, 4});
    return b.at(t + "_ok").get<bool>();
  }));
  Cell& a_out = a.at(t, 0);
  Cell& b_out = b.at(t + "_back");
  test::allocations_counted = 0;
  test::counting_allocations = true;
  for (int i = 0; i < 500; ++i) {
    ++k;
    for (Node* n : {&a, &b}) {
      n->ctx.scan = k;
      n->drv->latch_inputs(n->ctx);
    }
    a_out.set<double>(1.0 * static_cast<double>(k));
    b_out.set<double>(1.0 * static_cast<double>(k));
    a.drv->write_outputs(a.ctx);
    b.drv->write_outputs(b.ctx);
    if (i % 50 == 0) std::this_thread::sleep_for(std::chrono::milliseconds(1));  // stale periods too (safe values, events)
  }
  test::counting_allocations = false;
  EXPECT_EQ(test::allocations_counted.load(), 0);
  EXPECT_GT(b.at(t + "_scan").get<std::uint64_t>(), 0u);
}

}  // namespace
}  // namespace syncplc
