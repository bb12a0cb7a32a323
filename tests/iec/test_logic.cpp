// AND, OR, XOR, NOT: logical on BOOL, bitwise on BYTE..LWORD.
#include "tests/iec/iec_test_util.hpp"

namespace syncplc::iectest {
namespace {

template <class V>
V op2(const char* type, IecType dt, V a, V b) {
  BlockHarness h(registry(), type, opts(dt, std::set<std::string>{"IN1", "IN2"}));
  EXPECT_TRUE(h.ok()) << type << ": " << errors_of(h);
  h.set<V>("IN1", a);
  h.set<V>("IN2", b);
  h.scan();
  return h.get<V>("OUT");
}

template <class V>
V op_not(IecType dt, V a) {
  BlockHarness h(registry(), "NOT", opts(dt));
  EXPECT_TRUE(h.ok()) << errors_of(h);
  h.set<V>("IN", a);
  h.scan();
  return h.get<V>("OUT");
}

TEST(Logic, BoolTruthTables) {
  for (bool a : {false, true})
    for (bool b : {false, true}) {
      EXPECT_EQ(op2<bool>("AND", IecType::BOOL, a, b), a && b);
      EXPECT_EQ(op2<bool>("OR", IecType::BOOL, a, b), a || b);
      EXPECT_EQ(op2<bool>("XOR", IecType::BOOL, a, b), a != b);
    }
  EXPECT_EQ(op_not<bool>(IecType::BOOL, false), true);
  EXPECT_EQ(op_not<bool>(IecType::BOOL, true), false);
}

TEST(Logic, DefaultsToBool) {
  BlockHarness h(registry(), "AND", opts(std::nullopt, std::set<std::string>{"IN1", "IN2"}));
  ASSERT_HARNESS_OK(h);
  h.set<bool>("IN1", true);
  h.set<bool>("IN2", true);
  h.scan();
  EXPECT_TRUE(h.get<bool>("OUT"));
  EXPECT_EQ(h.cell("OUT").raw, 1u);
}

TEST(Logic, BitwiseWord) {
  EXPECT_EQ(op2<std::uint16_t>("AND", IecType::WORD, 0xF0F0, 0xFF00), 0xF000);
  EXPECT_EQ(op2<std::uint16_t>("OR", IecType::WORD, 0xF0F0, 0x0F00), 0xFFF0);
  EXPECT_EQ(op2<std::uint16_t>("XOR", IecType::WORD, 0xFFFF, 0x1234), 0xEDCB);
  EXPECT_EQ(op_not<std::uint16_t>(IecType::WORD, 0x00FF), 0xFF00);
}

TEST(Logic, BitwiseOtherWidths) {
  EXPECT_EQ(op_not<std::uint8_t>(IecType::BYTE, 0x0F), 0xF0);
  EXPECT_EQ(op2<std::uint8_t>("XOR", IecType::BYTE, 0xAA, 0xFF), 0x55);
  EXPECT_EQ(op_not<std::uint32_t>(IecType::DWORD, 0), 0xFFFFFFFFu);
  EXPECT_EQ(op2<std::uint64_t>("OR", IecType::LWORD, 1ull << 63, 1), (1ull << 63) | 1);
  EXPECT_EQ(op_not<std::uint64_t>(IecType::LWORD, 0), ~0ull);
  // The complement stays within the type's width: no bits above it in the cell.
  BlockHarness h(registry(), "NOT", opts(IecType::BYTE));
  h.set<std::uint8_t>("IN", 0);
  h.scan();
  EXPECT_EQ(h.cell("OUT").raw, 0xFFu);
}

TEST(Logic, ExtensibleWithSomeInputsConnected) {
  const std::set<std::string> conn{"IN1", "IN2", "IN6"};
  BlockHarness a(registry(), "AND", opts(IecType::WORD, conn));
  BlockHarness o(registry(), "OR", opts(IecType::WORD, conn));
  for (auto* h : {&a, &o}) {
    ASSERT_HARNESS_OK(*h);
    h->set<std::uint16_t>("IN1", 0x0FFF);
    h->set<std::uint16_t>("IN2", 0xFF0F);
    h->set<std::uint16_t>("IN3", 0x0000);  // unconnected: would clear everything for AND
    h->set<std::uint16_t>("IN4", 0xFFFF);  // unconnected: would set everything for OR
    h->set<std::uint16_t>("IN6", 0x3C3C);
    h->scan();
  }
  EXPECT_EQ(a.get<std::uint16_t>("OUT"), 0x0F0F & 0x3C3C);
  EXPECT_EQ(o.get<std::uint16_t>("OUT"), 0xFFFF);
}

TEST(Logic, XorOfThreeIsParity) {
  BlockHarness h(registry(), "XOR", opts(IecType::BOOL, std::set<std::string>{"IN1", "IN2", "IN3"}));
  ASSERT_HARNESS_OK(h);
  for (int m = 0; m < 8; ++m) {
    h.set<bool>("IN1", m & 1);
    h.set<bool>("IN2", m & 2);
    h.set<bool>("IN3", m & 4);
    h.scan();
    EXPECT_EQ(h.get<bool>("OUT"), __builtin_popcount(static_cast<unsigned>(m)) % 2 == 1) << m;
  }
}

TEST(Logic, AndOrOfEightBools) {
  BlockHarness a(registry(), "AND", opts(IecType::BOOL));
  BlockHarness o(registry(), "OR", opts(IecType::BOOL));
  for (int i = 1; i <= 8; ++i) {
    a.set<bool>("IN" + std::to_string(i), true);
    o.set<bool>("IN" + std::to_string(i), false);
  }
  a.scan();
  o.scan();
  EXPECT_TRUE(a.get<bool>("OUT"));
  EXPECT_FALSE(o.get<bool>("OUT"));
  a.set<bool>("IN8", false);
  o.set<bool>("IN8", true);
  a.scan();
  o.scan();
  EXPECT_FALSE(a.get<bool>("OUT"));
  EXPECT_TRUE(o.get<bool>("OUT"));
}

TEST(Logic, RejectsNonBitTypes) {
  for (const char* type : {"AND", "OR", "XOR", "NOT"})
    for (IecType t : {IecType::INT, IecType::UINT, IecType::REAL, IecType::TIME}) {
      BlockHarness h(registry(), type, opts(t));
      EXPECT_FALSE(h.ok()) << type << " " << type_name(t);
    }
}

}  // namespace
}  // namespace syncplc::iectest
