// ADD, SUB, MUL, DIV, MOD, ABS: wrap-around, division by zero, TIME, reals,
// extensible inputs.
#include <cmath>
#include <cstring>
#include <limits>

#include "tests/iec/iec_test_util.hpp"

namespace syncplc::iectest {
namespace {

template <class V>
V binary(const char* type, IecType dt, V a, V b, BlockHarness** keep = nullptr) {
  static thread_local std::unique_ptr<BlockHarness> last;
  last = std::make_unique<BlockHarness>(registry(), type, opts(dt, std::set<std::string>{"IN1", "IN2"}));
  EXPECT_TRUE(last->ok()) << type << ": " << errors_of(*last);
  if (!last->ok()) return V{};
  last->set<V>("IN1", a);
  last->set<V>("IN2", b);
  last->scan();
  if (keep) *keep = last.get();
  return last->get<V>("OUT");
}

template <class V>
V unary(const char* type, IecType dt, V a) {
  BlockHarness h(registry(), type, opts(dt));
  EXPECT_TRUE(h.ok()) << type << ": " << errors_of(h);
  h.set<V>("IN", a);
  h.scan();
  return h.get<V>("OUT");
}

template <class V>
using lim = std::numeric_limits<V>;

TEST(Add, DefaultsToLreal) {
  EXPECT_DOUBLE_EQ(binary<double>("ADD", IecType::LREAL, 1.25, 2.5), 3.75);
  BlockHarness h(registry(), "ADD");
  ASSERT_HARNESS_OK(h);
  h.set<double>("IN1", 0.5);
  h.set<double>("IN2", 0.25);
  h.scan();
  EXPECT_DOUBLE_EQ(h.get<double>("OUT"), 0.75);
}

TEST(Add, IntegersWrapAround) {
  EXPECT_EQ(binary<std::int16_t>("ADD", IecType::INT, 32767, 1), -32768);
  EXPECT_EQ(binary<std::int8_t>("ADD", IecType::SINT, 127, 1), -128);
  EXPECT_EQ(binary<std::int8_t>("ADD", IecType::SINT, -128, -1), 127);
  EXPECT_EQ(binary<std::int32_t>("ADD", IecType::DINT, lim<std::int32_t>::max(), 1), lim<std::int32_t>::min());
  EXPECT_EQ(binary<std::int64_t>("ADD", IecType::LINT, lim<std::int64_t>::max(), 1), lim<std::int64_t>::min());
  EXPECT_EQ(binary<std::uint16_t>("ADD", IecType::UINT, 65535, 1), 0);
  EXPECT_EQ(binary<std::uint8_t>("ADD", IecType::USINT, 200, 100), 44);
  EXPECT_EQ(binary<std::uint64_t>("ADD", IecType::ULINT, lim<std::uint64_t>::max(), 2), 1u);
  EXPECT_EQ(binary<std::int16_t>("ADD", IecType::INT, -1200, 34), -1166);
}

TEST(Sub, IntegersWrapAround) {
  EXPECT_EQ(binary<std::int16_t>("SUB", IecType::INT, -32768, 1), 32767);
  EXPECT_EQ(binary<std::uint16_t>("SUB", IecType::UINT, 0, 1), 65535);
  EXPECT_EQ(binary<std::uint32_t>("SUB", IecType::UDINT, 3, 5), 4294967294u);
  EXPECT_EQ(binary<std::int64_t>("SUB", IecType::LINT, lim<std::int64_t>::min(), 1), lim<std::int64_t>::max());
  EXPECT_EQ(binary<std::int32_t>("SUB", IecType::DINT, 10, 25), -15);
}

TEST(Mul, IntegersWrapAround) {
  EXPECT_EQ(binary<std::int16_t>("MUL", IecType::INT, 300, 300), 24464);  // 90000 - 65536
  EXPECT_EQ(binary<std::int16_t>("MUL", IecType::INT, -300, 300), -24464);
  EXPECT_EQ(binary<std::uint16_t>("MUL", IecType::UINT, 65535, 65535), 1);  // would overflow int if promoted
  EXPECT_EQ(binary<std::int8_t>("MUL", IecType::SINT, -128, -1), -128);
  EXPECT_EQ(binary<std::int32_t>("MUL", IecType::DINT, 65536, 65536), 0);
  EXPECT_EQ(binary<std::int64_t>("MUL", IecType::LINT, lim<std::int64_t>::min(), -1), lim<std::int64_t>::min());
  EXPECT_EQ(binary<std::int64_t>("MUL", IecType::LINT, 3'000'000'000'000, 4'000'000),
            static_cast<std::int64_t>(static_cast<std::uint64_t>(3'000'000'000'000) * 4'000'000u));
  EXPECT_EQ(binary<std::uint64_t>("MUL", IecType::ULINT, 1ull << 63, 2), 0u);
  EXPECT_EQ(binary<std::int32_t>("MUL", IecType::DINT, -7, 6), -42);
}

TEST(Div, IntegersTruncateTowardZero) {
  EXPECT_EQ(binary<std::int16_t>("DIV", IecType::INT, 7, 2), 3);
  EXPECT_EQ(binary<std::int16_t>("DIV", IecType::INT, -7, 2), -3);
  EXPECT_EQ(binary<std::int16_t>("DIV", IecType::INT, 7, -2), -3);
  EXPECT_EQ(binary<std::uint8_t>("DIV", IecType::USINT, 255, 2), 127);
  EXPECT_EQ(binary<std::uint64_t>("DIV", IecType::ULINT, lim<std::uint64_t>::max(), lim<std::uint64_t>::max()), 1u);
  EXPECT_EQ(binary<std::int32_t>("DIV", IecType::DINT, 5, -1), -5);
}

TEST(Div, MinByMinusOneGivesMinWithoutTrapping) {
  EXPECT_EQ(binary<std::int8_t>("DIV", IecType::SINT, -128, -1), -128);
  EXPECT_EQ(binary<std::int16_t>("DIV", IecType::INT, -32768, -1), -32768);
  EXPECT_EQ(binary<std::int32_t>("DIV", IecType::DINT, lim<std::int32_t>::min(), -1), lim<std::int32_t>::min());
  EXPECT_EQ(binary<std::int64_t>("DIV", IecType::LINT, lim<std::int64_t>::min(), -1), lim<std::int64_t>::min());
  // An unsigned divisor of all ones is a plain division.
  EXPECT_EQ(binary<std::uint16_t>("DIV", IecType::UINT, 65535, 65535), 1);
}

TEST(Div, IntegerDivisionByZeroRaisesFaultAndGivesZero) {
  for (IecType t : {IecType::SINT, IecType::INT, IecType::DINT, IecType::LINT, IecType::USINT, IecType::UINT,
                    IecType::UDINT, IecType::ULINT}) {
    BlockHarness h(registry(), "DIV", opts(t));
    ASSERT_HARNESS_OK(h);
    h.cell("IN1").set<std::int8_t>(42);
    h.cell("IN2").raw = 0;
    h.cell("OUT").set<std::int8_t>(99);
    h.scan();
    EXPECT_EQ(h.cell("OUT").raw, 0u) << type_name(t);
    ASSERT_EQ(h.events().size(), 1u) << type_name(t);
    EXPECT_EQ(h.events()[0].kind, EventKind::BlockFault);
    EXPECT_STREQ(h.events()[0].message, "DIV: division by zero");
    EXPECT_DOUBLE_EQ(h.events()[0].value, 42.0);
    EXPECT_EQ(h.events()[0].time_ns, 0);
    // The fault is raised on every scan that divides by zero, and not after.
    h.scan();
    EXPECT_EQ(h.events().size(), 2u);
    h.cell("IN2").set<std::int8_t>(2);
    h.scan();
    EXPECT_EQ(h.events().size(), 2u);
    EXPECT_EQ(h.cell("OUT").get<std::int8_t>(), 21);
  }
}

TEST(Div, RealsFollowIeee) {
  BlockHarness* h = nullptr;
  EXPECT_EQ(binary<double>("DIV", IecType::LREAL, 1.0, 0.0, &h), std::numeric_limits<double>::infinity());
  EXPECT_TRUE(h->events().empty());
  EXPECT_EQ(binary<double>("DIV", IecType::LREAL, -1.0, 0.0), -std::numeric_limits<double>::infinity());
  EXPECT_TRUE(std::isnan(binary<double>("DIV", IecType::LREAL, 0.0, 0.0)));
  EXPECT_EQ(binary<float>("DIV", IecType::REAL, 1.0f, 0.0f, &h), std::numeric_limits<float>::infinity());
  EXPECT_TRUE(h->events().empty());
  EXPECT_FLOAT_EQ(binary<float>("DIV", IecType::REAL, 1.0f, 3.0f), 1.0f / 3.0f);
  EXPECT_DOUBLE_EQ(binary<double>("DIV", IecType::LREAL, 1.0, 3.0), 1.0 / 3.0);
}

TEST(Mod, SignFollowsDividend) {
  EXPECT_EQ(binary<std::int16_t>("MOD", IecType::INT, 7, 3), 1);
  EXPECT_EQ(binary<std::int16_t>("MOD", IecType::INT, -7, 2), -1);
  EXPECT_EQ(binary<std::int16_t>("MOD", IecType::INT, 7, -2), 1);
  EXPECT_EQ(binary<std::uint32_t>("MOD", IecType::UDINT, 4000000000u, 7), 4000000000u % 7);
}

TEST(Mod, MinusOneAndZeroDivisor) {
  EXPECT_EQ(binary<std::int64_t>("MOD", IecType::LINT, lim<std::int64_t>::min(), -1), 0);
  EXPECT_EQ(binary<std::int8_t>("MOD", IecType::SINT, -128, -1), 0);
  BlockHarness* h = nullptr;
  EXPECT_EQ(binary<std::int16_t>("MOD", IecType::INT, 5, 0, &h), 0);
  ASSERT_EQ(h->events().size(), 1u);
  EXPECT_EQ(h->events()[0].kind, EventKind::BlockFault);
  EXPECT_STREQ(h->events()[0].message, "MOD: division by zero");
}

TEST(Mod, RejectsReals) {
  BlockHarness h(registry(), "MOD", opts(IecType::LREAL));
  EXPECT_FALSE(h.ok());
}

TEST(Abs, AllNumericKinds) {
  EXPECT_EQ(unary<std::int16_t>("ABS", IecType::INT, -5), 5);
  EXPECT_EQ(unary<std::int16_t>("ABS", IecType::INT, 5), 5);
  EXPECT_EQ(unary<std::int16_t>("ABS", IecType::INT, -32768), -32768);  // no positive counterpart
  EXPECT_EQ(unary<std::int64_t>("ABS", IecType::LINT, lim<std::int64_t>::min()), lim<std::int64_t>::min());
  EXPECT_EQ(unary<std::uint16_t>("ABS", IecType::UINT, 65535), 65535);
  EXPECT_DOUBLE_EQ(unary<double>("ABS", IecType::LREAL, -2.5), 2.5);
  EXPECT_FLOAT_EQ(unary<float>("ABS", IecType::REAL, -0.125f), 0.125f);
  EXPECT_FALSE(std::signbit(unary<double>("ABS", IecType::LREAL, -0.0)));
  EXPECT_EQ(unary<double>("ABS", IecType::LREAL, std::nan("")), 0.0);  // not executed: OUT held
}

TEST(TimeArithmetic, AddAndSubDurations) {
  EXPECT_EQ(binary<std::int64_t>("ADD", IecType::TIME, ms(1000), ms(500)), ms(1500));
  EXPECT_EQ(binary<std::int64_t>("SUB", IecType::TIME, ms(1000), ms(1500)), -ms(500));
  EXPECT_EQ(binary<std::int64_t>("ADD", IecType::TIME, 1, 2), 3);  // ns resolution
  // TIME is an int64 of ns: it wraps like LINT (no UB).
  EXPECT_EQ(binary<std::int64_t>("ADD", IecType::TIME, lim<std::int64_t>::max(), 1), lim<std::int64_t>::min());
}

TEST(TimeArithmetic, MulAndDivDoNotTakeTime) {
  BlockHarness mul(registry(), "MUL", opts(IecType::TIME));
  EXPECT_FALSE(mul.ok());
  BlockHarness div(registry(), "DIV", opts(IecType::TIME));
  EXPECT_FALSE(div.ok());
}

TEST(Arithmetic, RejectsBitStrings) {
  for (const char* type : {"ADD", "SUB", "MUL", "DIV", "ABS"}) {
    BlockHarness b(registry(), type, opts(IecType::BOOL));
    EXPECT_FALSE(b.ok()) << type;
    BlockHarness w(registry(), type, opts(IecType::WORD));
    EXPECT_FALSE(w.ok()) << type;
  }
}

TEST(Reals, RealVersusLreal) {
  // REAL is computed in single precision, LREAL in double.
  EXPECT_EQ(binary<float>("ADD", IecType::REAL, 16777216.0f, 1.0f), 16777216.0f);
  EXPECT_EQ(binary<double>("ADD", IecType::LREAL, 16777216.0, 1.0), 16777217.0);
  EXPECT_EQ(binary<float>("ADD", IecType::REAL, 0.1f, 0.2f), 0.1f + 0.2f);
  EXPECT_EQ(binary<double>("ADD", IecType::LREAL, 0.1, 0.2), 0.1 + 0.2);
  EXPECT_NE(static_cast<double>(binary<float>("ADD", IecType::REAL, 0.1f, 0.2f)),
            binary<double>("ADD", IecType::LREAL, 0.1, 0.2));
  EXPECT_EQ(binary<float>("MUL", IecType::REAL, 3.0e38f, 10.0f), std::numeric_limits<float>::infinity());
  EXPECT_EQ(binary<double>("MUL", IecType::LREAL, 3.0e38, 10.0), 3.0e39);
  // A REAL output cell holds a float in its low bytes, upper bytes zero.
  BlockHarness h(registry(), "SUB", opts(IecType::REAL));
  h.set<float>("IN1", 1.5f);
  h.set<float>("IN2", 0.25f);
  h.scan();
  EXPECT_EQ(h.get<float>("OUT"), 1.25f);
  EXPECT_EQ(h.cell("OUT").raw >> 32, 0u);
}

TEST(Extensible, OnlyConnectedOptionalInputsTakePart) {
  BlockHarness h(registry(), "ADD", opts(IecType::INT, std::set<std::string>{"IN1", "IN2", "IN5"}));
  ASSERT_HARNESS_OK(h);
  h.set<std::int16_t>("IN1", 1);
  h.set<std::int16_t>("IN2", 10);
  h.set<std::int16_t>("IN3", 1000);  // not connected: ignored even if the cell holds a value
  h.set<std::int16_t>("IN5", 100);
  h.scan();
  EXPECT_EQ(h.get<std::int16_t>("OUT"), 111);
}

TEST(Extensible, MulIgnoresUnconnectedZeroInputs) {
  BlockHarness h(registry(), "MUL", opts(IecType::LREAL, std::set<std::string>{"IN1", "IN2", "IN8"}));
  ASSERT_HARNESS_OK(h);
  h.set<double>("IN1", 2.0);
  h.set<double>("IN2", 3.0);
  h.set<double>("IN8", 0.5);
  h.scan();
  EXPECT_DOUBLE_EQ(h.get<double>("OUT"), 3.0);  // IN3..IN7 (zero) not multiplied in
}

TEST(Extensible, AllEightInputs) {
  BlockHarness h(registry(), "ADD", opts(IecType::DINT));  // harness default: all connected
  ASSERT_HARNESS_OK(h);
  for (int i = 1; i <= 8; ++i) h.set<std::int32_t>("IN" + std::to_string(i), i);
  h.scan();
  EXPECT_EQ(h.get<std::int32_t>("OUT"), 36);
  BlockHarness m(registry(), "MUL", opts(IecType::DINT));
  for (int i = 1; i <= 8; ++i) m.set<std::int32_t>("IN" + std::to_string(i), i);
  m.scan();
  EXPECT_EQ(m.get<std::int32_t>("OUT"), 40320);
}

TEST(Extensible, OnlyRequiredInputs) {
  BlockHarness h(registry(), "MUL", opts(IecType::INT, std::set<std::string>{"IN1", "IN2"}));
  ASSERT_HARNESS_OK(h);
  h.set<std::int16_t>("IN1", -4);
  h.set<std::int16_t>("IN2", 5);
  h.scan();
  EXPECT_EQ(h.get<std::int16_t>("OUT"), -20);
}

TEST(Extensible, WrapAroundAcrossSeveralInputs) {
  BlockHarness h(registry(), "ADD", opts(IecType::SINT, std::set<std::string>{"IN1", "IN2", "IN3"}));
  h.set<std::int8_t>("IN1", 100);
  h.set<std::int8_t>("IN2", 100);
  h.set<std::int8_t>("IN3", 100);
  h.scan();
  EXPECT_EQ(h.get<std::int8_t>("OUT"), 44);  // 300 - 256
}

}  // namespace
}  // namespace syncplc::iectest
