// CCC_2AXIS in a project, in virtual time: the robust gain follows the path's
// curvature, and on two mismatched axes tracing paper 002's circle the CCC
// lowers the true contour error of `sim --metrics` (contour_metric.*).
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "fblocks/library.hpp"
#include "runtime/core/virtual_clock.hpp"
#include "runtime/project/loader.hpp"
#include "runtime/project/metrics.hpp"
#include "tests/support/image_key.hpp"

namespace syncplc {
namespace {

LoadResult load(const std::string& yaml) {
  LoadOptions o;
  o.blocks = &builtin_blocks();
  auto r = load_project_text(yaml, "ccc.yaml", o);
  for (const auto& d : r.diagnostics.list()) ADD_FAILURE() << d.text();
  return r;
}

double value(Program& p, const std::string& ref) {
  auto r = p.resolve(ref);
  EXPECT_TRUE(r) << ref;
  return p.live_cell(*r, testing::image_key())->get<double>();
}

// Robust CCC on a circle of radius R: K = 1/R, and the gain is the schedule's
// value there; on a straight reference (constant velocity inputs) K = 0 and
// the gain is gain_low.
TEST(CccBlock, RobustGainFollowsCurvature) {
  for (double radius : {0.1, 0.32, 1.0, 4.0}) {
    auto r = load(R"(
tasks: [{name: servo, period: 1ms}]
tags: [{name: zero, type: LREAL}]
blocks:
  - {name: circle, type: CIRCLE, params: {radius: )" + std::to_string(radius) + R"(, feed: 0.1, turns: 0}}
  - {name: ccc, type: CCC_2AXIS, params: {robust: TRUE, gain_low: 100, gain: 200, k_ref: 4}}
  - {name: line, type: CCC_2AXIS, params: {robust: TRUE, gain_low: 100, gain: 200, k_ref: 4},
     inputs: {x_ref: 0, y_ref: 0, vx_ref: 0.1, vy_ref: 0.1, ax_ref: 0.2, ay_ref: 0.2, x: 0, y: 0.001}}
connections:
  - circle.x -> ccc.x_ref
  - circle.y -> ccc.y_ref
  - circle.vx -> ccc.vx_ref
  - circle.vy -> ccc.vy_ref
  - circle.ax -> ccc.ax_ref
  - circle.ay -> ccc.ay_ref
  - circle.x -> ccc.x
  - circle.y -> ccc.y
)");
    ASSERT_TRUE(r.program);
    VirtualClock clock(*r.program);
    clock.run_until(50'000'000);
    Program& p = *r.program;
    EXPECT_NEAR(value(p, "ccc.curvature"), 1 / radius, 1e-9 / radius);
    EXPECT_NEAR(value(p, "ccc.kc"), 100 + 100 * std::fmin(1.0, 1 / radius / 4), 1e-6);
    EXPECT_NEAR(value(p, "ccc.eps"), 0, 1e-15);  // on the path
    EXPECT_EQ(value(p, "line.curvature"), 0);
    EXPECT_EQ(value(p, "line.kc"), 100);
    // 1 mm above a line heading north-east: left of it, eps = -1 mm / sqrt 2.
    EXPECT_NEAR(value(p, "line.eps"), -0.001 / std::sqrt(2.0), 1e-15);
  }
}

// Paper 002's circle (R = 320 mm, 10000 mm/min, 1 ms) on two velocity-mode
// axes whose drives differ (tau 2 and 4 ms, velocity gain 0.05 and 0.048),
// P position loop + the nominal velocity feed-forward per axis.
std::string servo_project(double gain) {
  return R"(
tasks: [{name: servo, period: 1ms}]
tags:
  - {name: pos, type: "ARRAY[1..2] OF LREAL"}
  - {name: cmd, type: "ARRAY[1..2] OF LREAL", safe: 0}
  - {name: err, type: "ARRAY[1..2] OF LREAL", unit: m}
blocks:
  - {name: circle, type: CIRCLE, params: {radius: 320 mm, feed: 10000 mm/min, ramp_time: 100 ms}}
  - {name: vff_x, type: MUL, inputs: {IN2: 20.0}}
  - {name: ff_x, type: ADD}
  - {name: pid_x, type: PID, params: {Kp: 1000, out_min: -10, out_max: 10}}
  - {name: vff_y, type: MUL, inputs: {IN2: 20.0}}
  - {name: ff_y, type: ADD}
  - {name: pid_y, type: PID, params: {Kp: 1000, out_min: -10, out_max: 10}}
  - {name: ccc, type: CCC_2AXIS, params: {gain: )" + std::to_string(gain) + R"(, limit: 10}}
connections:
  - circle.vx -> vff_x.IN1
  - vff_x.OUT -> ff_x.IN1
  - ccc.ux -> ff_x.IN2
  - ff_x.OUT -> pid_x.ff
  - circle.x -> pid_x.setpoint
  - pos[1] -> pid_x.actual
  - pid_x.y -> cmd[1]
  - pid_x.error -> err[1]
  - circle.vy -> vff_y.IN1
  - vff_y.OUT -> ff_y.IN1
  - ccc.uy -> ff_y.IN2
  - ff_y.OUT -> pid_y.ff
  - circle.y -> pid_y.setpoint
  - pos[2] -> pid_y.actual
  - pid_y.y -> cmd[2]
  - pid_y.error -> err[2]
  - circle.x -> ccc.x_ref
  - circle.y -> ccc.y_ref
  - circle.vx -> ccc.vx_ref
  - circle.vy -> ccc.vy_ref
  - circle.ax -> ccc.ax_ref
  - circle.ay -> ccc.ay_ref
  - pos[1] -> ccc.x
  - pos[2] -> ccc.y
drivers:
  - {name: table, type: sim_table, axes: 2, tau: [0.002, 0.004], gain: [0.05, 0.048], saturation: 10,
     position0: [0.32, 0], bind: {cmd: cmd, pos: pos}}
metrics:
  axis_errors: err
  contour: {axes: ["pos[1]", "pos[2]"], circle: {center: [0, 0], radius: 320 mm}}
)";
}

struct CircleRun {
  double mean, max, rms, track;
};

CircleRun run_circle(double gain) {
  auto r = load(servo_project(gain));
  EXPECT_TRUE(r.program && r.metrics.contour);
  if (!r.program || !r.metrics.contour) return {};
  Program& p = *r.program;
  VirtualClock clock(p);
  MotionMetrics m(r.metrics);
  clock.on_time_point([&](std::int64_t t) { m.sample(p, clock.image_access(), t, clock.scans(m.task())); });
  clock.run_until(3'000'000'000);  // a quarter turn and more
  const ContourMetric* c = m.contour();
  EXPECT_NE(c, nullptr);
  if (!c) return {};
  EXPECT_EQ(c->samples(), 3000u);
  return {c->mean_abs(), c->max_abs(), c->rms(), m.track_rsme()};
}

TEST(CccBlock, ReducesTheContourErrorOfMismatchedAxes) {
  const CircleRun off = run_circle(0), on = run_circle(4000);
  // Without CCC the axes' different lags leave a contour error of tens of um.
  EXPECT_GT(off.max, 2e-5);
  EXPECT_LT(on.rms, off.rms / 2) << "off " << off.rms << " on " << on.rms;
  EXPECT_LT(on.max, off.max / 2) << "off " << off.max << " on " << on.max;
  EXPECT_LT(on.mean, off.mean / 2);
  // The CCC acts on the contour, not on the lag along the path.
  EXPECT_GT(on.track, 0.5 * off.track);
}

}  // namespace
}  // namespace syncplc
