// GT, GE, EQ, NE, LE, LT over several types, BOOL output.
#include <cmath>
#include <limits>

#include "tests/iec/iec_test_util.hpp"

namespace syncplc::iectest {
namespace {

struct Expect {
  bool gt, ge, eq, ne, le, lt;
};

template <class V>
void check(IecType dt, V a, V b, Expect e) {
  const std::pair<const char*, bool> cases[] = {{"GT", e.gt}, {"GE", e.ge}, {"EQ", e.eq},
                                                {"NE", e.ne}, {"LE", e.le}, {"LT", e.lt}};
  for (const auto& [name, want] : cases) {
    BlockHarness h(registry(), name, opts(dt));
    ASSERT_TRUE(h.ok()) << name << " " << type_name(dt) << ": " << errors_of(h);
    h.set<V>("IN1", a);
    h.set<V>("IN2", b);
    h.scan();
    EXPECT_EQ(h.get<bool>("OUT"), want) << name << " " << type_name(dt) << " " << +a << " vs " << +b;
    EXPECT_LE(h.cell("OUT").raw, 1u);  // a proper BOOL
  }
}

constexpr Expect kLess{false, false, false, true, true, true};
constexpr Expect kEqual{false, true, true, false, true, false};
constexpr Expect kGreater{true, true, false, true, false, false};

TEST(Compare, SignedIntegers) {
  check<std::int16_t>(IecType::INT, -5, 3, kLess);
  check<std::int16_t>(IecType::INT, 7, 7, kEqual);
  check<std::int16_t>(IecType::INT, 32767, -32768, kGreater);
  check<std::int8_t>(IecType::SINT, -128, 127, kLess);
  check<std::int64_t>(IecType::LINT, std::numeric_limits<std::int64_t>::min(), 0, kLess);
}

TEST(Compare, UnsignedAndBitStringsCompareUnsigned) {
  check<std::uint16_t>(IecType::UINT, 65535, 1, kGreater);
  check<std::uint8_t>(IecType::BYTE, 0x80, 0x7F, kGreater);
  check<std::uint16_t>(IecType::WORD, 0xFFFF, 0xFFFF, kEqual);
  check<std::uint64_t>(IecType::ULINT, 1ull << 63, 1, kGreater);
}

TEST(Compare, Reals) {
  check<double>(IecType::LREAL, 1.5, 2.5, kLess);
  check<double>(IecType::LREAL, -0.0, 0.0, kEqual);
  check<float>(IecType::REAL, 0.1f, 0.1f, kEqual);
  check<float>(IecType::REAL, 3.0f, -3.0f, kGreater);
}

// A NaN input: the block does not execute (finite_guard.hpp), OUT holds its
// last value and ENO is FALSE.
TEST(Compare, NanInputHoldsOutAndClearsEno) {
  for (const char* name : {"GT", "GE", "EQ", "NE", "LE", "LT"}) {
    BlockHarness h(registry(), name, opts(IecType::LREAL));
    h.set<double>("IN1", 1.0);
    h.set<double>("IN2", 2.0);
    h.scan();
    const bool before = h.get<bool>("OUT");
    h.set<double>("IN1", std::nan(""));
    h.scan();
    EXPECT_EQ(h.get<bool>("OUT"), before) << name;
    EXPECT_FALSE(h.get<bool>("ENO")) << name;
  }
}

TEST(Compare, BoolAndTime) {
  check<bool>(IecType::BOOL, false, true, kLess);
  check<bool>(IecType::BOOL, true, true, kEqual);
  check<std::int64_t>(IecType::TIME, ms(1500), ms(1000), kGreater);
  check<std::int64_t>(IecType::TIME, -ms(1), 0, kLess);
}

TEST(Compare, DefaultsToLreal) {
  BlockHarness h(registry(), "GT");
  ASSERT_HARNESS_OK(h);
  h.set<double>("IN1", 2.5);
  h.set<double>("IN2", 2.25);
  h.scan();
  EXPECT_TRUE(h.get<bool>("OUT"));
}

}  // namespace
}  // namespace syncplc::iectest
