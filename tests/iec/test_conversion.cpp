// Type conversion functions *_TO_** and *_TRUNC_**: every pair of elementary
// types is registered (generated from one table), IEC 61131-3 Table 22
// rounding (ties to even), truncation, saturation with a fault out of range,
// bit-pattern rules for bit strings, BOOL and TIME.
#include <cmath>
#include <limits>

#include "tests/iec/iec_test_util.hpp"

namespace syncplc::iectest {
namespace {

template <class D, class S>
D conv(const std::string& name, S in, std::size_t* faults = nullptr) {
  BlockHarness h(registry(), name);
  EXPECT_TRUE(h.ok()) << name << ": " << errors_of(h);
  if (!h.ok()) return D{};
  h.set<S>("IN", in);
  h.scan();
  if (faults) *faults = h.events().size();
  EXPECT_TRUE(h.get<bool>("ENO")) << name;
  return h.get<D>("OUT");
}

TEST(Conversion, EveryPairIsRegistered) {
  const char* types[] = {"BOOL", "SINT", "INT",  "DINT",  "LINT", "USINT", "UINT", "UDINT",
                         "ULINT", "BYTE", "WORD", "DWORD", "LWORD", "REAL", "LREAL", "TIME"};
  int n = 0;
  for (const char* s : types)
    for (const char* d : types) {
      if (std::string(s) == d) continue;
      const auto* t = registry().find(std::string(s) + "_TO_" + d);
      ASSERT_NE(t, nullptr) << s << "_TO_" << d;
      EXPECT_EQ(t->category, "IEC type conversion");
      EXPECT_NE(t->reference.find("Table 22"), std::string::npos);
      ++n;
    }
  EXPECT_EQ(n, 240);
  for (const char* s : {"REAL", "LREAL"})
    for (const char* d : {"SINT", "INT", "DINT", "LINT", "USINT", "UINT", "UDINT", "ULINT"})
      EXPECT_NE(registry().find(std::string(s) + "_TRUNC_" + d), nullptr) << s << "_TRUNC_" << d;
  EXPECT_EQ(registry().find("INT_TO_INT"), nullptr);
}

// The user guide's example: INT to DINT needs a block.
TEST(Conversion, WideningIsExact) {
  EXPECT_EQ(conv<std::int32_t>("INT_TO_DINT", std::int16_t{-32768}), -32768);
  EXPECT_EQ(conv<std::int64_t>("UDINT_TO_LINT", std::uint32_t{4294967295u}), 4294967295LL);
  EXPECT_EQ(conv<double>("DINT_TO_LREAL", std::int32_t{-7}), -7.0);
}

TEST(Conversion, RealToIntegerRoundsToNearestTiesToEven) {
  // IEC 61131-3 Table 22 note b.
  const std::pair<float, std::int16_t> cases[] = {{1.6f, 2}, {-1.6f, -2}, {1.5f, 2},  {-1.5f, -2},
                                                  {1.4f, 1}, {-1.4f, -1}, {2.5f, 2}, {-2.5f, -2}, {3.5f, 4}};
  for (auto [in, want] : cases) EXPECT_EQ(conv<std::int16_t>("REAL_TO_INT", in), want) << in;
  EXPECT_EQ(conv<std::int64_t>("LREAL_TO_LINT", 0.5), 0);
}

TEST(Conversion, TruncRoundsTowardZero) {
  // Table 22 note c.
  EXPECT_EQ(conv<std::int16_t>("REAL_TRUNC_INT", 1.6f), 1);
  EXPECT_EQ(conv<std::int16_t>("REAL_TRUNC_INT", -1.6f), -1);
  EXPECT_EQ(conv<std::int32_t>("LREAL_TRUNC_DINT", -2.9), -2);
  EXPECT_EQ(conv<std::uint8_t>("LREAL_TRUNC_USINT", 255.9), 255);
}

TEST(Conversion, OutOfRangeSaturatesAndFaults) {
  std::size_t f = 0;
  EXPECT_EQ(conv<std::int16_t>("DINT_TO_INT", std::int32_t{40000}, &f), 32767);
  EXPECT_EQ(f, 1u);
  EXPECT_EQ(conv<std::int8_t>("INT_TO_SINT", std::int16_t{-200}, &f), -128);
  EXPECT_EQ(f, 1u);
  EXPECT_EQ(conv<std::uint16_t>("INT_TO_UINT", std::int16_t{-1}, &f), 0);
  EXPECT_EQ(f, 1u);
  EXPECT_EQ(conv<std::int32_t>("LREAL_TO_DINT", 1e12, &f), std::numeric_limits<std::int32_t>::max());
  EXPECT_EQ(f, 1u);
  EXPECT_EQ(conv<std::uint64_t>("LREAL_TO_ULINT", 1e30, &f), std::numeric_limits<std::uint64_t>::max());
  EXPECT_EQ(f, 1u);
  EXPECT_EQ(conv<std::int64_t>("ULINT_TO_LINT", std::numeric_limits<std::uint64_t>::max(), &f),
            std::numeric_limits<std::int64_t>::max());
  EXPECT_EQ(f, 1u);
  EXPECT_EQ(conv<float>("LREAL_TO_REAL", 1e300, &f), std::numeric_limits<float>::max());
  EXPECT_EQ(f, 1u);
  EXPECT_EQ(conv<std::int16_t>("DINT_TO_INT", std::int32_t{-32768}, &f), -32768);  // fits: no fault
  EXPECT_EQ(f, 0u);
}

TEST(Conversion, BitStringsAreBitPatterns) {
  std::size_t f = 0;
  EXPECT_EQ(conv<std::uint16_t>("INT_TO_WORD", std::int16_t{-1}, &f), 0xFFFF);
  EXPECT_EQ(f, 0u);
  EXPECT_EQ(conv<std::uint8_t>("DWORD_TO_BYTE", std::uint32_t{0x1234}, &f), 0x34);
  EXPECT_EQ(f, 0u);
  EXPECT_EQ(conv<std::int16_t>("WORD_TO_INT", std::uint16_t{0xFFFF}, &f), -1);  // same width: reinterpreted
  EXPECT_EQ(f, 0u);
  EXPECT_EQ(conv<std::int16_t>("DWORD_TO_INT", std::uint32_t{0xFFFF}, &f), 32767);  // a number: saturated
  EXPECT_EQ(f, 1u);
  EXPECT_EQ(conv<std::uint32_t>("INT_TO_DWORD", std::int16_t{-2}), 0xFFFFFFFEu);
  EXPECT_EQ(conv<std::uint8_t>("REAL_TO_BYTE", 2.5f), 2);
  EXPECT_EQ(conv<std::uint8_t>("REAL_TO_BYTE", -3.0f, &f), 0);
  EXPECT_EQ(f, 1u);
}

TEST(Conversion, BoolRules) {
  EXPECT_TRUE(conv<bool>("INT_TO_BOOL", std::int16_t{-5}));
  EXPECT_FALSE(conv<bool>("LREAL_TO_BOOL", 0.0));
  EXPECT_TRUE(conv<bool>("LREAL_TO_BOOL", 0.25));
  EXPECT_EQ(conv<std::int16_t>("BOOL_TO_INT", true), 1);
  EXPECT_EQ(conv<double>("BOOL_TO_LREAL", false), 0.0);
  EXPECT_EQ(conv<std::int64_t>("BOOL_TO_TIME", true), ms(1));
}

TEST(Conversion, TimeCountsMilliseconds) {
  EXPECT_EQ(conv<std::int32_t>("TIME_TO_DINT", ms(1500)), 1500);
  EXPECT_EQ(conv<double>("TIME_TO_LREAL", ms(1) + 500 * kUs), 1.5);
  EXPECT_EQ(conv<std::int32_t>("TIME_TO_DINT", 2 * kMs + 500 * kUs), 2);  // ties to even
  EXPECT_EQ(conv<std::int64_t>("DINT_TO_TIME", std::int32_t{250}), ms(250));
  EXPECT_EQ(conv<std::int64_t>("LREAL_TO_TIME", 0.001), std::int64_t{1000});
  std::size_t f = 0;
  EXPECT_EQ(conv<std::int64_t>("ULINT_TO_TIME", std::numeric_limits<std::uint64_t>::max(), &f),
            std::numeric_limits<std::int64_t>::max());
  EXPECT_EQ(f, 1u);
}

TEST(Conversion, NonFiniteRealHoldsOut) {
  BlockHarness h(registry(), "LREAL_TO_DINT");
  h.set<double>("IN", 7.0);
  h.scan();
  h.set<double>("IN", std::numeric_limits<double>::quiet_NaN());
  h.scan();
  EXPECT_EQ(h.get<std::int32_t>("OUT"), 7);
  EXPECT_FALSE(h.get<bool>("ENO"));
}

}  // namespace
}  // namespace syncplc::iectest
