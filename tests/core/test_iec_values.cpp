// parse_value / format_value for every IEC elementary type: limits, bases,
// underscores, TRUE/FALSE, typed literals, errors, and text round trips.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <limits>
#include <string>

#include "runtime/core/iec_type.hpp"

namespace syncplc {
namespace {

using ::testing::HasSubstr;

// The parsed cell, or a failure carrying the error text.
Cell parse_ok(IecType t, const std::string& text) {
  std::string err;
  auto c = parse_value(t, text, &err);
  EXPECT_TRUE(c.has_value()) << type_name(t) << " '" << text << "': " << err;
  return c.value_or(Cell{});
}

std::string parse_err(IecType t, const std::string& text) {
  std::string err;
  auto c = parse_value(t, text, &err);
  EXPECT_FALSE(c.has_value()) << type_name(t) << " '" << text << "' parsed";
  return err;
}

template <class N>
N as(IecType t, const std::string& text) {
  return parse_ok(t, text).get<N>();
}

TEST(IecValues, TypeNames) {
  for (int i = 0; i < kIecTypeCount; ++i) {
    auto t = static_cast<IecType>(i);
    EXPECT_EQ(parse_type_name(type_name(t)), t);
  }
  EXPECT_EQ(parse_type_name(" lreal "), IecType::LREAL);
  EXPECT_EQ(parse_type_name("LTIME"), IecType::TIME);
  EXPECT_FALSE(parse_type_name("FLOAT").has_value());
  EXPECT_FALSE(parse_type_name("").has_value());
}

TEST(IecValues, Bool) {
  for (const char* s : {"TRUE", "true", "True", "1", "ON", "yes", "BOOL#TRUE", " TRUE "})
    EXPECT_TRUE(as<bool>(IecType::BOOL, s)) << s;
  for (const char* s : {"FALSE", "false", "0", "off", "NO", "BOOL#0"}) EXPECT_FALSE(as<bool>(IecType::BOOL, s)) << s;
  EXPECT_EQ(parse_err(IecType::BOOL, "maybe"), "'maybe' is not a BOOL (TRUE or FALSE)");
  EXPECT_THAT(parse_err(IecType::BOOL, "2"), HasSubstr("is not a BOOL"));
  EXPECT_THAT(parse_err(IecType::BOOL, ""), HasSubstr("is not a BOOL"));
  EXPECT_EQ(format_value(IecType::BOOL, parse_ok(IecType::BOOL, "TRUE")), "TRUE");
  EXPECT_EQ(format_value(IecType::BOOL, Cell{}), "FALSE");
}

TEST(IecValues, SignedIntegerLimits) {
  EXPECT_EQ(as<std::int8_t>(IecType::SINT, "-128"), -128);
  EXPECT_EQ(as<std::int8_t>(IecType::SINT, "127"), 127);
  EXPECT_EQ(parse_err(IecType::SINT, "128"), "value 128 is out of range for SINT (-128 .. 127)");
  EXPECT_EQ(parse_err(IecType::SINT, "-129"), "value -129 is out of range for SINT (-128 .. 127)");
  EXPECT_EQ(as<std::int16_t>(IecType::INT, "-32768"), -32768);
  EXPECT_EQ(as<std::int16_t>(IecType::INT, "32767"), 32767);
  EXPECT_EQ(parse_err(IecType::INT, "40000"), "value 40000 is out of range for INT (-32768 .. 32767)");
  EXPECT_EQ(as<std::int32_t>(IecType::DINT, "-2147483648"), INT32_MIN);
  EXPECT_EQ(as<std::int32_t>(IecType::DINT, "2147483647"), INT32_MAX);
  EXPECT_THAT(parse_err(IecType::DINT, "2147483648"), HasSubstr("out of range for DINT"));
  EXPECT_EQ(as<std::int64_t>(IecType::LINT, "-9223372036854775808"), INT64_MIN);
  EXPECT_EQ(as<std::int64_t>(IecType::LINT, "9223372036854775807"), INT64_MAX);
  EXPECT_THAT(parse_err(IecType::LINT, "9223372036854775808"), HasSubstr("out of range for LINT"));
  EXPECT_THAT(parse_err(IecType::LINT, "-9223372036854775809"), HasSubstr("out of range for LINT"));
}

TEST(IecValues, UnsignedIntegerLimits) {
  EXPECT_EQ(as<std::uint8_t>(IecType::USINT, "255"), 255);
  EXPECT_EQ(parse_err(IecType::USINT, "256"), "value 256 is out of range for USINT (0 .. 255)");
  EXPECT_EQ(parse_err(IecType::USINT, "-1"), "value -1 is out of range for USINT (unsigned)");
  EXPECT_EQ(as<std::uint8_t>(IecType::USINT, "-0"), 0);
  EXPECT_EQ(as<std::uint16_t>(IecType::UINT, "65535"), 65535);
  EXPECT_THAT(parse_err(IecType::UINT, "65536"), HasSubstr("out of range for UINT"));
  EXPECT_EQ(as<std::uint32_t>(IecType::UDINT, "4294967295"), UINT32_MAX);
  EXPECT_THAT(parse_err(IecType::UDINT, "4294967296"), HasSubstr("out of range for UDINT"));
  EXPECT_EQ(as<std::uint64_t>(IecType::ULINT, "18446744073709551615"), UINT64_MAX);
  EXPECT_THAT(parse_err(IecType::ULINT, "18446744073709551616"), HasSubstr("out of range for ULINT"));
  EXPECT_THAT(parse_err(IecType::ULINT, "123456789012345678901234567890"), HasSubstr("is too large"));
}

TEST(IecValues, BitStrings) {
  EXPECT_EQ(as<std::uint8_t>(IecType::BYTE, "16#FF"), 0xFF);
  EXPECT_THAT(parse_err(IecType::BYTE, "16#100"), HasSubstr("out of range for BYTE (0 .. 255)"));
  EXPECT_EQ(as<std::uint16_t>(IecType::WORD, "16#ffff"), 0xFFFF);
  EXPECT_EQ(as<std::uint32_t>(IecType::DWORD, "16#DEAD_BEEF"), 0xDEADBEEFu);
  EXPECT_EQ(as<std::uint64_t>(IecType::LWORD, "16#FFFF_FFFF_FFFF_FFFF"), UINT64_MAX);
  EXPECT_THAT(parse_err(IecType::WORD, "-1"), HasSubstr("(unsigned)"));
  EXPECT_EQ(format_value(IecType::BYTE, parse_ok(IecType::BYTE, "10")), "16#0A");
  EXPECT_EQ(format_value(IecType::WORD, parse_ok(IecType::WORD, "255")), "16#00FF");
  EXPECT_EQ(format_value(IecType::DWORD, parse_ok(IecType::DWORD, "1")), "16#00000001");
  EXPECT_EQ(format_value(IecType::LWORD, parse_ok(IecType::LWORD, "16#FFFF_FFFF_FFFF_FFFF")), "16#FFFFFFFFFFFFFFFF");
}

TEST(IecValues, BasesAndUnderscores) {
  EXPECT_EQ(as<std::int32_t>(IecType::DINT, "16#7F"), 127);
  EXPECT_EQ(as<std::int32_t>(IecType::DINT, "-16#80"), -128);
  EXPECT_EQ(as<std::int32_t>(IecType::DINT, "8#777"), 511);
  EXPECT_EQ(as<std::int32_t>(IecType::DINT, "2#1010_1010"), 170);
  EXPECT_EQ(as<std::int32_t>(IecType::DINT, "0x1F"), 31);
  EXPECT_EQ(as<std::int32_t>(IecType::DINT, "0b101"), 5);
  EXPECT_EQ(as<std::int32_t>(IecType::DINT, "1_000_000"), 1'000'000);
  EXPECT_EQ(as<std::int32_t>(IecType::DINT, "+42"), 42);
  EXPECT_EQ(as<std::int32_t>(IecType::DINT, "  7  "), 7);
  EXPECT_THAT(parse_err(IecType::DINT, "2#102"), HasSubstr("is not an integer"));
  EXPECT_THAT(parse_err(IecType::DINT, "8#8"), HasSubstr("is not an integer"));
  EXPECT_THAT(parse_err(IecType::DINT, "16#"), HasSubstr("is not an integer"));
  EXPECT_THAT(parse_err(IecType::DINT, "12abc"), HasSubstr("is not an integer"));
  EXPECT_THAT(parse_err(IecType::DINT, "1.5"), HasSubstr("is not an integer"));
  EXPECT_THAT(parse_err(IecType::DINT, ""), HasSubstr("is not an integer"));
  EXPECT_THAT(parse_err(IecType::DINT, "-"), HasSubstr("is not an integer"));
}

TEST(IecValues, TypedLiterals) {
  EXPECT_EQ(as<std::int16_t>(IecType::INT, "INT#5"), 5);
  EXPECT_EQ(as<std::int16_t>(IecType::INT, "int#-5"), -5);
  EXPECT_EQ(as<std::uint16_t>(IecType::WORD, "WORD#16#FF"), 0xFF);
  EXPECT_FLOAT_EQ(as<float>(IecType::REAL, "REAL#1.5"), 1.5f);
  EXPECT_EQ(parse_err(IecType::INT, "DINT#5"), "literal DINT#5 is DINT, expected INT");
  EXPECT_EQ(parse_err(IecType::LREAL, "REAL#1.5"), "literal REAL#1.5 is REAL, expected LREAL");
  EXPECT_EQ(parse_err(IecType::BOOL, "INT#1"), "literal INT#1 is INT, expected BOOL");
  EXPECT_THAT(parse_err(IecType::SINT, "SINT#200"), HasSubstr("out of range for SINT"));
  // A base prefix is not a type prefix.
  EXPECT_EQ(as<std::int16_t>(IecType::INT, "16#10"), 16);
}

TEST(IecValues, Reals) {
  EXPECT_FLOAT_EQ(as<float>(IecType::REAL, "1.5e3"), 1500.0f);
  EXPECT_FLOAT_EQ(as<float>(IecType::REAL, "-0.25"), -0.25f);
  EXPECT_FLOAT_EQ(as<float>(IecType::REAL, "3.4e38"), 3.4e38f);
  EXPECT_EQ(parse_err(IecType::REAL, "3.5e38"), "value 3.5e38 is out of range for REAL");
  EXPECT_DOUBLE_EQ(as<double>(IecType::LREAL, "1_000.5"), 1000.5);
  EXPECT_DOUBLE_EQ(as<double>(IecType::LREAL, "+2"), 2.0);
  EXPECT_DOUBLE_EQ(as<double>(IecType::LREAL, "1.7976931348623157e308"), 1.7976931348623157e308);
  EXPECT_THAT(parse_err(IecType::LREAL, "1e309"), HasSubstr("is not a number"));
  EXPECT_THAT(parse_err(IecType::LREAL, "inf"), HasSubstr("is not a number"));
  EXPECT_THAT(parse_err(IecType::LREAL, "nan"), HasSubstr("is not a number"));
  EXPECT_THAT(parse_err(IecType::LREAL, "fast"), HasSubstr("is not a number"));
  EXPECT_THAT(parse_err(IecType::LREAL, "1.5 m"), HasSubstr("is not a number"));  // units: parse_quantity
  EXPECT_EQ(parse_err(IecType::LREAL, ""), "empty number");
}

TEST(IecValues, RealsFormatAsTheShortestExactText) {
  EXPECT_EQ(format_value(IecType::LREAL, parse_ok(IecType::LREAL, "0.35")), "0.35");
  EXPECT_EQ(format_value(IecType::LREAL, parse_ok(IecType::LREAL, "-1.5")), "-1.5");
  EXPECT_EQ(format_value(IecType::LREAL, parse_ok(IecType::LREAL, "1e-7")), "1e-07");
  EXPECT_EQ(format_value(IecType::REAL, parse_ok(IecType::REAL, "0.1")), "0.1");
  EXPECT_EQ(format_value(IecType::LREAL, Cell{}), "0");
  // Every double reads back exactly from its text.
  for (double d : {0.1, 1.0 / 3.0, 6.02214076e23, -2.2250738585072014e-308, 123456.789}) {
    Cell c;
    c.set<double>(d);
    EXPECT_EQ(parse_ok(IecType::LREAL, format_value(IecType::LREAL, c)).get<double>(), d);
  }
}

TEST(IecValues, Time) {
  EXPECT_EQ(as<std::int64_t>(IecType::TIME, "T#1s500ms"), 1'500'000'000);
  EXPECT_EQ(as<std::int64_t>(IecType::TIME, "TIME#250ms"), 250'000'000);
  EXPECT_EQ(as<std::int64_t>(IecType::TIME, "LTIME#1us"), 1'000);
  EXPECT_EQ(as<std::int64_t>(IecType::TIME, "250ms"), 250'000'000);
  EXPECT_EQ(as<std::int64_t>(IecType::TIME, "-1s"), -1'000'000'000);
  EXPECT_THAT(parse_err(IecType::TIME, "5"), HasSubstr("missing unit after 5"));
  EXPECT_EQ(format_value(IecType::TIME, parse_ok(IecType::TIME, "1500ms")), "T#1s500ms");
  EXPECT_EQ(format_value(IecType::TIME, parse_ok(IecType::TIME, "-2m")), "T#-2m");
  EXPECT_EQ(format_value(IecType::TIME, Cell{}), "T#0ms");
}

TEST(IecValues, IntegersFormatInDecimal) {
  EXPECT_EQ(format_value(IecType::SINT, parse_ok(IecType::SINT, "-128")), "-128");
  EXPECT_EQ(format_value(IecType::INT, parse_ok(IecType::INT, "16#7FFF")), "32767");
  EXPECT_EQ(format_value(IecType::LINT, parse_ok(IecType::LINT, "-9223372036854775808")), "-9223372036854775808");
  EXPECT_EQ(format_value(IecType::USINT, parse_ok(IecType::USINT, "255")), "255");
  EXPECT_EQ(format_value(IecType::ULINT, parse_ok(IecType::ULINT, "18446744073709551615")), "18446744073709551615");
}

TEST(IecValues, EveryLimitRoundTripsThroughItsText) {
  auto round_trip = [](IecType t, const std::string& text) {
    Cell c = parse_ok(t, text);
    std::string shown = format_value(t, c);
    Cell back = parse_ok(t, shown);
    EXPECT_EQ(back.raw, c.raw) << type_name(t) << " " << text << " -> " << shown;
  };
  const std::pair<IecType, const char*> cases[] = {
      {IecType::BOOL, "TRUE"},       {IecType::BOOL, "FALSE"},
      {IecType::SINT, "-128"},       {IecType::SINT, "127"},
      {IecType::INT, "-32768"},      {IecType::INT, "32767"},
      {IecType::DINT, "-2147483648"}, {IecType::DINT, "2147483647"},
      {IecType::LINT, "-9223372036854775808"}, {IecType::LINT, "9223372036854775807"},
      {IecType::USINT, "255"},       {IecType::UINT, "65535"},
      {IecType::UDINT, "4294967295"}, {IecType::ULINT, "18446744073709551615"},
      {IecType::BYTE, "16#FF"},      {IecType::WORD, "16#FFFF"},
      {IecType::DWORD, "16#FFFFFFFF"}, {IecType::LWORD, "16#FFFFFFFFFFFFFFFF"},
      {IecType::REAL, "3.4e38"}, {IecType::REAL, "-1.17549435e-38"}, {IecType::REAL, "1e-45"},
      {IecType::LREAL, "1.7976931348623157e308"}, {IecType::LREAL, "-5e-324"},
      {IecType::TIME, "T#2555555h"}, {IecType::TIME, "-1ns"},
  };
  for (const auto& [t, text] : cases) round_trip(t, text);
}

// The largest REAL formats as 3.4028235e+38 (the shortest text that reads back
// as that float) and reads back: only what rounds to infinity is out of range.
TEST(IecValues, LargestRealRoundTrips) {
  Cell c;
  c.set<float>(std::numeric_limits<float>::max());
  EXPECT_EQ(format_value(IecType::REAL, c), "3.4028235e+38");
  EXPECT_EQ(parse_ok(IecType::REAL, format_value(IecType::REAL, c)).raw, c.raw);
  c.set<float>(-std::numeric_limits<float>::max());
  EXPECT_EQ(parse_ok(IecType::REAL, format_value(IecType::REAL, c)).raw, c.raw);
  std::string why;
  EXPECT_FALSE(parse_value(IecType::REAL, "3.4028236e38", &why));  // rounds to infinity
  EXPECT_NE(why.find("out of range for REAL"), std::string::npos) << why;
}

TEST(IecValues, Classes) {
  EXPECT_TRUE(in_class(IecType::TIME, TypeClass::ANY_MAGNITUDE));
  EXPECT_FALSE(in_class(IecType::TIME, TypeClass::ANY_NUM));
  EXPECT_TRUE(in_class(IecType::USINT, TypeClass::ANY_INT));
  EXPECT_FALSE(in_class(IecType::BYTE, TypeClass::ANY_INT));
  EXPECT_TRUE(in_class(IecType::BOOL, TypeClass::ANY_BIT));
  EXPECT_FALSE(in_class(IecType::REAL, TypeClass::ANY_BIT));
  EXPECT_TRUE(in_class(IecType::REAL, TypeClass::ANY_REAL));
  EXPECT_FALSE(in_class(IecType::LINT, TypeClass::ANY_REAL));
  EXPECT_TRUE(in_class(IecType::TIME, TypeClass::ANY));
  EXPECT_FALSE(in_class(IecType::INT, TypeClass::Exact));
  EXPECT_EQ(bit_width(IecType::BOOL), 1);
  EXPECT_EQ(bit_width(IecType::USINT), 8);
  EXPECT_EQ(bit_width(IecType::WORD), 16);
  EXPECT_EQ(bit_width(IecType::REAL), 32);
  EXPECT_EQ(bit_width(IecType::TIME), 64);
}

TEST(IecValues, CellAsDouble) {
  EXPECT_DOUBLE_EQ(cell_as_double(IecType::TIME, parse_ok(IecType::TIME, "1500ms")), 1.5);  // seconds
  EXPECT_DOUBLE_EQ(cell_as_double(IecType::SINT, parse_ok(IecType::SINT, "-3")), -3.0);
  EXPECT_DOUBLE_EQ(cell_as_double(IecType::BOOL, parse_ok(IecType::BOOL, "TRUE")), 1.0);
  EXPECT_DOUBLE_EQ(cell_as_double(IecType::REAL, parse_ok(IecType::REAL, "0.5")), 0.5);
}

}  // namespace
}  // namespace syncplc
