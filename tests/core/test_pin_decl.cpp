// The one pin-declaration helper: named steps set exactly their field.
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
