// SEL, LIMIT, MAX, MIN, MOVE over several types.
#include <cmath>
#include <limits>

#include "tests/iec/iec_test_util.hpp"

namespace syncplc::iectest {
namespace {

template <class V>
V sel(IecType dt, bool g, V in0, V in1) {
  BlockHarness h(registry(), "SEL", opts(dt));
  EXPECT_TRUE(h.ok()) << errors_of(h);
  h.set<bool>("G", g);
  h.set<V>("IN0", in0);
  h.set<V>("IN1", in1);
  h.scan();
  return h.get<V>("OUT");
}

template <class V>
V limit(IecType dt, V mn, V in, V mx) {
  BlockHarness h(registry(), "LIMIT", opts(dt));
  EXPECT_TRUE(h.ok()) << errors_of(h);
  h.set<V>("MN", mn);
  h.set<V>("IN", in);
  h.set<V>("MX", mx);
  h.scan();
  return h.get<V>("OUT");
}

TEST(Sel, SelectsOnG) {
  EXPECT_EQ(sel<std::int16_t>(IecType::INT, false, 10, 20), 10);
  EXPECT_EQ(sel<std::int16_t>(IecType::INT, true, 10, 20), 20);
  EXPECT_DOUBLE_EQ(sel<double>(IecType::LREAL, true, 1.5, -2.5), -2.5);
  EXPECT_FLOAT_EQ(sel<float>(IecType::REAL, false, 1.5f, -2.5f), 1.5f);
  EXPECT_EQ(sel<bool>(IecType::BOOL, true, true, false), false);
  EXPECT_EQ(sel<std::int64_t>(IecType::TIME, true, ms(1), ms(2)), ms(2));
  EXPECT_EQ(sel<std::uint16_t>(IecType::WORD, false, 0xABCD, 0x1234), 0xABCD);
}

TEST(Sel, FollowsGEveryScan) {
  BlockHarness h(registry(), "SEL", opts(IecType::DINT));
  h.set<std::int32_t>("IN0", -1);
  h.set<std::int32_t>("IN1", 1);
  for (int i = 0; i < 6; ++i) {
    h.set<bool>("G", i % 2 == 1);
    h.scan();
    EXPECT_EQ(h.get<std::int32_t>("OUT"), i % 2 == 1 ? 1 : -1);
  }
}

TEST(Limit, ClampsIntegers) {
  EXPECT_EQ(limit<std::int16_t>(IecType::INT, -10, -50, 10), -10);
  EXPECT_EQ(limit<std::int16_t>(IecType::INT, -10, 5, 10), 5);
  EXPECT_EQ(limit<std::int16_t>(IecType::INT, -10, 50, 10), 10);
  EXPECT_EQ(limit<std::uint16_t>(IecType::UINT, 100, 65535, 200), 200);
  EXPECT_EQ(limit<std::int64_t>(IecType::LINT, 0, std::numeric_limits<std::int64_t>::min(), 5), 0);
}

TEST(Limit, ClampsRealsAndTime) {
  EXPECT_DOUBLE_EQ(limit<double>(IecType::LREAL, 0.0, 1.5, 1.0), 1.0);
  EXPECT_DOUBLE_EQ(limit<double>(IecType::LREAL, 0.0, -1e300, 1.0), 0.0);
  EXPECT_FLOAT_EQ(limit<float>(IecType::REAL, -1.0f, 0.25f, 1.0f), 0.25f);
  EXPECT_EQ(limit<std::int64_t>(IecType::TIME, ms(10), ms(500), ms(100)), ms(100));
  EXPECT_EQ(limit<std::int64_t>(IecType::TIME, ms(10), ms(1), ms(100)), ms(10));
}

TEST(Limit, MnAboveMxGivesMx) {
  // MIN(MAX(IN, MN), MX) with MN > MX is MX whatever IN is.
  EXPECT_EQ(limit<std::int16_t>(IecType::INT, 10, 0, 5), 5);
  EXPECT_EQ(limit<std::int16_t>(IecType::INT, 10, 7, 5), 5);
  EXPECT_EQ(limit<std::int16_t>(IecType::INT, 10, 20, 5), 5);
}

// A NaN input or bound: the block does not execute, OUT keeps its last value.
TEST(Limit, NanHoldsTheLastOutput) {
  EXPECT_DOUBLE_EQ(limit<double>(IecType::LREAL, 0.0, std::nan(""), 1.0), 0.0);
  EXPECT_DOUBLE_EQ(limit<double>(IecType::LREAL, std::nan(""), 5.0, 1.0), 0.0);
  EXPECT_DOUBLE_EQ(limit<double>(IecType::LREAL, 0.0, 0.5, std::nan("")), 0.0);
}

TEST(Limit, Bool) {
  EXPECT_EQ(limit<bool>(IecType::BOOL, true, false, true), true);
  EXPECT_EQ(limit<bool>(IecType::BOOL, false, true, false), false);
}

TEST(MaxMin, TwoInputs) {
  BlockHarness mx(registry(), "MAX", opts(IecType::INT));
  BlockHarness mn(registry(), "MIN", opts(IecType::INT));
  ASSERT_HARNESS_OK(mx);
  ASSERT_HARNESS_OK(mn);
  for (auto* h : {&mx, &mn}) {
    h->set<std::int16_t>("IN1", -3);
    h->set<std::int16_t>("IN2", 2);
    // Harness default connects IN3..IN8 too: give them neutral values.
    for (int i = 3; i <= 8; ++i) h->set<std::int16_t>("IN" + std::to_string(i), 0);
    h->scan();
  }
  EXPECT_EQ(mx.get<std::int16_t>("OUT"), 2);
  EXPECT_EQ(mn.get<std::int16_t>("OUT"), -3);
}

TEST(MaxMin, ExtensibleWithSomeInputsConnected) {
  const std::set<std::string> conn{"IN1", "IN2", "IN4", "IN7"};
  BlockHarness mx(registry(), "MAX", opts(IecType::DINT, conn));
  BlockHarness mn(registry(), "MIN", opts(IecType::DINT, conn));
  for (auto* h : {&mx, &mn}) {
    h->set<std::int32_t>("IN1", 5);
    h->set<std::int32_t>("IN2", 7);
    h->set<std::int32_t>("IN3", 1000);  // unconnected: ignored
    h->set<std::int32_t>("IN4", -20);
    h->set<std::int32_t>("IN6", -1000);  // unconnected: ignored
    h->set<std::int32_t>("IN7", 30);
    h->scan();
  }
  EXPECT_EQ(mx.get<std::int32_t>("OUT"), 30);
  EXPECT_EQ(mn.get<std::int32_t>("OUT"), -20);
}

TEST(MaxMin, UnconnectedZeroInputsDoNotClamp) {
  const std::set<std::string> conn{"IN1", "IN2"};
  BlockHarness mx(registry(), "MAX", opts(IecType::LREAL, conn));
  mx.set<double>("IN1", -5.0);
  mx.set<double>("IN2", -3.0);
  mx.scan();
  EXPECT_DOUBLE_EQ(mx.get<double>("OUT"), -3.0);  // not 0 from IN3..IN8
  BlockHarness mn(registry(), "MIN", opts(IecType::UINT, conn));
  mn.set<std::uint16_t>("IN1", 9);
  mn.set<std::uint16_t>("IN2", 4);
  mn.scan();
  EXPECT_EQ(mn.get<std::uint16_t>("OUT"), 4);
}

TEST(MaxMin, RealsTimeAndNan) {
  const std::set<std::string> conn{"IN1", "IN2", "IN3"};
  BlockHarness mx(registry(), "MAX", opts(IecType::REAL, conn));
  mx.set<float>("IN1", 1.5f);
  mx.set<float>("IN2", std::nanf(""));
  mx.set<float>("IN3", -2.0f);
  mx.scan();
  EXPECT_FLOAT_EQ(mx.get<float>("OUT"), 0.0f);  // NaN: not executed, OUT held
  EXPECT_FALSE(mx.get<bool>("ENO"));
  mx.set<float>("IN2", 0.5f);
  mx.scan();
  EXPECT_FLOAT_EQ(mx.get<float>("OUT"), 1.5f);
  BlockHarness mn(registry(), "MIN", opts(IecType::TIME, conn));
  mn.set<std::int64_t>("IN1", ms(3));
  mn.set<std::int64_t>("IN2", ms(1));
  mn.set<std::int64_t>("IN3", ms(2));
  mn.scan();
  EXPECT_EQ(mn.get<std::int64_t>("OUT"), ms(1));
}

TEST(Move, CopiesEveryType) {
  {
    BlockHarness h(registry(), "MOVE");
    ASSERT_HARNESS_OK(h);
    h.set<double>("IN", -123.456);
    h.scan();
    EXPECT_DOUBLE_EQ(h.get<double>("OUT"), -123.456);
  }
  {
    BlockHarness h(registry(), "MOVE", opts(IecType::WORD));
    h.set<std::uint16_t>("IN", 0xBEEF);
    h.scan();
    EXPECT_EQ(h.get<std::uint16_t>("OUT"), 0xBEEF);
  }
  {
    BlockHarness h(registry(), "MOVE", opts(IecType::BOOL));
    h.set<bool>("IN", true);
    h.scan();
    EXPECT_TRUE(h.get<bool>("OUT"));
  }
  {
    BlockHarness h(registry(), "MOVE", opts(IecType::TIME));
    h.set<std::int64_t>("IN", -ms(7));
    h.scan();
    EXPECT_EQ(h.get<std::int64_t>("OUT"), -ms(7));
  }
}

}  // namespace
}  // namespace syncplc::iectest
