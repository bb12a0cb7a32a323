// TripleBuffer and SpscRing, single-threaded: the semantics the scan relies
// on (the threaded behaviour is exercised by tests/realtime).
#include <gtest/gtest.h>

#include <cstdint>
#include <vector>

#include "runtime/core/spsc_ring.hpp"
#include "runtime/core/triple_buffer.hpp"

namespace syncplc {
namespace {

std::vector<Cell> cells(std::initializer_list<std::uint64_t> v) {
  std::vector<Cell> c;
  for (auto x : v) c.push_back(Cell{x});
  return c;
}

std::vector<std::uint64_t> raw(const Cell* p, std::size_t n) {
  std::vector<std::uint64_t> v;
  for (std::size_t i = 0; i < n; ++i) v.push_back(p[i].raw);
  return v;
}

using V = std::vector<std::uint64_t>;

// --- TripleBuffer -------------------------------------------------------------------------------

TEST(TripleBuffer, StartsFromTheFilledValue) {
  TripleBuffer b(3);
  EXPECT_EQ(b.size(), 3u);
  EXPECT_EQ(raw(b.acquire(), 3), (V{0, 0, 0}));
  auto init = cells({7, 8, 9});
  b.fill(init.data());
  EXPECT_EQ(raw(b.acquire(), 3), (V{7, 8, 9}));
  EXPECT_EQ(raw(b.back(), 3), (V{7, 8, 9}));  // every buffer holds it
}

TEST(TripleBuffer, NewestPublicationWins) {
  TripleBuffer b(2);
  for (std::uint64_t k = 1; k <= 5; ++k) {
    auto v = cells({k, 10 * k});
    b.publish(v.data());
  }
  EXPECT_EQ(raw(b.acquire(), 2), (V{5, 50}));
  // Nothing new: the consumer keeps the same values.
  EXPECT_EQ(raw(b.acquire(), 2), (V{5, 50}));
  auto v = cells({6, 60});
  b.publish(v.data());
  EXPECT_EQ(raw(b.acquire(), 2), (V{6, 60}));
}

TEST(TripleBuffer, AcquiredBufferIsStableWhileTheProducerGoesOn) {
  TripleBuffer b(2);
  auto one = cells({1, 1});
  b.publish(one.data());
  const Cell* seen = b.acquire();
  // The producer publishes many times; what the consumer holds never changes
  // (no torn pair) until it acquires again.
  for (std::uint64_t k = 2; k < 50; ++k) {
    Cell* back = b.back();
    EXPECT_NE(back, seen);
    back[0].raw = k;
    back[1].raw = k;
    b.publish();
    EXPECT_EQ(raw(seen, 2), (V{1, 1}));
    EXPECT_EQ(raw(b.front(), 2), (V{1, 1}));
  }
  EXPECT_EQ(raw(b.acquire(), 2), (V{49, 49}));
}

TEST(TripleBuffer, ThreeDistinctBuffers) {
  TripleBuffer b(1);
  const Cell* front = b.acquire();
  Cell* back = b.back();
  EXPECT_NE(front, back);
  b.publish();  // back goes to the middle; producer takes the old middle
  Cell* back2 = b.back();
  EXPECT_NE(back2, back);
  EXPECT_NE(back2, front);
  EXPECT_EQ(b.acquire(), back);  // consumer takes what was published
}

// --- SpscRing ------------------------------------------------------------------------------------

TEST(SpscRing, CapacityRoundsUpToAPowerOfTwo) {
  EXPECT_EQ(SpscRing<int>(5).capacity(), 8u);
  EXPECT_EQ(SpscRing<int>(16).capacity(), 16u);
  EXPECT_EQ(SpscRing<int>(1).capacity(), 1u);
  SpscRing<int> none(0);
  EXPECT_EQ(none.capacity(), 0u);
  EXPECT_FALSE(none.push(1));
}

TEST(SpscRing, FifoOrder) {
  SpscRing<int> r(4);
  int out = 0;
  EXPECT_FALSE(r.pop(out));
  for (int round = 0; round < 10; ++round) {  // wraps around many times
    EXPECT_TRUE(r.push(3 * round));
    EXPECT_TRUE(r.push(3 * round + 1));
    EXPECT_TRUE(r.push(3 * round + 2));
    EXPECT_EQ(r.size_approx(), 3u);
    for (int i = 0; i < 3; ++i) {
      ASSERT_TRUE(r.pop(out));
      EXPECT_EQ(out, 3 * round + i);
    }
    EXPECT_FALSE(r.pop(out));
  }
}

TEST(SpscRing, FullRingRejects) {
  SpscRing<int> r(4);
  for (int i = 0; i < 4; ++i) EXPECT_TRUE(r.push(i));
  EXPECT_FALSE(r.has_room(1));
  EXPECT_FALSE(r.push(99));
  int out;
  ASSERT_TRUE(r.pop(out));
  EXPECT_EQ(out, 0);
  EXPECT_TRUE(r.has_room(1));
  EXPECT_FALSE(r.has_room(2));
  EXPECT_TRUE(r.push(4));
  EXPECT_FALSE(r.push(5));
  for (int want = 1; want <= 4; ++want) {
    ASSERT_TRUE(r.pop(out));
    EXPECT_EQ(out, want);
  }
}

TEST(SpscRing, BatchBecomesVisibleAtCommit) {
  SpscRing<int> r(8);
  EXPECT_TRUE(r.stage(1));
  EXPECT_TRUE(r.stage(2));
  EXPECT_TRUE(r.stage(3));
  int out;
  EXPECT_FALSE(r.pop(out));  // staged, not committed
  EXPECT_EQ(r.size_approx(), 0u);
  EXPECT_TRUE(r.has_room(5));
  EXPECT_FALSE(r.has_room(6));  // staged entries take room
  r.commit();
  EXPECT_EQ(r.size_approx(), 3u);
  for (int want = 1; want <= 3; ++want) {
    ASSERT_TRUE(r.pop(out));
    EXPECT_EQ(out, want);
  }
}

TEST(SpscRing, StagingStopsWhenFull) {
  SpscRing<int> r(2);
  EXPECT_TRUE(r.stage(1));
  EXPECT_TRUE(r.stage(2));
  EXPECT_FALSE(r.stage(3));
  r.commit();
  EXPECT_EQ(r.size_approx(), 2u);
}

TEST(SpscRing, RollbackDiscardsTheStagedBatch) {
  SpscRing<int> r(4);
  EXPECT_TRUE(r.push(10));
  EXPECT_TRUE(r.stage(20));
  EXPECT_TRUE(r.stage(30));
  r.rollback();
  EXPECT_TRUE(r.has_room(3));
  int out;
  ASSERT_TRUE(r.pop(out));
  EXPECT_EQ(out, 10);
  EXPECT_FALSE(r.pop(out));
  // The slots are reused by the next batch.
  EXPECT_TRUE(r.stage(40));
  r.commit();
  ASSERT_TRUE(r.pop(out));
  EXPECT_EQ(out, 40);
}

TEST(SpscRing, ResetEmptiesIt) {
  SpscRing<int> r(4);
  r.push(1);
  r.stage(2);
  r.reset(2);
  EXPECT_EQ(r.capacity(), 2u);
  EXPECT_EQ(r.size_approx(), 0u);
  EXPECT_TRUE(r.has_room(2));
  int out;
  EXPECT_FALSE(r.pop(out));
}

}  // namespace
}  // namespace syncplc
