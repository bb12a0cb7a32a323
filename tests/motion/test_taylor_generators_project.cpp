// The estimator and the generators in a loaded project: parameters written
// with units (320 mm, 2500 mm/min, 4 pi rad as a number), connections, and the
// project seed reaching STEP_RAMP_SEQUENCE.
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <numbers>
#include <string>

#include "tests/support/image_key.hpp"
#include "runtime/core/virtual_clock.hpp"
#include "runtime/project/loader.hpp"

namespace syncplc {
namespace {

constexpr double kPi = std::numbers::pi;

const char* kProject = R"(
project: {name: motion_refs, seed: 7}
tasks: [{name: fast, period: 1ms}]
tags:
  - {name: x, type: LREAL, unit: m}
  - {name: y, type: LREAL, unit: m}
  - {name: x_est, type: LREAL, unit: m}
  - {name: link_ok, type: BOOL, init: TRUE}
  - {name: lost_in_row, type: UDINT}
  - {name: q, type: LREAL, unit: rad}
  - {name: r1, type: LREAL}
  - {name: r2, type: LREAL}
blocks:
  - name: circle
    type: CIRCLE
    params: {radius: 320 mm, feed: 10000 mm/min, ramp_time: 100 ms}
  - {name: est, type: TAYLOR_ESTIMATOR, params: {order: 3, history: 0, max_extrapolation: 20}}
  - {name: cosine, type: COSINE_TRAJECTORY, params: {amplitude: 12.566370614359172, omega: 60 rev/min, cycles: 3}}
  - {name: steps1, type: STEP_RAMP_SEQUENCE, params: {max_hold: 500 ms}}
  - {name: steps2, type: STEP_RAMP_SEQUENCE, params: {max_hold: 500 ms}}
connections:
  - circle.x -> x
  - circle.y -> y
  - circle.x -> est.in
  - link_ok -> est.valid
  - est.out -> x_est
  - est.consecutive -> lost_in_row
  - cosine.x -> q
  - steps1.r -> r1
  - steps2.r -> r2
)";

std::unique_ptr<Program> load(const std::string& yaml) {
  auto r = load_project_text(yaml, "test.yaml");  // the built-in block library
  for (const auto& d : r.diagnostics.list()) ADD_FAILURE() << d.text();
  return std::move(r.program);
}

Cell& tag_cell(Program& p, const std::string& name) {
  auto r = p.resolve(name);
  EXPECT_TRUE(r) << name;
  return *p.live_cell(*r, ::syncplc::testing::image_key());
}

TEST(MotionProject, GeneratorsAndEstimatorLoadAndRun) {
  auto p = load(kProject);
  ASSERT_TRUE(p);
  VirtualClock clock(*p);
  clock.run_until(2'000'000'000);  // scans at 0 .. 1999 ms
  // Circle: R = 0.32 m, on the circle, anticlockwise from (R, 0).
  const double x = tag_cell(*p, "x").get<double>(), y = tag_cell(*p, "y").get<double>();
  EXPECT_NEAR(std::hypot(x, y), 0.32, 1e-12);
  const double s = 10.0 / 60 * (1.999 - 0.05);  // path length after the 100 ms ramp
  EXPECT_NEAR(std::atan2(y, x), s / 0.32, 1e-9);
  EXPECT_EQ(tag_cell(*p, "x_est").get<double>(), x);  // link up: the sample itself
  // omega written as 60 rev/min = 2 pi rad/s.
  EXPECT_NEAR(tag_cell(*p, "q").get<double>(), 4 * kPi * (1 - std::cos(2 * kPi * 1.999)), 1e-9);
  // Two instances, one project seed: different sequences.
  EXPECT_NE(tag_cell(*p, "r1").get<double>(), tag_cell(*p, "r2").get<double>());
  // Link down: the estimator extrapolates the circle's x.
  tag_cell(*p, "link_ok").set<bool>(false);
  clock.run_until(2'005'000'000);  // 5 more scans
  EXPECT_EQ(tag_cell(*p, "lost_in_row").get<std::uint32_t>(), 5u);
  const double x_true = tag_cell(*p, "x").get<double>(), x_est = tag_cell(*p, "x_est").get<double>();
  EXPECT_NE(x_est, x_true);
  EXPECT_NEAR(x_est, x_true, 2e-6);  // centripetal 0.087 m/s^2: a (5 ms)^2 / 2 ~ 1.1e-6 m
}

// Scripted STEP_RAMP_SEQUENCE with list constants on its array pins, times
// written with units, as docs/motion/reference-generators.md shows.
TEST(MotionProject, ScriptedStepRampSequenceFromListConstants) {
  auto p = load(R"(
tasks: [{name: fast, period: 1ms}]
tags:
  - {name: r, type: LREAL}
  - {name: r_dot, type: LREAL}
  - {name: seg, type: DINT}
blocks:
  - name: script
    type: STEP_RAMP_SEQUENCE
    params: {mode: 1, segments: 3}
    inputs: {t: [200 ms, 0.5 s, 1.2 s], value: [1, 2, -1], slope: [0, 4, -0.5]}
connections:
  - script.r -> r
  - script.r_dot -> r_dot
  - script.segment -> seg
)");
  ASSERT_TRUE(p);
  VirtualClock clock(*p);
  clock.run_until(100'000'000, true);  // last scan at 100 ms: before t[0]
  EXPECT_EQ(tag_cell(*p, "r").get<double>(), 1.0);
  EXPECT_EQ(tag_cell(*p, "seg").get<std::int32_t>(), -1);
  clock.run_until(750'000'000, true);  // 750 ms: the ramp, 2 + 4 * 0.25
  EXPECT_NEAR(tag_cell(*p, "r").get<double>(), 3.0, 1e-12);
  EXPECT_EQ(tag_cell(*p, "r_dot").get<double>(), 4.0);
  EXPECT_EQ(tag_cell(*p, "seg").get<std::int32_t>(), 1);
  clock.run_until(1'400'000'000, true);
  EXPECT_NEAR(tag_cell(*p, "r").get<double>(), -1.1, 1e-12);
  EXPECT_EQ(tag_cell(*p, "seg").get<std::int32_t>(), 2);
}

}  // namespace
}  // namespace syncplc
