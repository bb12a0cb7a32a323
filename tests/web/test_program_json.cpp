// A task's statistics in GET /status (docs/http-api.md, "Reading"): the
// coarse 1-2-5 histogram always, the task's own buckets with
// ?histograms=full, and percentiles of an interval from two snapshots.
#include <gtest/gtest.h>

#include <cstdint>
#include <map>

#include "runtime/core/histogram.hpp"
#include "runtime/web/program_json.hpp"

namespace syncplc::web {
namespace {

std::map<std::int64_t, std::uint64_t> buckets(const nlohmann::json& full) {
  std::map<std::int64_t, std::uint64_t> out;
  const auto& upper = full.at("upper_ns");
  const auto& counts = full.at("counts");
  EXPECT_EQ(upper.size(), counts.size());
  for (std::size_t i = 0; i < upper.size(); ++i) out[upper[i].get<std::int64_t>()] = counts[i].get<std::uint64_t>();
  return out;
}

TEST(ProgramJson, FullHistogramOnlyWhenAskedFor) {
  Histogram h;
  h.reset();
  h.record(12'000);
  EXPECT_FALSE(statistics_json(h).contains("full"));
  EXPECT_TRUE(statistics_json(h, true).contains("full"));
}

TEST(ProgramJson, FullHistogramHoldsEveryValueWithinOne32nd) {
  Histogram h;
  h.reset();
  const std::int64_t values[] = {0, 5, 31, 32, 1'000, 12'345, 12'346, 99'999, 1'000'000, 7'000'000'000};
  for (auto v : values) h.record(v);
  const auto b = buckets(full_histogram_json(h));
  std::uint64_t n = 0;
  for (const auto& [upper, count] : b) {
    EXPECT_GT(count, 0u);  // only non-empty buckets
    n += count;
  }
  EXPECT_EQ(n, std::size(values));
  for (auto v : values) {
    // The bucket that holds v is the first whose upper bound is >= v, and that bound is within 1/32 of v.
    const auto it = b.lower_bound(v);
    ASSERT_NE(it, b.end()) << v;
    EXPECT_LE(it->first - v, v / 32) << v;
  }
}

TEST(ProgramJson, TwoSnapshotsGiveTheIntervalAlone) {
  Histogram h;
  h.reset();
  for (int i = 0; i < 1000; ++i) h.record(500'000);  // before: slow starts
  const auto a = buckets(full_histogram_json(h));
  for (int i = 0; i < 99; ++i) h.record(10'000);
  h.record(40'000);
  const auto b = buckets(full_histogram_json(h));
  std::map<std::int64_t, std::uint64_t> d;
  for (const auto& [upper, count] : b) {
    const auto it = a.find(upper);
    const std::uint64_t before = it == a.end() ? 0 : it->second;
    if (count > before) d[upper] = count - before;
  }
  ASSERT_EQ(d.size(), 2u);
  EXPECT_EQ(d.begin()->second, 99u);
  EXPECT_GE(d.begin()->first, 10'000);
  EXPECT_GE(d.rbegin()->first, 40'000);
  EXPECT_LT(d.rbegin()->first, 500'000);
}

}  // namespace
}  // namespace syncplc::web
