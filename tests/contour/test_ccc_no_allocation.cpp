// The scan path never allocates (tests/scheduler/test_no_allocation.cpp's
// pattern): CCC_2AXIS, fixed and robust, with the contour metric sampling,
// on paper 002's circle. This file replaces the global operator new of the
// test_contour binary with a counting one (counting only inside the window).
#include <gtest/gtest.h>

#include <atomic>
#include <cstdlib>
#include <new>

#include "fblocks/library.hpp"
#include "runtime/core/virtual_clock.hpp"
#include "runtime/project/loader.hpp"
#include "runtime/project/metrics.hpp"

#include "tests/support/allocation_counter.hpp"

// The scan-path test below counts this binary's operator new
// (tests/support/allocation_counter.*).
namespace {
std::atomic<bool>& g_ccc_counting = syncplc::test::counting_allocations;
std::atomic<long>& g_ccc_allocations = syncplc::test::allocations_counted;
}  // namespace

namespace syncplc {
namespace {

TEST(ScanPath, CccBlocksAndContourMetricDoNotAllocate) {
  LoadOptions o;
  o.blocks = &builtin_blocks();
  auto r = load_project_text(R"(
tasks: [{name: servo, period: 1ms}]
tags:
  - {name: pos, type: "ARRAY[1..2] OF LREAL"}
  - {name: cmd, type: "ARRAY[1..2] OF LREAL", safe: 0}
  - {name: err, type: "ARRAY[1..2] OF LREAL"}
blocks:
  - {name: circle, type: CIRCLE, params: {radius: 320 mm, feed: 10000 mm/min, ramp_time: 100 ms}}
  - {name: sx, type: SUB}
  - {name: sy, type: SUB}
  - {name: ux, type: ADD}
  - {name: uy, type: ADD}
  - {name: fixed, type: CCC_2AXIS, params: {gain: 1000, Ti: 0.05, limit: 5}}
  - {name: robust, type: CCC_2AXIS, params: {robust: TRUE, gain_low: 500, gain: 2000, k_ref: 5, Ti: 0.1}}
connections:
  - circle.x -> sx.IN1
  - pos[1] -> sx.IN2
  - circle.y -> sy.IN1
  - pos[2] -> sy.IN2
  - sx.OUT -> err[1]
  - sy.OUT -> err[2]
  - fixed.ux -> ux.IN1
  - robust.ux -> ux.IN2
  - fixed.uy -> uy.IN1
  - robust.uy -> uy.IN2
  - ux.OUT -> cmd[1]
  - uy.OUT -> cmd[2]
  - circle.x -> fixed.x_ref
  - circle.y -> fixed.y_ref
  - circle.vx -> fixed.vx_ref
  - circle.vy -> fixed.vy_ref
  - circle.ax -> fixed.ax_ref
  - circle.ay -> fixed.ay_ref
  - pos[1] -> fixed.x
  - pos[2] -> fixed.y
  - circle.x -> robust.x_ref
  - circle.y -> robust.y_ref
  - circle.vx -> robust.vx_ref
  - circle.vy -> robust.vy_ref
  - circle.ax -> robust.ax_ref
  - circle.ay -> robust.ay_ref
  - pos[1] -> robust.x
  - pos[2] -> robust.y
drivers:
  - {name: table, type: sim_table, axes: 2, tau: [0.002, 0.004], gain: [0.05, 0.05], saturation: 10,
     position0: [0.32, 0], bind: {cmd: cmd, pos: pos}}
metrics:
  axis_errors: err
  contour: {axes: ["pos[1]", "pos[2]"], circle: {center: [0, 0], radius: 320 mm}}
)", "alloc.yaml", o);
  for (const auto& d : r.diagnostics.list()) ADD_FAILURE() << d.text();
  ASSERT_TRUE(r.program);
  Program& p = *r.program;
  std::string err;
  ASSERT_TRUE(p.open_drivers(&err)) << err;
  VirtualClock clock(p);
  MotionMetrics m(r.metrics);
  clock.on_time_point([&](std::int64_t t) { m.sample(p, clock.image_access(), t, clock.scans(m.task())); });
  clock.run_until(200'000'000);  // warm-up: the ramp, the first tangent
  g_ccc_allocations = 0;
  g_ccc_counting = true;
  clock.run_until(1'200'000'000);
  g_ccc_counting = false;
  EXPECT_EQ(g_ccc_allocations.load(), 0);
  ASSERT_NE(m.contour(), nullptr);
  EXPECT_GT(m.contour()->samples(), 1000u);
  p.stop_drivers();
}

}  // namespace
}  // namespace syncplc
