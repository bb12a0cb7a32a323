// Array pins: pins declared ARRAY[1..n] whose length comes from a parameter of
// the instance. They connect whole to array tags (or other array pins) and
// element by element; constants are one value for all or a list of n.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "runtime/core/virtual_clock.hpp"
#include "tests/project/loader_test_util.hpp"
#include "tests/support/project_fixture.hpp"

namespace syncplc {
namespace {

using loadertest::has_error;

LoadResult load_arrays(const std::string& text, std::vector<ParamOverride> overrides = {}) {
  LoadOptions o;
  o.blocks = &testing::test_blocks();
  o.overrides = std::move(overrides);
  return load_project_text(loadertest::yaml(text.c_str()), "p.yaml", o);
}

std::vector<std::string> array_errors(const std::string& text, std::vector<ParamOverride> overrides = {}) {
  return loadertest::errors(load_arrays(text, std::move(overrides)));
}

double value(Program& p, const std::string& ref) {
  auto r = p.resolve(ref);
  EXPECT_TRUE(r) << ref;
  return r ? p.live_cell(*r, ::syncplc::testing::image_key())->get<double>() : 0.0;
}

TEST(ArrayPins, WholeArraysConnectToArrayTags) {
  auto p = load_test_project(R"(
tasks: [{name: main, period: 1ms}]
tags:
  - {name: a, type: "ARRAY[1..4] OF LREAL", init: [1, -2, 3, 4]}
  - {name: b, type: "ARRAY[0..3] OF LREAL"}
  - {name: f, type: "ARRAY[1..4] OF BOOL"}
  - {name: s, type: LREAL}
blocks:
  - {name: g, type: ARRAY_GAIN, params: {N: 4, GAIN: 10}}
connections:
  - a -> g.IN
  - g.OUT -> b
  - g.FLAGS -> f
  - g.SUM -> s
)");
  ASSERT_TRUE(p);
  VirtualClock clock(*p);
  clock.run_until(1'000'000);
  EXPECT_EQ(value(*p, "b[0]"), 10);
  EXPECT_EQ(value(*p, "b[1]"), -20);
  EXPECT_EQ(value(*p, "b[3]"), 40);
  EXPECT_EQ(value(*p, "s"), 6);
  EXPECT_TRUE(tag_cell(*p, "f[1]").get<bool>());
  EXPECT_FALSE(tag_cell(*p, "f[2]").get<bool>());
  // The pin itself resolves, 1-based, like the declared ARRAY[1..N].
  EXPECT_EQ(value(*p, "g.OUT[2]"), -20);
  EXPECT_EQ(value(*p, "g.IN[4]"), 4);
  auto whole = p->resolve("g.OUT");
  ASSERT_TRUE(whole);
  EXPECT_EQ(whole->length, 4u);
  std::string err;
  EXPECT_FALSE(p->resolve("g.OUT[0]", &err));
  EXPECT_FALSE(p->resolve("g.OUT[5]", &err));
  EXPECT_FALSE(p->resolve("g.SUM[1]", &err));
}

TEST(ArrayPins, ElementsConnectOneByOne) {
  auto p = load_test_project(R"(
tasks: [{name: main, period: 1ms}]
tags:
  - {name: x1, type: LREAL, init: 1.5}
  - {name: x3, type: LREAL, init: 2.5}
  - {name: arr, type: "ARRAY[1..3] OF LREAL", init: [7, 8, 9]}
  - {name: y2, type: LREAL}
  - {name: out, type: "ARRAY[1..3] OF LREAL"}
  - {name: z, type: LREAL}
blocks:
  - {name: g, type: ARRAY_GAIN}
  - {name: h, type: ARRAY_GAIN, params: {GAIN: 1}}
  - {name: m, type: MOVE}
connections:
  - x1 -> g.IN[1]
  - arr[2] -> g.IN[2]
  - x3 -> g.IN[3]
  - g.OUT[2] -> y2
  - g.OUT -> h.IN
  - h.OUT[1] -> out[3]
  - h.OUT[3] -> m.IN
  - m.OUT -> z
traces:
  - g.OUT[1]
  - h.OUT[3]
)");
  ASSERT_TRUE(p);
  VirtualClock clock(*p);
  clock.run_until(1'000'000);
  EXPECT_EQ(value(*p, "y2"), 16);
  EXPECT_EQ(value(*p, "out[3]"), 3);
  EXPECT_EQ(value(*p, "z"), 5);
  EXPECT_EQ(value(*p, "g.SUM"), 12);
  ASSERT_EQ(p->traces.size(), 2u);
}

TEST(ArrayPins, ConstantsAreOneValueForAllOrOnePerElement) {
  auto p = load_test_project(R"(
tasks: [{name: main, period: 1ms}]
blocks:
  - {name: all, type: ARRAY_GAIN, inputs: {IN: 2 mm}}
  - {name: each, type: ARRAY_GAIN, params: {N: 2}, inputs: {IN: [1, 3000 mm]}}
)");
  ASSERT_TRUE(p);
  VirtualClock clock(*p);
  clock.run_until(1'000'000);
  EXPECT_DOUBLE_EQ(value(*p, "all.SUM"), 0.006);  // 2 mm in each of 3 elements, in m
  EXPECT_DOUBLE_EQ(value(*p, "each.SUM"), 4);
  EXPECT_DOUBLE_EQ(value(*p, "each.OUT[2]"), 6);
}

TEST(ArrayPins, OverrideOfTheLengthParameterResizes) {
  LoadOptions o;
  o.blocks = &testing::test_blocks();
  o.overrides = {{"g", "N", "7"}};
  auto r = load_project_text("tasks: [{name: main, period: 1ms}]\nblocks: [{name: g, type: ARRAY_GAIN, inputs: {IN: 1}}]\n",
                             "p.yaml", o);
  ASSERT_TRUE(r.ok()) << loadertest::joined(r);
  VirtualClock clock(*r.program);
  clock.run_until(1'000'000);
  EXPECT_EQ(value(*r.program, "g.SUM"), 7);
  EXPECT_EQ(r.program->resolve("g.OUT")->length, 7u);
}

TEST(ArrayPinErrors, LengthMismatch) {
  EXPECT_THAT(array_errors(R"(
tasks: [{name: main, period: 1ms}]
tags: [{name: a, type: "ARRAY[1..3] OF LREAL"}]
blocks: [{name: g, type: ARRAY_GAIN, params: {N: 4}}]
connections:
  - a -> g.IN
)"),
              ::testing::ElementsAre("p.yaml:5:5: type mismatch: a is LREAL[3], g.IN is LREAL[4]"));
}

TEST(ArrayPinErrors, ElementIndexOutsideThePin) {
  EXPECT_THAT(array_errors(R"(
tasks: [{name: main, period: 1ms}]
tags: [{name: x, type: LREAL}]
blocks: [{name: g, type: ARRAY_GAIN}]
connections:
  - x -> g.IN[4]
  - x -> g.IN[0]
  - g.SUM[1] -> x
)"),
              ::testing::ElementsAre("p.yaml:5:10: index 4 is outside g.IN[1..3]",
                                     "p.yaml:6:10: index 0 is outside g.IN[1..3]",
                                     "p.yaml:7:5: pin g.SUM is not an array"));
}

TEST(ArrayPinErrors, TwoSourcesForOneElement) {
  auto e = array_errors(R"(
tasks: [{name: main, period: 1ms}]
tags: [{name: x, type: LREAL}, {name: a, type: "ARRAY[1..3] OF LREAL"}]
blocks: [{name: g, type: ARRAY_GAIN}]
connections:
  - x -> g.IN[2]
  - x -> g.IN[2]
  - a -> g.IN
)");
  EXPECT_THAT(e, has_error("p.yaml:6:10", "g.IN[2] already has a source (x -> g.IN[2] at p.yaml:5:5)"));
  EXPECT_THAT(e, has_error("p.yaml:7:10", "g.IN already has a source (x -> g.IN[2] at p.yaml:5:5)"));
  EXPECT_EQ(e.size(), 2u);
}

TEST(ArrayPinErrors, WholeThenElement) {
  EXPECT_THAT(array_errors(R"(
tasks: [{name: main, period: 1ms}]
tags: [{name: x, type: LREAL}, {name: a, type: "ARRAY[1..3] OF LREAL"}]
blocks: [{name: g, type: ARRAY_GAIN}]
connections:
  - a -> g.IN
  - x -> g.IN[1]
)"),
              ::testing::ElementsAre("p.yaml:6:10: g.IN[1] already has a source (a -> g.IN at p.yaml:5:5)"));
}

TEST(ArrayPinErrors, ConstantListOfTheWrongLength) {
  EXPECT_THAT(array_errors(R"(
tasks: [{name: main, period: 1ms}]
blocks:
  - {name: g, type: ARRAY_GAIN, inputs: {IN: [1, 2]}}
  - {name: h, type: ARRAY_GAIN, inputs: {IN: [1, 2, zz]}}
  - {name: k, type: ARRAY_GAIN, inputs: {SUM: [1, 2, 3]}}
)"),
              ::testing::ElementsAre(
                  "p.yaml:3:46: g.IN: 2 values for ARRAY[1..3] (give one value for every element, or a single value for all)",
                  ::testing::StartsWith("p.yaml:4:53: h.IN[3]: "),
                  "p.yaml:5:47: ARRAY_GAIN.SUM is an output: it takes no constant"));
}

TEST(ArrayPinErrors, LengthParameterOutOfRange) {
  EXPECT_THAT(array_errors(R"(
tasks: [{name: main, period: 1ms}]
tags: [{name: x, type: LREAL}]
blocks:
  - {name: g, type: ARRAY_GAIN, params: {N: 0}}
connections:
  - x -> g.IN[1]
)"),
              ::testing::ElementsAre("p.yaml:4:45: g.N = 0: array pin IN needs 1..4096 elements"));
  EXPECT_THAT(array_errors("tasks: [{name: main, period: 1ms}]\nblocks: [{name: g, type: ARRAY_GAIN}]\n",
                           {{"g", "N", "4097"}}),
              ::testing::ElementsAre("command line:0:0: g.N = 4097: array pin IN needs 1..4096 elements"));
}

TEST(ArrayPinErrors, TraceOfAWholeArrayPin) {
  EXPECT_THAT(array_errors(R"(
tasks: [{name: main, period: 1ms}]
blocks: [{name: g, type: ARRAY_GAIN}]
traces:
  - g.OUT
  - g.OUT[9]
)"),
              ::testing::ElementsAre(
                  "p.yaml:4:5: trace: g.OUT is an array; trace its elements (g.OUT[i])",
                  "p.yaml:5:5: trace: index 9 is outside g.OUT[1..3]"));
}

}  // namespace
}  // namespace syncplc
