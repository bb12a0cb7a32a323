// Motion metrics of `syncplc sim --metrics`: paper 000 eqs. (26)-(27).
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <nlohmann/json.hpp>

#include "runtime/core/virtual_clock.hpp"
#include "runtime/project/metrics.hpp"
#include "tests/project/loader_test_util.hpp"
#include "tests/support/project_fixture.hpp"

namespace syncplc {
namespace {

TEST(Metrics, TrackAndSyncRsmeFollowEquations26And27) {
  // Three axes whose errors ramp: e = (1, 2, 3) * k at scan k (k = 1..100),
  // made by a constant integrated through ADD + UNIT_DELAY per axis.
  auto r = load_test_result(R"(
tasks: [{name: servo, period: 1ms}, {name: slow, period: 7ms}]
tags:
  - {name: e, type: "ARRAY[1..3] OF LREAL"}
blocks:
  - {name: a1, type: ADD, inputs: {IN2: 1}, task: servo}
  - {name: d1, type: UNIT_DELAY, task: servo}
  - {name: a2, type: ADD, inputs: {IN2: 2}, task: servo}
  - {name: d2, type: UNIT_DELAY, task: servo}
  - {name: a3, type: ADD, inputs: {IN2: 3}, task: servo}
  - {name: d3, type: UNIT_DELAY, task: servo}
  - {name: idle, type: NOT, task: slow, inputs: {IN: TRUE}}
connections:
  - d1.OUT -> a1.IN1
  - a1.OUT -> d1.IN
  - a1.OUT -> e[1]
  - d2.OUT -> a2.IN1
  - a2.OUT -> d2.IN
  - a2.OUT -> e[2]
  - d3.OUT -> a3.IN1
  - a3.OUT -> d3.IN
  - a3.OUT -> e[3]
metrics: {axis_errors: e, from: 0s}
)");
  auto& p = r.program;
  ASSERT_TRUE(p);
  ASSERT_EQ(r.metrics.axis_errors.size(), 3u);
  EXPECT_EQ(r.metrics.axis_errors[2].label, "e[3]");
  VirtualClock clock(*p);
  MotionMetrics m(r.metrics);
  clock.on_time_point([&](std::int64_t t) { m.sample(*p, clock.image_access(), t, clock.scans(m.task())); });
  clock.run_until(100'000'000);  // scans 0..99 of servo, and the slow task's own time points
  ASSERT_EQ(m.samples(), 100u);
  double track = 0, sync = 0;
  for (int k = 1; k <= 100; ++k) {
    track += (1 + 4 + 9) * double(k) * k;
    const double eps2 = 2.0 * k - 1.0 * k, eps3 = 3.0 * k - 1.5 * k;  // eps = T e, eq. (6)
    sync += eps2 * eps2 + eps3 * eps3;
  }
  EXPECT_NEAR(m.track_rsme(), std::sqrt(track / 100), 1e-9);
  EXPECT_NEAR(m.sync_rsme(), std::sqrt(sync / 100), 1e-9);
  EXPECT_EQ(m.max_abs_error(2), 300);
  EXPECT_EQ(m.max_abs_sync_error(0), 0);
  EXPECT_EQ(m.max_abs_sync_error(2), 150);
  auto j = nlohmann::json::parse(m.json(*p, 100'000'000, 0.5));
  EXPECT_EQ(j["metrics"]["samples"], 100);
  EXPECT_DOUBLE_EQ(j["metrics"]["track_rsme"].get<double>(), m.track_rsme());
  EXPECT_EQ(j["metrics"]["axes"][1]["error"], "e[2]");
  EXPECT_EQ(j["tasks"][0]["name"], "servo");
  EXPECT_EQ(j["tasks"][0]["scans"], 100);
}

TEST(Metrics, WindowStartsAtFrom) {
  auto r = load_test_result(R"(
tasks: [{name: servo, period: 1ms}]
tags: [{name: e1, type: LREAL, init: 2}, {name: e2, type: LREAL, init: 5}]
metrics: {axis_errors: [e1, e2], from: 10ms}
)");
  auto& p = r.program;
  ASSERT_TRUE(p);
  VirtualClock clock(*p);
  MotionMetrics m(r.metrics);
  clock.on_time_point([&](std::int64_t t) { m.sample(*p, clock.image_access(), t, clock.scans(m.task())); });
  clock.run_until(50'000'000);
  EXPECT_EQ(m.samples(), 40u);
  EXPECT_NEAR(m.track_rsme(), std::sqrt(29.0), 1e-12);
  EXPECT_NEAR(m.sync_rsme(), 3.0, 1e-12);
}

TEST(Metrics, Errors) {
  using loadertest::has_error;
  auto e = loadertest::errors(R"(
tasks: [{name: servo, period: 1ms}]
tags: [{name: n, type: INT}, {name: x, type: LREAL}]
metrics:
  axis_errors: [x, n, nosuch, "x[2]"]
  from: soon
  colour: red
)");
  EXPECT_THAT(e, has_error("p.yaml:4:23", "metrics: unknown tag or instance.pin 'nosuch'"));
  EXPECT_THAT(e, has_error("p.yaml:4:31", "metrics: tag x is not an array"));
  EXPECT_THAT(e, has_error("p.yaml:5:9", "metrics from: 'soon' is not a duration"));
  EXPECT_THAT(e, has_error("p.yaml:6:11", "unknown key 'colour' in metrics (axis_errors, from, contour)"));
  auto e2 = loadertest::errors(R"(
tasks: [{name: servo, period: 1ms}]
tags: [{name: n, type: INT}]
metrics: {axis_errors: n}
)");
  EXPECT_THAT(e2, ::testing::ElementsAre("p.yaml:3:24: metrics: n is INT; axis errors are REAL or LREAL"));
}

}  // namespace
}  // namespace syncplc
