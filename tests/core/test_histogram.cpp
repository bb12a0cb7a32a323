// Histogram: percentiles within 1/32 of the exact order statistic; min, max,
// mean and count exact; reset.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <random>
#include <vector>

#include "runtime/core/histogram.hpp"

namespace syncplc {
namespace {

std::int64_t exact(std::vector<std::int64_t> v, double q) {
  std::sort(v.begin(), v.end());
  auto rank = static_cast<std::size_t>(q * static_cast<double>(v.size()));
  return v[std::min(rank, v.size() - 1)];
}

void expect_within_1_32(std::int64_t reported, std::int64_t truth) {
  EXPECT_GE(reported, truth);  // the bucket's upper edge, never below
  EXPECT_LE(static_cast<double>(reported - truth), static_cast<double>(truth) / 32.0)
      << "reported " << reported << " true " << truth;
}

void check(const std::vector<std::int64_t>& data) {
  Histogram h;
  for (auto v : data) h.record(v);
  auto s = h.summary();
  EXPECT_EQ(s.count, data.size());
  EXPECT_EQ(s.min, *std::min_element(data.begin(), data.end()));
  EXPECT_EQ(s.max, *std::max_element(data.begin(), data.end()));
  long double sum = 0;
  for (auto v : data) sum += static_cast<long double>(v);
  EXPECT_NEAR(s.mean, static_cast<double>(sum / static_cast<long double>(data.size())), 1e-6 * std::fabs(s.mean) + 1e-9);
  expect_within_1_32(s.p50, exact(data, 0.50));
  expect_within_1_32(s.p99, exact(data, 0.99));
}

TEST(Histogram, PercentilesOfUniformData) {
  std::mt19937_64 rng(1);
  std::uniform_int_distribution<std::int64_t> d(0, 5'000'000);
  std::vector<std::int64_t> v(100'000);
  for (auto& x : v) x = d(rng);
  check(v);
}

TEST(Histogram, PercentilesOfLogNormalData) {
  // Scan times: most around tens of microseconds, a long tail to milliseconds.
  std::mt19937_64 rng(2);
  std::lognormal_distribution<double> d(10.0, 1.5);
  std::vector<std::int64_t> v(200'000);
  for (auto& x : v) x = static_cast<std::int64_t>(d(rng));
  check(v);
}

TEST(Histogram, PercentilesOfManyRandomSets) {
  std::mt19937_64 rng(3);
  for (int set = 0; set < 50; ++set) {
    std::uniform_int_distribution<int> exp(0, 50);
    std::uniform_int_distribution<std::size_t> n(1, 3000);
    std::vector<std::int64_t> v(n(rng));
    int e = exp(rng);
    std::uniform_int_distribution<std::int64_t> d(0, (std::int64_t{1} << e) + 100);
    for (auto& x : v) x = d(rng);
    SCOPED_TRACE(set);
    check(v);
  }
}

TEST(Histogram, SmallValuesAreExact) {
  Histogram h;
  for (int i = 0; i < 32; ++i) h.record(i);
  auto s = h.summary();
  EXPECT_EQ(s.p50, 16);
  EXPECT_EQ(s.p99, 31);
  EXPECT_EQ(s.min, 0);
  EXPECT_EQ(s.max, 31);
  EXPECT_DOUBLE_EQ(s.mean, 15.5);
}

TEST(Histogram, OneValue) {
  Histogram h;
  h.record(123'456'789);
  auto s = h.summary();
  EXPECT_EQ(s.count, 1u);
  EXPECT_EQ(s.min, 123'456'789);
  EXPECT_EQ(s.max, 123'456'789);
  EXPECT_EQ(s.p50, 123'456'789);  // clamped to [min, max]
  EXPECT_EQ(s.p99, 123'456'789);
}

TEST(Histogram, EmptyAndReset) {
  Histogram h;
  auto empty = h.summary();
  EXPECT_EQ(empty.count, 0u);
  EXPECT_EQ(empty.p99, 0);
  for (int i = 1; i <= 1000; ++i) h.record(i * 1000);
  EXPECT_EQ(h.summary().count, 1000u);
  h.reset();
  auto s = h.summary();
  EXPECT_EQ(s.count, 0u);
  EXPECT_EQ(s.max, 0);
  h.record(7);
  h.record(5);
  s = h.summary();
  EXPECT_EQ(s.count, 2u);
  EXPECT_EQ(s.min, 5);  // min and max start over after reset
  EXPECT_EQ(s.max, 7);
  EXPECT_DOUBLE_EQ(s.mean, 6.0);
}

TEST(Histogram, NegativeValuesCountAsZeroInBuckets) {
  Histogram h;
  h.record(-5);
  h.record(10);
  auto s = h.summary();
  EXPECT_EQ(s.min, -5);
  EXPECT_EQ(s.max, 10);
  EXPECT_EQ(s.p50, 10);
  EXPECT_DOUBLE_EQ(s.mean, 2.5);
}

TEST(Histogram, BucketEdges) {
  std::mt19937_64 rng(4);
  for (int i = 0; i < 100'000; ++i) {
    std::uint64_t u = rng() >> (rng() % 64);
    int b = Histogram::index(u);
    ASSERT_GE(b, 0);
    ASSERT_LT(b, Histogram::kBuckets);
    std::uint64_t hi = Histogram::upper(b);
    ASSERT_GE(hi, u);
    ASSERT_LE(static_cast<double>(hi - u), static_cast<double>(u) / 32.0) << u;
    if (b > 0) {
      ASSERT_LT(Histogram::upper(b - 1), u) << u;  // buckets are contiguous
    }
  }
  EXPECT_EQ(Histogram::index(UINT64_MAX), Histogram::kBuckets - 1);
  EXPECT_EQ(Histogram::upper(Histogram::kBuckets - 1), UINT64_MAX);
}

}  // namespace
}  // namespace syncplc
