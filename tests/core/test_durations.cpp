// parse_duration_ns and format_duration.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cstdint>
#include <string>

#include "runtime/core/duration_text.hpp"
#include "runtime/core/iec_type.hpp"

namespace syncplc {
namespace {

using ::testing::HasSubstr;

std::int64_t ns(const std::string& text) {
  std::string err;
  auto v = parse_duration_ns(text, &err);
  EXPECT_TRUE(v.has_value()) << "'" << text << "': " << err;
  return v.value_or(-999);
}

std::string err(const std::string& text) {
  std::string e;
  auto v = parse_duration_ns(text, &e);
  EXPECT_FALSE(v.has_value()) << "'" << text << "' = " << *v;
  return e;
}

constexpr std::int64_t kUs = 1'000, kMs = 1'000'000, kS = 1'000'000'000;

TEST(Durations, SingleUnits) {
  EXPECT_EQ(ns("100ns"), 100);
  EXPECT_EQ(ns("250us"), 250 * kUs);
  EXPECT_EQ(ns("1ms"), kMs);
  EXPECT_EQ(ns("0.5s"), kS / 2);
  EXPECT_EQ(ns("2m"), 120 * kS);
  EXPECT_EQ(ns("2min"), 120 * kS);
  EXPECT_EQ(ns("1h"), 3600 * kS);
  EXPECT_EQ(ns("1d"), 86400 * kS);
  EXPECT_EQ(ns("1.5ms"), 1'500'000);
  EXPECT_EQ(ns("0.1us"), 100);
  EXPECT_EQ(ns("1MS"), kMs);  // units are case-insensitive
}

TEST(Durations, CompoundsGoFromLargestToSmallest) {
  EXPECT_EQ(ns("T#1h2m3s4ms"), ((3600 + 120 + 3) * 1000 + 4) * kMs);
  EXPECT_EQ(ns("1m30s"), 90 * kS);
  EXPECT_EQ(ns("1s500ms"), 1500 * kMs);
  EXPECT_EQ(ns("1d2h"), 26 * 3600 * kS);
  EXPECT_EQ(ns("1s_500ms"), 1500 * kMs);  // underscores are ignored
  EXPECT_THAT(err("1ms2s"), HasSubstr("units must go from largest to smallest"));
  EXPECT_THAT(err("1s1s"), HasSubstr("units must go from largest to smallest"));
  EXPECT_THAT(err("30s1m"), HasSubstr("units must go from largest to smallest"));
}

TEST(Durations, IecPrefixesAndSign) {
  EXPECT_EQ(ns("T#250ms"), 250 * kMs);
  EXPECT_EQ(ns("t#250ms"), 250 * kMs);
  EXPECT_EQ(ns("TIME#1s"), kS);
  EXPECT_EQ(ns("LT#1s"), kS);
  EXPECT_EQ(ns("LTIME#1s"), kS);
  EXPECT_EQ(ns("-5ms"), -5 * kMs);
  EXPECT_EQ(ns("T#-1s500ms"), -1500 * kMs);
  EXPECT_EQ(ns("+5ms"), 5 * kMs);
  EXPECT_EQ(ns("  5ms  "), 5 * kMs);
}

TEST(Durations, Errors) {
  EXPECT_EQ(err("5q"), "'5q' is not a duration (unknown unit 'q'; write e.g. 1ms, 250us, 0.5s, T#1m30s)");
  EXPECT_THAT(err("10"), HasSubstr("missing unit after 10"));
  EXPECT_THAT(err("ms"), HasSubstr("missing number"));
  EXPECT_THAT(err(""), HasSubstr("(empty;"));
  EXPECT_THAT(err("T#"), HasSubstr("(empty;"));
  EXPECT_THAT(err("1.2.3s"), HasSubstr("bad number '1.2.3'"));
  // No spaces inside a duration, and the message says that is the problem.
  EXPECT_EQ(err("10 ms"), "'10 ms' is not a duration (no space may separate 10 from its unit: 10ms; write e.g. 1ms, "
                          "250us, 0.5s, T#1m30s)");
  EXPECT_THAT(err("1 ms x"), HasSubstr("no space may separate 1 from its unit: 1ms"));
  EXPECT_THAT(err("1sec"), HasSubstr("unknown unit 'sec'"));
  EXPECT_THAT(err("106752d"), HasSubstr("too long"));
}

TEST(Durations, Limits) {
  // The whole LTIME range reads back: INT64_MAX and INT64_MIN ns, not one more.
  EXPECT_EQ(ns("106481d"), 106481LL * 86400 * kS);
  EXPECT_EQ(ns("T#106751d23h47m16s854ms775us807ns"), INT64_MAX);
  EXPECT_EQ(ns(format_duration(INT64_MAX)), INT64_MAX);
  EXPECT_EQ(ns(format_duration(INT64_MIN)), INT64_MIN);
  EXPECT_THAT(err("T#106751d23h47m16s854ms775us808ns"), HasSubstr("too long"));
  EXPECT_EQ(ns("0ms"), 0);
  EXPECT_EQ(ns("0.4ns"), 0);  // rounded to whole nanoseconds
  EXPECT_EQ(ns("0.6ns"), 1);
}

TEST(Durations, Format) {
  EXPECT_EQ(format_duration(0), "0ms");
  EXPECT_EQ(format_duration(1), "1ns");
  EXPECT_EQ(format_duration(250 * kUs), "250us");
  EXPECT_EQ(format_duration(1500 * kMs), "1s500ms");
  EXPECT_EQ(format_duration(90 * kS), "1m30s");
  EXPECT_EQ(format_duration(3600 * kS + 1), "1h1ns");
  EXPECT_EQ(format_duration(-kMs), "-1ms");
  EXPECT_EQ(format_duration(INT64_MIN), "-2562047h47m16s854ms775us808ns");
  for (std::int64_t v : std::initializer_list<std::int64_t>{1, 999 * kUs, 61 * kS + 7, 9'200'000'000'000'000'000, -123456789})
    EXPECT_EQ(ns(format_duration(v)), v) << v;
}

}  // namespace
}  // namespace syncplc

namespace syncplc {
namespace {

// The reading under parse_duration_ns and ST's STRING_TO_TIME: its faults,
// with what they point at, and no allocation on any path.
TEST(DurationText, FaultsSayWhatIsWrong) {
  EXPECT_EQ(scan_duration("T#1m30s").ns, 90'000'000'000);
  EXPECT_EQ(scan_duration(" 1_000ms ").ns, 1'000'000'000);
  EXPECT_EQ(scan_duration("T#1s_").ns, 1'000'000'000);        // as the project files always read it
  EXPECT_EQ(scan_duration("T#1m_30s").ns, 90'000'000'000);
  EXPECT_EQ(scan_duration("1m_s").ns, 1'000'000);  // the unit ms, an underscore in it
  EXPECT_EQ(scan_duration("ltime#-1.5s").ns, -1'500'000'000);
  EXPECT_EQ(scan_duration("T#").fault, DurationFault::Empty);
  EXPECT_EQ(scan_duration("-").fault, DurationFault::Empty);
  EXPECT_EQ(scan_duration("ms").fault, DurationFault::MissingNumber);
  const DurationScan bad = scan_duration("1.5.2us");
  EXPECT_EQ(bad.fault, DurationFault::BadNumber);
  EXPECT_EQ(bad.number, "1.5.2");
  EXPECT_EQ(scan_duration("10").fault, DurationFault::MissingUnit);
  const DurationScan spaced = scan_duration("10 ms x");
  EXPECT_EQ(spaced.fault, DurationFault::SpacedUnit);
  EXPECT_EQ(spaced.number, "10");
  EXPECT_EQ(spaced.unit, "ms");
  const DurationScan unknown = scan_duration("5q");
  EXPECT_EQ(unknown.fault, DurationFault::UnknownUnit);
  EXPECT_EQ(unknown.unit, "q");
  EXPECT_EQ(scan_duration("1s1m").fault, DurationFault::UnitOrder);
  // A number longer than the reading holds is no number, not an overflow.
  EXPECT_EQ(scan_duration(std::string(100, '1') + "ms").fault, DurationFault::BadNumber);
}

TEST(DurationText, PastTheRangeGivesTheLimitOfItsSign) {
  const DurationScan up = scan_duration("T#200000d");
  EXPECT_EQ(up.fault, DurationFault::TooLong);
  EXPECT_EQ(up.ns, INT64_MAX);
  const DurationScan down = scan_duration("T#-200000d");
  EXPECT_EQ(down.fault, DurationFault::TooLong);
  EXPECT_EQ(down.ns, INT64_MIN);
  EXPECT_EQ(scan_duration("-9223372036854775808ns").ns, INT64_MIN);
}

TEST(DurationText, WrittenShortestAndWithinItsRoom) {
  char buf[kDurationTextMax];
  auto text = [&](std::int64_t v) { return std::string(buf, write_duration(buf, v)); };
  EXPECT_EQ(text(0), "0ms");
  EXPECT_EQ(text(90'000'000'000), "1m30s");
  EXPECT_EQ(text(-250'000), "-250us");
  EXPECT_EQ(text(INT64_MIN), "-2562047h47m16s854ms775us808ns");
  EXPECT_LE(text(INT64_MIN).size(), kDurationTextMax);
  EXPECT_EQ(scan_duration(text(INT64_MIN)).ns, INT64_MIN);
  EXPECT_EQ(scan_duration(text(INT64_MAX)).ns, INT64_MAX);
}

}  // namespace
}  // namespace syncplc
