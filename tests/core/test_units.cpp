// Units: parse_unit, parse_quantity (conversion to a target unit), split_quantity.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <string>

#include "runtime/core/units.hpp"

namespace syncplc {
namespace {

using ::testing::HasSubstr;
constexpr double kPi = std::numbers::pi;

double q(const std::string& text, const std::string& target) {
  std::string err;
  auto v = parse_quantity(text, target, &err);
  EXPECT_TRUE(v.has_value()) << "'" << text << "' in '" << target << "': " << err;
  return v.value_or(NAN);
}

std::string qerr(const std::string& text, const std::string& target) {
  std::string err;
  auto v = parse_quantity(text, target, &err);
  EXPECT_FALSE(v.has_value()) << "'" << text << "' in '" << target << "' = " << *v;
  return err;
}

std::string uerr(const std::string& text) {
  std::string err;
  EXPECT_FALSE(parse_unit(text, &err).has_value()) << text;
  return err;
}

TEST(Units, ConversionToTheTargetUnit) {
  EXPECT_NEAR(q("3000 mm/min", "m/s"), 0.05, 1e-15);
  EXPECT_NEAR(q("21 m/min", "m/s"), 0.35, 1e-15);
  EXPECT_NEAR(q("36 km/h", "m/s"), 10.0, 1e-12);
  EXPECT_NEAR(q("180 deg", "rad"), kPi, 1e-15);
  EXPECT_NEAR(q("1 rev", "deg"), 360.0, 1e-12);
  EXPECT_NEAR(q("60 rev/min", "rad/s"), 2 * kPi, 1e-12);
  EXPECT_NEAR(q("2.5 in", "mm"), 63.5, 1e-12);
  EXPECT_NEAR(q("500 mA", "A"), 0.5, 1e-15);
  EXPECT_NEAR(q("1500 g", "kg"), 1.5, 1e-15);
  EXPECT_NEAR(q("1 kHz", "Hz"), 1000.0, 1e-9);
  EXPECT_NEAR(q("1 kHz", "1/s"), 1000.0, 1e-9);
  EXPECT_NEAR(q("2 ms", "s"), 0.002, 1e-18);
  EXPECT_NEAR(q("50 %", ""), 0.5, 1e-15);
  EXPECT_NEAR(q("50 %", "1"), 0.5, 1e-15);
}

TEST(Units, WithoutAUnitTheNumberIsInTheTargetUnit) {
  EXPECT_DOUBLE_EQ(q("2.5", "m/s"), 2.5);
  EXPECT_DOUBLE_EQ(q("-1e3", "mm"), -1000.0);
  EXPECT_DOUBLE_EQ(q("1_000", ""), 1000.0);
  EXPECT_DOUBLE_EQ(q("+4", "V"), 4.0);
}

TEST(Units, CompositesAndPowers) {
  EXPECT_NEAR(q("1000 mm/s^2", "m/s^2"), 1.0, 1e-15);
  EXPECT_NEAR(q("1 m/s/s", "m/s^2"), 1.0, 1e-15);
  EXPECT_NEAR(q("1 s^-1", "Hz"), 1.0, 1e-15);
  EXPECT_NEAR(q("1 m*m", "mm^2"), 1e6, 1e-6);
  EXPECT_NEAR(q("1 m.s", "ms*m"), 1000.0, 1e-9);
  // Motion control: speed per PWM duty, counts per revolution.
  EXPECT_NEAR(q("60 rev/min/PWM", "(rad/s)/PWM"), 2 * kPi, 1e-12);
  EXPECT_NEAR(q("6 (rev/min)/PWM", "rad/s/PWM"), 0.2 * kPi, 1e-12);
  EXPECT_NEAR(q("4096 counts/rev", "count/rad"), 4096 / (2 * kPi), 1e-9);
  EXPECT_NEAR(q("10 inc/mm", "count/m"), 10000.0, 1e-9);
}

TEST(Units, NumberAndUnitMayTouch) {
  EXPECT_NEAR(q("12.5mm/s", "m/s"), 0.0125, 1e-15);
  EXPECT_NEAR(q("1e-3m", "mm"), 1.0, 1e-12);
  EXPECT_NEAR(q("-2.5E+2mm", "m"), -0.25, 1e-15);
}

TEST(Units, DimensionMismatch) {
  EXPECT_EQ(qerr("3 kg", "m/s"), "unit 'kg' is not compatible with 'm/s'");
  EXPECT_EQ(qerr("1 rad/s", "m/s"), "unit 'rad/s' is not compatible with 'm/s'");
  EXPECT_EQ(qerr("1 Hz", "s"), "unit 'Hz' is not compatible with 's'");
  EXPECT_EQ(qerr("2 m", ""), "'2 m' has a unit but the value is dimensionless");
  EXPECT_EQ(qerr("1 rev/min", "rad/s/PWM"), "unit 'rev/min' is not compatible with 'rad/s/PWM'");
}

TEST(Units, BadUnitsAndNumbers) {
  EXPECT_EQ(qerr("3 parsec", "m"), "bad unit 'parsec': unknown unit 'parsec'");
  EXPECT_EQ(qerr("fast", "m"), "'fast' is not a number");
  EXPECT_EQ(qerr("", "m"), "'' is not a number");
  EXPECT_EQ(qerr("1.2.3 m", "m"), "'1.2.3 m' is not a number");
  EXPECT_THAT(qerr("1 m", "furlong"), HasSubstr("unknown unit 'furlong'"));  // the target itself is bad
  EXPECT_EQ(uerr("m^5"), "bad unit 'm^5': bad exponent");
  EXPECT_EQ(uerr("m^0"), "bad unit 'm^0': bad exponent");
  EXPECT_EQ(uerr("m/"), "bad unit 'm/': expected a unit name");
  EXPECT_EQ(uerr("(m/s"), "bad unit '(m/s': missing ')'");
  EXPECT_EQ(uerr("m s"), "bad unit 'm s': unexpected text");
  EXPECT_EQ(uerr("degC"), "bad unit 'degC': unknown unit 'degC'");
  EXPECT_EQ(uerr("M"), "bad unit 'M': unknown unit 'M'");  // unit names are case-sensitive
}

TEST(Units, ParseUnit) {
  std::string err;
  auto none = parse_unit("", &err);
  ASSERT_TRUE(none.has_value());
  EXPECT_DOUBLE_EQ(none->scale, 1.0);
  EXPECT_TRUE(none->same_dimension(Unit{}));
  auto acc = parse_unit("mm/s^2", &err);
  ASSERT_TRUE(acc.has_value()) << err;
  EXPECT_DOUBLE_EQ(acc->scale, 1e-3);
  EXPECT_EQ(acc->dim[0], 1);   // m
  EXPECT_EQ(acc->dim[1], -2);  // s
  auto hz = parse_unit("Hz", &err);
  auto per_s = parse_unit("1/s", &err);
  ASSERT_TRUE(hz && per_s);
  EXPECT_TRUE(hz->same_dimension(*per_s));
  auto deg = parse_unit("deg", &err);
  ASSERT_TRUE(deg.has_value());
  EXPECT_NEAR(deg->scale, kPi / 180, 1e-18);
  EXPECT_FALSE(deg->same_dimension(Unit{}));  // angles are a dimension of their own
}

TEST(Units, SplitQuantity) {
  std::string n, u;
  split_quantity("12.5 mm/s", n, u);
  EXPECT_EQ(n, "12.5");
  EXPECT_EQ(u, "mm/s");
  split_quantity("  -1e3m ", n, u);
  EXPECT_EQ(n, "-1e3");
  EXPECT_EQ(u, "m");
  split_quantity("1_000", n, u);
  EXPECT_EQ(n, "1_000");
  EXPECT_EQ(u, "");
  split_quantity("m/s", n, u);
  EXPECT_EQ(n, "");
  EXPECT_EQ(u, "m/s");
  split_quantity("2e", n, u);  // 'e' without an exponent is a unit name
  EXPECT_EQ(n, "2");
  EXPECT_EQ(u, "e");
}

}  // namespace
}  // namespace syncplc
