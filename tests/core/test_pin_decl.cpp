// The one pin- and parameter-declaration helper: named steps set exactly their field.
#include "runtime/core/pin_decl.hpp"

#include <gtest/gtest.h>

#include "runtime/core/monotonic_clock.hpp"

namespace syncplc {
namespace {

TEST(PinDecl, NamedStepsSetTheirFields) {
  PinDecl x = input("x", IecType::LREAL).unit("m").doc("measured position").required();
  EXPECT_EQ(x.name, "x");
  EXPECT_EQ(x.dir, PinDir::In);
  EXPECT_EQ(x.cls, TypeClass::Exact);
  EXPECT_EQ(x.type, IecType::LREAL);
  EXPECT_EQ(x.unit, "m");
  EXPECT_EQ(x.doc, "measured position");
  EXPECT_TRUE(x.required);
  EXPECT_TRUE(x.init.empty());
  EXPECT_FALSE(x.is_array());

  PinDecl w = input("w", IecType::LREAL).array("n").init("1");
  EXPECT_FALSE(w.required);
  EXPECT_EQ(w.length_param, "n");
  EXPECT_EQ(w.init, "1");
  EXPECT_TRUE(w.is_array());

  PinDecl out = output("OUT", TypeClass::ANY_NUM).doc("sum");
  EXPECT_EQ(out.dir, PinDir::Out);
  EXPECT_EQ(out.cls, TypeClass::ANY_NUM);
  EXPECT_EQ(out.doc, "sum");
}

TEST(ParamDecl, NamedStepsSetTheirFields) {
  ParamDecl kp = parameter("kp", IecType::LREAL).init("1").min(0).max(10).unit("1/s").doc("gain").tunable();
  EXPECT_EQ(kp.name, "kp");
  EXPECT_EQ(kp.type, IecType::LREAL);
  EXPECT_EQ(kp.default_value, "1");
  EXPECT_EQ(kp.min, 0.0);
  EXPECT_EQ(kp.max, 10.0);
  EXPECT_EQ(kp.unit, "1/s");
  EXPECT_EQ(kp.doc, "gain");
  EXPECT_TRUE(kp.tunable);

  // Nothing but name and type: mandatory, unbounded, structural.
  ParamDecl n = parameter("n", IecType::DINT);
  EXPECT_EQ(n.type, IecType::DINT);
  EXPECT_TRUE(n.default_value.empty());
  EXPECT_FALSE(n.min.has_value());
  EXPECT_FALSE(n.max.has_value());
  EXPECT_TRUE(n.unit.empty());
  EXPECT_TRUE(n.doc.empty());
  EXPECT_FALSE(n.tunable);

  ParamDecl lo = parameter("lo", IecType::LREAL).min(-1.5);
  EXPECT_EQ(lo.min, -1.5);
  EXPECT_FALSE(lo.max.has_value());
}

TEST(MonotonicClock, NeverGoesBack) {
  std::int64_t last = monotonic_ns();
  for (int i = 0; i < 1000; ++i) {
    const std::int64_t now = monotonic_ns();
    EXPECT_GE(now, last);
    last = now;
  }
  EXPECT_GT(last, 0);
}

}  // namespace
}  // namespace syncplc
