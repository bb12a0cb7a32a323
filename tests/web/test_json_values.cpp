// Values in JSON: exact where JSON can be, IEC text where it cannot
// (docs/http-api.md, "Reading"), and written values into the one parser.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "runtime/core/units.hpp"
#include "runtime/web/json_values.hpp"

namespace syncplc::web {
namespace {

Cell of(IecType t, const char* text) {
  std::string why;
  auto c = parse_value(t, text, &why);
  EXPECT_TRUE(c) << text << ": " << why;
  return c.value_or(Cell{});
}

TEST(JsonValues, NumbersBooleansAndText) {
  EXPECT_EQ(cell_json(IecType::BOOL, of(IecType::BOOL, "TRUE")), nlohmann::json(true));
  EXPECT_EQ(cell_json(IecType::DINT, of(IecType::DINT, "-123456")), nlohmann::json(-123456));
  EXPECT_EQ(cell_json(IecType::UINT, of(IecType::UINT, "65535")), nlohmann::json(65535));
  EXPECT_EQ(cell_json(IecType::LREAL, of(IecType::LREAL, "1.5")), nlohmann::json(1.5));
  EXPECT_EQ(cell_json(IecType::TIME, of(IecType::TIME, "T#1s500ms")), nlohmann::json("T#1s500ms"));
  // Past 2^53 a double would round: the exact value as text.
  EXPECT_EQ(cell_json(IecType::LINT, of(IecType::LINT, "9007199254740993")), nlohmann::json("9007199254740993"));
  EXPECT_EQ(cell_json(IecType::LINT, of(IecType::LINT, "9007199254740992")), nlohmann::json(9007199254740992LL));
  EXPECT_TRUE(cell_json(IecType::ULINT, of(IecType::ULINT, "18446744073709551615")).is_string());
  Cell nan;
  nan.set(std::numeric_limits<double>::quiet_NaN());
  EXPECT_TRUE(cell_json(IecType::LREAL, nan).is_string());  // JSON has no NaN
}

TEST(JsonValues, ArraysAreJsonArrays) {
  Cell c[3] = {of(IecType::INT, "1"), of(IecType::INT, "-2"), of(IecType::INT, "3")};
  EXPECT_EQ(cells_json(IecType::INT, c, 3, true), nlohmann::json::parse("[1,-2,3]"));
  EXPECT_EQ(cells_json(IecType::INT, c, 1, false), nlohmann::json(1));
}

TEST(JsonValues, WrittenValuesBecomeTheParsersText) {
  std::string why;
  EXPECT_EQ(value_text(true, &why), "TRUE");
  EXPECT_EQ(value_text(-7, &why), "-7");
  EXPECT_EQ(value_text(nlohmann::json::parse("18446744073709551615"), &why), "18446744073709551615");
  EXPECT_EQ(value_text("1500 mm", &why), "1500 mm");
  // A double reads back as the same double.
  const double v = 0.1 + 0.2;
  auto text = value_text(v, &why);
  ASSERT_TRUE(text);
  auto cell = parse_value_in_unit(IecType::LREAL, "", *text, &why);
  ASSERT_TRUE(cell) << why;
  EXPECT_EQ(cell->get<double>(), v);
  EXPECT_FALSE(value_text(nullptr, &why));
  EXPECT_NE(why.find("null"), std::string::npos);
  EXPECT_FALSE(value_text(nlohmann::json::object(), &why));
  EXPECT_FALSE(value_text(nlohmann::json::array(), &why));
}

}  // namespace
}  // namespace syncplc::web

namespace syncplc::web {
namespace {

TEST(JsonValues, ABodyThatIsNotJsonOrHoldsANumberBeyondADoubleIsAnErrorNeverAnException) {
  // The issue's case: {"value": 1e999} escaped the parser's error handling as a 500.
  std::string why;
  EXPECT_FALSE(parse_json_body(R"({"value": 1e999})", &why));
  EXPECT_EQ(why, "a number in the body is too large for a 64-bit float ('1e999')");
  EXPECT_FALSE(parse_json_body(R"({"value": -1e400})", &why));
  EXPECT_NE(why.find("too large"), std::string::npos) << why;
  EXPECT_FALSE(parse_json_body("{not json", &why));
  EXPECT_EQ(why, "the body is not valid JSON (at byte 3)");
  auto ok = parse_json_body(R"({"value": 1e308})", &why);
  ASSERT_TRUE(ok);
  EXPECT_EQ((*ok)["value"].get<double>(), 1e308);
}

}  // namespace
}  // namespace syncplc::web
