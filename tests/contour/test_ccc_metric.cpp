// The true contour-error metric of `syncplc sim --metrics`
// (runtime/project/contour_metric.*): distance from the path, its statistics,
// the JSON, and the project section's errors.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <nlohmann/json.hpp>

#include "fblocks/library.hpp"
#include "runtime/core/virtual_clock.hpp"
#include "runtime/project/loader.hpp"
#include "runtime/project/metrics.hpp"

namespace syncplc {
namespace {

TEST(CccMetric, DistanceFromCircleAndLine) {
  ContourPath c;
  c.cx = 1, c.cy = -2, c.radius = 0.5;
  EXPECT_NEAR(contour_distance(c, 1 + 0.3, -2 + 0.4), 0.0, 1e-15);
  EXPECT_DOUBLE_EQ(contour_distance(c, 1 + 0.6, -2 + 0.8), 0.5);   // outside: > 0
  EXPECT_DOUBLE_EQ(contour_distance(c, 1, -2), -0.5);               // the centre
  ContourPath l;
  l.kind = ContourPath::Kind::Line;
  l.px = 1, l.py = 1, l.dx = 0, l.dy = 1;  // northwards through (1, 1): right is +x
  EXPECT_DOUBLE_EQ(contour_distance(l, 3, 7), 2);
  EXPECT_DOUBLE_EQ(contour_distance(l, 0, -4), -1);
}

TEST(CccMetric, StatisticsOfTheSignedError) {
  ContourPath l;
  l.kind = ContourPath::Kind::Line;  // along +x through 0: right is -y
  ContourMetric m;
  for (double y : {-1.0, 2.0, -3.0, 0.0}) m.add(5, y, l);
  EXPECT_EQ(m.samples(), 4u);
  EXPECT_DOUBLE_EQ(m.mean(), (1 - 2 + 3 + 0) / 4.0);
  EXPECT_DOUBLE_EQ(m.mean_abs(), 6 / 4.0);
  EXPECT_DOUBLE_EQ(m.max_abs(), 3);
  EXPECT_DOUBLE_EQ(m.rms(), std::sqrt(14 / 4.0));
}

// Two axes moved along a known track by an integrator: after scan k
// (k = 0, 1, ...) x = 1 m + (k + 1) mm, y = 0, against the circle of radius
// 1 m about the origin: the error is exactly (k + 1) mm (outside the circle).
TEST(CccMetric, SampledWithTheAxisErrorsAndReportedInJson) {
  LoadOptions o;
  o.blocks = &builtin_blocks();
  auto r = load_project_text(R"(
tasks: [{name: servo, period: 1ms}]
tags:
  - {name: px, type: LREAL}
  - {name: py, type: LREAL}
  - {name: e, type: LREAL}
blocks:
  - {name: step, type: ADD, inputs: {IN2: 0.001}}
  - {name: hold, type: UNIT_DELAY}
  - {name: shift, type: ADD, inputs: {IN2: 1.0}}
connections:
  - step.OUT -> shift.IN1
  - shift.OUT -> px
  - hold.OUT -> step.IN1
  - step.OUT -> hold.IN
  - step.OUT -> e
metrics:
  axis_errors: e
  from: 0s
  contour: {axes: [px, py], circle: {center: [0, 0 m], radius: 1000 mm}}
)", "m.yaml", o);
  for (const auto& d : r.diagnostics.list()) ADD_FAILURE() << d.text();
  ASSERT_TRUE(r.program);
  ASSERT_TRUE(r.metrics.contour);
  EXPECT_EQ(r.metrics.contour->path.radius, 1.0);
  Program& p = *r.program;
  VirtualClock clock(p);
  MotionMetrics m(r.metrics);
  clock.on_time_point([&](std::int64_t t) { m.sample(p, clock.image_access(), t, clock.scans(m.task())); });
  clock.run_until(10'000'000);
  const ContourMetric* c = m.contour();
  ASSERT_NE(c, nullptr);
  ASSERT_EQ(c->samples(), 10u);
  EXPECT_NEAR(c->max_abs(), 0.010, 1e-12);  // 1 .. 10 mm
  EXPECT_NEAR(c->mean_abs(), 0.0055, 1e-12);
  EXPECT_NEAR(c->mean(), 0.0055, 1e-12);     // all outside: signed = magnitude
  EXPECT_NEAR(c->rms(), std::sqrt(385e-6 / 10), 1e-12);
  auto j = nlohmann::json::parse(m.json(p, 10'000'000, 0.1));
  const auto& ce = j["metrics"]["contour_error"];
  EXPECT_EQ(ce["axes"][0], "px");
  EXPECT_EQ(ce["axes"][1], "py");
  EXPECT_EQ(ce["path"]["circle"]["radius"], 1.0);
  EXPECT_EQ(ce["samples"], 10);
  EXPECT_DOUBLE_EQ(ce["max_abs"].get<double>(), c->max_abs());
  EXPECT_DOUBLE_EQ(ce["rms"].get<double>(), c->rms());
  EXPECT_DOUBLE_EQ(ce["mean_abs"].get<double>(), c->mean_abs());
}

std::vector<std::string> load_errors(const std::string& metrics) {
  LoadOptions o;
  o.blocks = &builtin_blocks();
  auto r = load_project_text(R"(
tasks: [{name: servo, period: 1ms}, {name: slow, period: 10ms}]
tags:
  - {name: px, type: LREAL}
  - {name: n, type: INT}
  - {name: e, type: LREAL}
  - {name: other, type: LREAL}
blocks:
  - {name: a, type: ADD, inputs: {IN1: 1, IN2: 1}, task: servo}
  - {name: b, type: ADD, inputs: {IN1: 1, IN2: 1}, task: slow}
connections: [a.OUT -> e, b.OUT -> other]
)" + metrics, "m.yaml", o);
  std::vector<std::string> out;
  for (const auto& d : r.diagnostics.list()) out.push_back(d.text());
  return out;
}

TEST(CccMetric, ErrorsSayWhereAndWhat) {
  using ::testing::Contains;
  using ::testing::HasSubstr;
  EXPECT_THAT(load_errors("metrics: {axis_errors: e, contour: {axes: [px], circle: {center: [0, 0], radius: 1}}}"),
              Contains(HasSubstr("m.yaml:12:43: metrics contour: axes is a list of the two actual positions")));
  EXPECT_THAT(load_errors("metrics: {axis_errors: e, contour: {axes: [px, px]}}"),
              Contains(HasSubstr("exactly one of circle")));
  EXPECT_THAT(load_errors("metrics: {axis_errors: e, contour: {axes: [px, px], circle: {center: [0, 0], radius: -1}}}"),
              Contains(HasSubstr("circle radius must be a positive length")));
  EXPECT_THAT(load_errors("metrics: {axis_errors: e, contour: {axes: [px, px], line: {point: [0, 0], direction: [0, 0]}}}"),
              Contains(HasSubstr("line direction must not be [0, 0]")));
  EXPECT_THAT(load_errors("metrics: {axis_errors: e, contour: {axes: [px, n], circle: {center: [0, 0], radius: 1}}}"),
              Contains(HasSubstr("metrics contour: n must be one REAL or LREAL value")));
  EXPECT_THAT(load_errors("metrics: {axis_errors: e, contour: {axes: [px, nosuch], circle: {center: [0, 0], radius: 1}}}"),
              Contains(HasSubstr("metrics contour: ")));
  EXPECT_THAT(load_errors("metrics: {axis_errors: e, contour: {axes: [px, other], circle: {center: [0, 0], radius: 1}}}"),
              Contains(HasSubstr("other belongs to another task than the axis_errors")));
  EXPECT_THAT(load_errors("metrics: {axis_errors: e, contour: {axes: [px, px], circle: {center: [0], radius: 1}}}"),
              Contains(HasSubstr("circle center is written [x, y]")));
  EXPECT_THAT(load_errors("metrics: {axis_errors: e, contour: {axes: [px, px], square: 1}}"),
              Contains(HasSubstr("unknown key 'square' in metrics contour")));
}

}  // namespace
}  // namespace syncplc
