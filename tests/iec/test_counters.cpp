// CTU, CTD, CTUD: edge counting, priorities, thresholds, type limits.
#include <limits>

#include "tests/iec/iec_test_util.hpp"

namespace syncplc::iectest {
namespace {

// One rising edge on `pin` (a TRUE scan followed by a FALSE scan).
void pulse(BlockHarness& h, const char* pin) {
  h.set<bool>(pin, true);
  h.scan();
  h.set<bool>(pin, false);
  h.scan();
}

TEST(Ctu, CountsRisingEdgesOnly) {
  BlockHarness h(registry(), "CTU");
  ASSERT_HARNESS_OK(h);
  h.set<std::int16_t>("PV", 3);
  h.scan();
  EXPECT_EQ(h.get<std::int16_t>("CV"), 0);
  h.set<bool>("CU", true);
  h.scans(5);  // held TRUE: one edge
  EXPECT_EQ(h.get<std::int16_t>("CV"), 1);
  EXPECT_FALSE(h.get<bool>("Q"));
  h.set<bool>("CU", false);
  h.scan();
  pulse(h, "CU");
  EXPECT_EQ(h.get<std::int16_t>("CV"), 2);
  EXPECT_FALSE(h.get<bool>("Q"));
  pulse(h, "CU");
  EXPECT_EQ(h.get<std::int16_t>("CV"), 3);
  EXPECT_TRUE(h.get<bool>("Q"));  // CV >= PV
  pulse(h, "CU");
  EXPECT_EQ(h.get<std::int16_t>("CV"), 4);
  EXPECT_TRUE(h.get<bool>("Q"));
}

TEST(Ctu, CuTrueOnFirstScanCounts) {
  BlockHarness h(registry(), "CTU");
  h.set<bool>("CU", true);
  h.scan();
  EXPECT_EQ(h.get<std::int16_t>("CV"), 1);
}

TEST(Ctu, ResetIsDominantAndBlocksCounting) {
  BlockHarness h(registry(), "CTU");
  h.set<std::int16_t>("PV", 1);
  pulse(h, "CU");
  pulse(h, "CU");
  EXPECT_EQ(h.get<std::int16_t>("CV"), 2);
  h.set<bool>("R", true);
  h.set<bool>("CU", true);  // edge together with R: not counted
  h.scan();
  EXPECT_EQ(h.get<std::int16_t>("CV"), 0);
  EXPECT_FALSE(h.get<bool>("Q"));
  h.set<bool>("R", false);
  h.scan();  // CU still TRUE: no new edge
  EXPECT_EQ(h.get<std::int16_t>("CV"), 0);
  h.set<bool>("CU", false);
  h.scan();
  pulse(h, "CU");
  EXPECT_EQ(h.get<std::int16_t>("CV"), 1);
  EXPECT_TRUE(h.get<bool>("Q"));
}

TEST(Ctu, QThresholdWithZeroAndNegativePv) {
  BlockHarness h(registry(), "CTU");
  h.set<std::int16_t>("PV", 0);
  h.scan();
  EXPECT_TRUE(h.get<bool>("Q"));  // 0 >= 0
  h.set<std::int16_t>("PV", -5);
  h.set<bool>("R", true);
  h.scan();
  EXPECT_TRUE(h.get<bool>("Q"));
  h.set<std::int16_t>("PV", 1);
  h.scan();
  EXPECT_FALSE(h.get<bool>("Q"));
}

TEST(Ctu, IntStopsAt32767) {
  BlockHarness h(registry(), "CTU");
  h.set<std::int16_t>("PV", 32767);
  for (int i = 0; i < 32766; ++i) pulse(h, "CU");
  EXPECT_EQ(h.get<std::int16_t>("CV"), 32766);
  EXPECT_FALSE(h.get<bool>("Q"));
  pulse(h, "CU");
  EXPECT_EQ(h.get<std::int16_t>("CV"), 32767);
  EXPECT_TRUE(h.get<bool>("Q"));
  for (int i = 0; i < 5; ++i) pulse(h, "CU");
  EXPECT_EQ(h.get<std::int16_t>("CV"), 32767);  // no wrap to -32768
  EXPECT_TRUE(h.get<bool>("Q"));
}

TEST(Ctu, DintVariantCountsPastIntRange) {
  BlockHarness h(registry(), "CTU", opts(IecType::DINT));
  ASSERT_HARNESS_OK(h);
  h.set<std::int32_t>("PV", 40000);
  for (int i = 0; i < 39999; ++i) pulse(h, "CU");
  EXPECT_EQ(h.get<std::int32_t>("CV"), 39999);
  EXPECT_FALSE(h.get<bool>("Q"));
  pulse(h, "CU");
  EXPECT_EQ(h.get<std::int32_t>("CV"), 40000);
  EXPECT_TRUE(h.get<bool>("Q"));
}

TEST(Ctu, UsintStopsAt255) {
  BlockHarness h(registry(), "CTU", opts(IecType::USINT));
  ASSERT_HARNESS_OK(h);
  h.set<std::uint8_t>("PV", 200);
  for (int i = 0; i < 300; ++i) pulse(h, "CU");
  EXPECT_EQ(h.get<std::uint8_t>("CV"), 255);
  EXPECT_TRUE(h.get<bool>("Q"));
}

TEST(Ctu, SintStopsAt127) {
  BlockHarness h(registry(), "CTU", opts(IecType::SINT));
  ASSERT_HARNESS_OK(h);
  for (int i = 0; i < 200; ++i) pulse(h, "CU");
  EXPECT_EQ(h.get<std::int8_t>("CV"), 127);
}

TEST(Ctu, RejectsNonIntegerDatatype) {
  BlockHarness h(registry(), "CTU", opts(IecType::REAL));
  EXPECT_FALSE(h.ok());
  BlockHarness t(registry(), "CTUD", opts(IecType::TIME));
  EXPECT_FALSE(t.ok());
}

TEST(Ctd, LoadsAndCountsDown) {
  BlockHarness h(registry(), "CTD");
  ASSERT_HARNESS_OK(h);
  h.scan();
  EXPECT_EQ(h.get<std::int16_t>("CV"), 0);
  EXPECT_TRUE(h.get<bool>("Q"));  // CV <= 0
  h.set<std::int16_t>("PV", 2);
  h.set<bool>("LD", true);
  h.set<bool>("CD", true);  // edge together with LD: not counted
  h.scan();
  EXPECT_EQ(h.get<std::int16_t>("CV"), 2);
  EXPECT_FALSE(h.get<bool>("Q"));
  h.set<bool>("LD", false);
  h.set<bool>("CD", false);
  h.scan();
  pulse(h, "CD");
  EXPECT_EQ(h.get<std::int16_t>("CV"), 1);
  EXPECT_FALSE(h.get<bool>("Q"));
  pulse(h, "CD");
  EXPECT_EQ(h.get<std::int16_t>("CV"), 0);
  EXPECT_TRUE(h.get<bool>("Q"));
  pulse(h, "CD");
  EXPECT_EQ(h.get<std::int16_t>("CV"), -1);  // keeps counting below 0
  EXPECT_TRUE(h.get<bool>("Q"));
}

TEST(Ctd, IntStopsAtMinus32768) {
  BlockHarness h(registry(), "CTD");
  h.set<std::int16_t>("PV", -32766);
  h.set<bool>("LD", true);
  h.scan();
  h.set<bool>("LD", false);
  pulse(h, "CD");
  pulse(h, "CD");
  EXPECT_EQ(h.get<std::int16_t>("CV"), -32768);
  pulse(h, "CD");
  pulse(h, "CD");
  EXPECT_EQ(h.get<std::int16_t>("CV"), -32768);  // no wrap to 32767
  EXPECT_TRUE(h.get<bool>("Q"));
}

TEST(Ctd, UnsignedStopsAtZero) {
  BlockHarness h(registry(), "CTD", opts(IecType::UINT));
  ASSERT_HARNESS_OK(h);
  h.set<std::uint16_t>("PV", 1);
  h.set<bool>("LD", true);
  h.scan();
  h.set<bool>("LD", false);
  pulse(h, "CD");
  pulse(h, "CD");
  pulse(h, "CD");
  EXPECT_EQ(h.get<std::uint16_t>("CV"), 0);
  EXPECT_TRUE(h.get<bool>("Q"));
}

TEST(Ctd, LintLimits) {
  BlockHarness h(registry(), "CTD", opts(IecType::LINT));
  ASSERT_HARNESS_OK(h);
  h.set<std::int64_t>("PV", std::numeric_limits<std::int64_t>::min() + 1);
  h.set<bool>("LD", true);
  h.scan();
  h.set<bool>("LD", false);
  for (int i = 0; i < 3; ++i) pulse(h, "CD");
  EXPECT_EQ(h.get<std::int64_t>("CV"), std::numeric_limits<std::int64_t>::min());
}

TEST(Ctud, CountsUpAndDownWithThresholds) {
  BlockHarness h(registry(), "CTUD");
  ASSERT_HARNESS_OK(h);
  h.set<std::int16_t>("PV", 2);
  h.scan();
  EXPECT_EQ(h.get<std::int16_t>("CV"), 0);
  EXPECT_FALSE(h.get<bool>("QU"));
  EXPECT_TRUE(h.get<bool>("QD"));
  pulse(h, "CU");
  EXPECT_EQ(h.get<std::int16_t>("CV"), 1);
  EXPECT_FALSE(h.get<bool>("QU"));
  EXPECT_FALSE(h.get<bool>("QD"));
  pulse(h, "CU");
  EXPECT_EQ(h.get<std::int16_t>("CV"), 2);
  EXPECT_TRUE(h.get<bool>("QU"));
  EXPECT_FALSE(h.get<bool>("QD"));
  pulse(h, "CD");
  pulse(h, "CD");
  pulse(h, "CD");
  EXPECT_EQ(h.get<std::int16_t>("CV"), -1);
  EXPECT_FALSE(h.get<bool>("QU"));
  EXPECT_TRUE(h.get<bool>("QD"));
}

TEST(Ctud, SimultaneousEdgesCancel) {
  BlockHarness h(registry(), "CTUD");
  pulse(h, "CU");
  h.set<bool>("CU", true);
  h.set<bool>("CD", true);
  h.scan();
  EXPECT_EQ(h.get<std::int16_t>("CV"), 1);
  // CU stays high, CD gets a new edge alone: counts down.
  h.set<bool>("CD", false);
  h.scan();
  h.set<bool>("CD", true);
  h.scan();
  EXPECT_EQ(h.get<std::int16_t>("CV"), 0);
}

TEST(Ctud, ResetDominatesLoad) {
  BlockHarness h(registry(), "CTUD");
  h.set<std::int16_t>("PV", 7);
  h.set<bool>("LD", true);
  h.scan();
  EXPECT_EQ(h.get<std::int16_t>("CV"), 7);
  EXPECT_TRUE(h.get<bool>("QU"));
  h.set<bool>("R", true);  // R and LD both TRUE
  h.scan();
  EXPECT_EQ(h.get<std::int16_t>("CV"), 0);
  EXPECT_FALSE(h.get<bool>("QU"));
  EXPECT_TRUE(h.get<bool>("QD"));
  h.set<bool>("R", false);  // LD alone again
  h.scan();
  EXPECT_EQ(h.get<std::int16_t>("CV"), 7);
}

TEST(Ctud, LoadAndResetBlockCountingButEdgeMemoryTracks) {
  BlockHarness h(registry(), "CTUD");
  h.set<std::int16_t>("PV", 5);
  h.set<bool>("LD", true);
  h.set<bool>("CU", true);
  h.scan();
  EXPECT_EQ(h.get<std::int16_t>("CV"), 5);
  h.set<bool>("LD", false);
  h.scan();  // CU still TRUE: the edge was consumed during LD
  EXPECT_EQ(h.get<std::int16_t>("CV"), 5);
  h.set<bool>("CU", false);
  h.scan();
  pulse(h, "CU");
  EXPECT_EQ(h.get<std::int16_t>("CV"), 6);
}

TEST(Ctud, TypeLimitsBothWays) {
  BlockHarness h(registry(), "CTUD", opts(IecType::SINT));
  ASSERT_HARNESS_OK(h);
  h.set<std::int8_t>("PV", 126);
  h.set<bool>("LD", true);
  h.scan();
  h.set<bool>("LD", false);
  for (int i = 0; i < 4; ++i) pulse(h, "CU");
  EXPECT_EQ(h.get<std::int8_t>("CV"), 127);
  h.set<std::int8_t>("PV", -127);
  h.set<bool>("LD", true);
  h.scan();
  h.set<bool>("LD", false);
  for (int i = 0; i < 4; ++i) pulse(h, "CD");
  EXPECT_EQ(h.get<std::int8_t>("CV"), -128);
}

TEST(Ctud, DintVariant) {
  BlockHarness h(registry(), "CTUD", opts(IecType::DINT));
  ASSERT_HARNESS_OK(h);
  h.set<std::int32_t>("PV", 100000);
  h.set<bool>("LD", true);
  h.scan();
  EXPECT_EQ(h.get<std::int32_t>("CV"), 100000);
  EXPECT_TRUE(h.get<bool>("QU"));
  h.set<bool>("LD", false);
  pulse(h, "CD");
  EXPECT_EQ(h.get<std::int32_t>("CV"), 99999);
  EXPECT_FALSE(h.get<bool>("QU"));
}

}  // namespace
}  // namespace syncplc::iectest
