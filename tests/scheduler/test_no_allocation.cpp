// The scan path never allocates: every size is resolved at load. This test
// replaces the global operator new of the test binary with a counting one and
// runs scans of a project that uses every standard block family, two tasks,
// snapshots between them, queued writes, a driver and trended tags (their
// rings fill up, nobody drains them here: full rings drop without allocating).
#include <gtest/gtest.h>

#include <atomic>
#include <cstdlib>
#include <new>

#include "runtime/core/virtual_clock.hpp"
#include "tests/support/project_fixture.hpp"

#include "tests/support/allocation_counter.hpp"

// The scan-path test below counts this binary's operator new
// (tests/support/allocation_counter.*).
namespace {
std::atomic<bool>& g_counting = syncplc::test::counting_allocations;
std::atomic<long>& g_allocations = syncplc::test::allocations_counted;
}  // namespace

namespace syncplc {
namespace {

// Runs `clock` to `warm_up_ns` uncounted, then to `until_ns` counting every
// operator new; returns the count.
long allocations_while_running(VirtualClock& clock, std::int64_t warm_up_ns, std::int64_t until_ns) {
  clock.run_until(warm_up_ns);
  g_allocations = 0;
  g_counting = true;
  clock.run_until(until_ns);
  g_counting = false;
  return g_allocations.load();
}

// TAYLOR_ESTIMATOR (every history form, under alternating loss) and the
// reference generators (random and scripted STEP_RAMP_SEQUENCE included) on
// the scan path: no allocation.
TEST(ScanPath, EstimatorAndReferenceGeneratorsDoNotAllocate) {
  LoadOptions lo;
  lo.blocks = &builtin_blocks();
  auto r = load_project_text(R"(
tasks:
  - {name: servo, period: 1ms, priority: 80}
tags:
  - {name: x, type: LREAL}
  - {name: ok, type: BOOL}
blocks:
  - {name: circle, type: CIRCLE, task: servo, params: {radius: 320 mm, feed: 10000 mm/min, ramp_time: 100 ms}}
  - {name: cosine, type: COSINE_TRAJECTORY, task: servo, params: {amplitude: 1, omega: 10, cycles: 0}}
  - {name: steps, type: STEP_RAMP_SEQUENCE, task: servo, params: {min_hold: 10 ms, max_hold: 50 ms}}
  - name: script
    type: STEP_RAMP_SEQUENCE
    task: servo
    params: {mode: 1, segments: 3}
    inputs: {t: [0, 0.2 s, 0.4 s], value: [0, 1, 2], slope: [1, 0, -1]}
  - {name: robust, type: TAYLOR_ESTIMATOR, task: servo}
  - {name: recursive, type: TAYLOR_ESTIMATOR, task: servo, params: {history: 1}}
  - {name: zero, type: TAYLOR_ESTIMATOR, task: servo, params: {history: 2, order: 2}}
  - {name: flip, type: NOT, task: servo}
  - {name: fb, type: UNIT_DELAY, task: servo, datatype: BOOL}
connections:
  - fb.OUT -> flip.IN
  - flip.OUT -> fb.IN
  - flip.OUT -> ok
  - circle.x -> x
  - x -> robust.in
  - ok -> robust.valid
  - cosine.x -> recursive.in
  - ok -> recursive.valid
  - steps.r -> zero.in
  - ok -> zero.valid
)", "motion_refs.yaml", lo);
  for (const auto& d : r.diagnostics.list()) ADD_FAILURE() << d.text();
  auto& p = r.program;
  ASSERT_TRUE(p);
  VirtualClock clock(*p);
  EXPECT_EQ(allocations_while_running(clock, 10'000'000, 1'000'000'000), 0);
  EXPECT_GT(p->tasks[0]->stats.summary().scans, 990u);
}

TEST(ScanPath, DoesNotAllocate) {
  auto p = load_test_project(R"(
tasks:
  - {name: fast, period: 1ms, priority: 80, watchdog: {time: 1ms, sensitivity: 2, action: log}}
  - {name: slow, period: 7ms, priority: 20, missed_cycles: immediate}
tags:
  - {name: run, type: BOOL, init: TRUE, hmi: readwrite}
  - {name: count, type: DINT}
  - {name: level, type: LREAL, trend: {rate: 10ms, deadband: 0.1}}
  - {name: levels, type: "ARRAY[0..3] OF LREAL", trend: true}
  - {name: elapsed, type: TIME}
  - {name: out, type: BOOL, safe: FALSE}
  - {name: div0, type: INT}
  - {name: sensor, type: LREAL}
blocks:
  - {name: fb, type: UNIT_DELAY, task: fast}
  - {name: inv, type: NOT, task: fast}
  - {name: t, type: TON, task: fast, inputs: {PT: 5ms}}
  - {name: tp, type: TP, task: fast, inputs: {PT: 2ms}}
  - {name: tof, type: TOF, task: fast, inputs: {PT: 3ms}}
  - {name: edge, type: R_TRIG, task: fast}
  - {name: fall, type: F_TRIG, task: fast}
  - {name: c, type: CTUD, task: fast, datatype: DINT, inputs: {PV: 100}}
  - {name: sr, type: SR, task: fast}
  - {name: add, type: ADD, task: fast, datatype: LREAL, inputs: {IN2: 0.5}}
  - {name: lim, type: LIMIT, task: fast, inputs: {MN: 0.0, MX: 10.0}}
  - {name: gt, type: GT, task: slow, inputs: {IN2: 5.0}}
  - {name: sel, type: SEL, task: slow, inputs: {IN0: 1.0, IN1: 2.0}}
  - {name: mx, type: MAX, task: slow, inputs: {IN2: 0.0}}
  - {name: a, type: AND, task: slow, inputs: {IN2: TRUE}}
  - {name: zero, type: DIV, task: slow, datatype: INT, inputs: {IN1: 7, IN2: 0}}
  - {name: burn, type: BURN, task: slow, inputs: {EXEC: 8ms}}
connections:
  - t.Q -> fb.IN
  - fb.OUT -> inv.IN
  - inv.OUT -> t.IN
  - t.Q -> tp.IN
  - t.Q -> tof.IN
  - t.Q -> edge.CLK
  - t.Q -> fall.CLK
  - edge.Q -> c.CU
  - fall.Q -> sr.S1
  - c.CV -> count
  - t.ET -> elapsed
  - sensor -> add.IN1
  - add.OUT -> lim.IN
  - lim.OUT -> level
  - lim.OUT -> levels[2]
  - level -> gt.IN1
  - gt.OUT -> sel.G
  - sel.OUT -> mx.IN1
  - run -> a.IN1
  - a.OUT -> out
  - zero.OUT -> div0
drivers:
  - name: io
    type: memory
    task: fast
    channels: [{name: o, dir: out, type: BOOL}, {name: i, dir: in, type: LREAL}]
    bind: {o: out, i: sensor}
)");
  ASSERT_TRUE(p);
  VirtualClock clock(*p);
  clock.run_until(50'000'000);  // warm up: first scans, channels swapped at least once
  const Tag* run = p->find_tag("run");
  Cell v;
  v.set<bool>(true);
  ASSERT_TRUE(p->write_tag(*run, 0, &v, 1));  // the write itself is on the writer's side, allowed to allocate

  // The counter is live: one allocation is seen as one.
  g_allocations = 0;
  g_counting = true;
  int* volatile probe = new int(1);  // volatile: the compiler may not elide the pair
  delete probe;
  g_counting = false;
  ASSERT_EQ(g_allocations.load(), 1);

  g_allocations = 0;
  g_counting = true;
  clock.run_until(2'000'000'000);
  g_counting = false;
  EXPECT_EQ(g_allocations.load(), 0);
  EXPECT_GT(p->tasks[0]->stats.summary().scans, 1900u);
  EXPECT_GT(p->tasks[1]->stats.summary().overruns, 0u);  // the overrun path ran too
}

// Forces at every point of the scan (driver input, a block's output tag,
// input and output pins, a unit delay's pins, a tag bound to a driver
// output) and pin monitoring under way: still no allocation on the scan
// path, also in the scans that take and release the forces.
TEST(ScanPath, ForcesAndPinMonitoringDoNotAllocate) {
  auto p = load_test_project(R"(
tasks:
  - {name: fast, period: 1ms}
  - {name: slow, period: 5ms}
tags:
  - {name: sensor, type: LREAL}
  - {name: level, type: LREAL}
  - {name: levels, type: "ARRAY[0..3] OF LREAL"}
  - {name: out, type: BOOL}
  - {name: flag, type: BOOL}
  - {name: setpoint, type: LREAL, hmi: readwrite}
blocks:
  - {name: add, type: ADD, task: fast, datatype: LREAL, inputs: {IN2: 0.5}}
  - {name: lim, type: LIMIT, task: fast, inputs: {MN: 0.0, MX: 10.0}}
  - {name: fb, type: UNIT_DELAY, task: fast, datatype: BOOL}
  - {name: inv, type: NOT, task: fast}
  - {name: gt, type: GT, task: slow, inputs: {IN2: 5.0}}
  - {name: rec, type: MOVE, task: slow}  # not RECORD: its record list grows
connections:
  - sensor -> add.IN1
  - add.OUT -> lim.IN
  - lim.OUT -> level
  - lim.OUT -> levels[1]
  - fb.OUT -> inv.IN
  - inv.OUT -> fb.IN
  - inv.OUT -> out
  - level -> gt.IN1
  - gt.OUT -> flag
  - setpoint -> rec.IN
drivers:
  - name: io
    type: memory
    task: fast
    channels: [{name: o, dir: out, type: BOOL}, {name: i, dir: in, type: LREAL}]
    bind: {o: out, i: sensor}
)");
  ASSERT_TRUE(p);
  VirtualClock clock(*p);
  Cell pin;
  ASSERT_TRUE(p->read_value(*p->resolve("lim.OUT"), &pin, 10'000'000'000));  // monitored for the whole run
  ASSERT_TRUE(p->read_value(*p->resolve("gt.OUT"), &pin, 10'000'000'000));
  clock.run_until(20'000'000);
  const char* forced[][2] = {{"sensor", "3"}, {"level", "4"}, {"levels[1]", "5"}, {"add.IN2", "1.5"},
                             {"lim.OUT", "2"}, {"fb.IN", "TRUE"}, {"fb.OUT", "FALSE"}, {"out", "TRUE"},
                             {"gt.IN1", "6"}, {"setpoint", "7"}};
  for (const auto& f : forced) ASSERT_TRUE(p->force(f[0], f[1]).ok) << f[0];
  EXPECT_EQ(allocations_while_running(clock, 20'000'000, 500'000'000), 0);
  EXPECT_EQ(p->tasks[0]->force_table().size(), 8u);
  EXPECT_EQ(p->tasks[1]->force_table().size(), 2u);
  ASSERT_EQ(p->unforce_all().size(), 10u);
  EXPECT_EQ(allocations_while_running(clock, 500'000'000, 600'000'000), 0);
  EXPECT_EQ(p->tasks[0]->force_table().size(), 0u);
  EXPECT_TRUE(p->read_value(*p->resolve("lim.OUT"), &pin)) << "the pins were copied all along";
}

// The controller blocks of fblocks/motion (SYNC_CONTROLLER with its message
// estimators, PD_CONTROLLER, PID) on the scan path: no allocation either.
TEST(ScanPath, MotionControllersDoNotAllocate) {
  LoadOptions lo;
  lo.blocks = &builtin_blocks();
  auto r = load_project_text(R"(
tasks:
  - {name: servo, period: 1ms, priority: 80}
tags:
  - {name: xd, type: LREAL}
  - {name: x3, type: LREAL}
  - {name: u3, type: LREAL}
  - {name: u, type: LREAL}
blocks:
  - {name: ax3, type: SYNC_CONTROLLER, task: servo, params: {axis: 3, n: 3}, inputs: {v_d: 0.1, a_d: 0.2}}
  - {name: ax3c, type: SYNC_CONTROLLER, task: servo, params: {axis: 3, n: 3, compensation: FALSE, robust: 0}}
  - {name: pd, type: PD_CONTROLLER, task: servo}
  - {name: pid, type: PID, task: servo, params: {Ti: 1s, Td: 10ms, Tf: 1ms, anti_windup: 2}, inputs: {setpoint: 1.0}}
  - {name: ramp, type: ADD, task: servo, datatype: LREAL, inputs: {IN2: 0.001}}
  - {name: fb, type: UNIT_DELAY, task: servo}
connections:
  - fb.OUT -> ramp.IN1
  - ramp.OUT -> fb.IN
  - ramp.OUT -> xd
  - xd -> ax3.x_d
  - x3 -> ax3.x
  - xd -> ax3c.x_d
  - x3 -> ax3c.x
  - ax3.tau -> u3
  - xd -> pd.x_d
  - x3 -> pd.x
  - xd -> pid.actual
  - pid.y -> u
)", "motion.yaml", lo);
  for (const auto& d : r.diagnostics.list()) ADD_FAILURE() << d.text();
  auto& p = r.program;
  ASSERT_TRUE(p);
  VirtualClock clock(*p);
  EXPECT_EQ(allocations_while_running(clock, 10'000'000, 1'000'000'000), 0);
  EXPECT_GT(p->tasks[0]->stats.summary().scans, 990u);
}

// CIA402_DRIVE (fblocks/drives): two instances (SINT and INT mode pins) with
// the drive's objects set to every state, a fault with its events, a reset, a
// mode change, the following error window and a link loss.
TEST(ScanPath, Cia402DriveDoesNotAllocate) {
  LoadOptions lo;
  lo.blocks = &builtin_blocks();
  auto r = load_project_text(R"(
tasks:
  - {name: servo, period: 1ms, priority: 80}
tags:
  - {name: enable, type: BOOL}
  - {name: reset, type: BOOL}
  - {name: statusword, type: UINT}
  - {name: display, type: SINT}
  - {name: mode, type: SINT}
  - {name: display16, type: INT}
  - {name: mode16, type: INT}
  - {name: x_set, type: LREAL}
  - {name: actual, type: DINT}
  - {name: error_code, type: UINT}
  - {name: link_ok, type: BOOL, init: TRUE}
blocks:
  - {name: a1, type: CIA402_DRIVE, params: {transition_timeout: 0.005, following_error_window: 1, following_error_time: 0.002}}
  - {name: a2, type: CIA402_DRIVE, params: {idle_state: 2}}
connections:
  - enable -> a1.enable
  - reset -> a1.reset
  - statusword -> a1.statusword
  - display -> a1.modes_display
  - mode -> a1.mode
  - x_set -> a1.position_set
  - actual -> a1.position_actual
  - error_code -> a1.error_code
  - enable -> a2.enable
  - statusword -> a2.statusword
  - display16 -> a2.modes_display
  - mode16 -> a2.mode
  - link_ok -> a1.link_ok
  - link_ok -> a2.link_ok
)", "cia402_alloc.yaml", lo);
  for (const auto& d : r.diagnostics.list()) ADD_FAILURE() << d.text();
  ASSERT_TRUE(r.program);
  Program& p = *r.program;
  auto cell = [&](const char* name) -> Cell& { return *p.live_cell(*p.resolve(name), ::syncplc::testing::image_key()); };
  VirtualClock clock(p);
  clock.run_until(5'000'000);  // warm up, uncounted
  cell("enable").set<bool>(true);
  cell("mode").set<std::int8_t>(8);
  cell("display").set<std::int8_t>(8);
  cell("mode16").set<std::int16_t>(9);
  cell("display16").set<std::int16_t>(9);
  std::int64_t t = 5'000'000;
  long allocations = 0;
  auto window = [&](std::uint16_t sw) {
    cell("statusword").set<std::uint16_t>(sw);
    g_allocations = 0;
    g_counting = true;
    t += 10'000'000;
    clock.run_until(t);
    g_counting = false;
    allocations += g_allocations.load();
  };
  for (std::uint16_t sw : {0x0000, 0x0240, 0x0221, 0x0233, 0x0237, 0x0207, 0x0241}) window(sw);
  cell("x_set").set<double>(5.0);  // outside the window: event
  window(0x0237);
  cell("error_code").set<std::uint16_t>(0x7300);
  window(0x020F);  // fault reaction: event
  window(0x0208);
  cell("reset").set<bool>(true);
  window(0x0208);  // reset refused: timeout event
  window(0x0240);  // recovered: event
  cell("mode").set<std::int8_t>(3);
  window(0x0237);  // mode not displayed: timeout
  cell("link_ok").set<bool>(false);
  window(0x0237);  // link lost: event, quick stop
  cell("link_ok").set<bool>(true);
  window(0x0207);  // back: quick stopped until a new enable
  EXPECT_EQ(allocations, 0);
  EXPECT_GT(p.tasks[0]->stats.summary().scans, 100u);
}

}  // namespace
}  // namespace syncplc

namespace syncplc {
namespace {

// The shipped four-axis demo and its PD twin, with frame loss on every link so
// the estimators and the ring's loss draws run too: the table's plant, the
// ring, the controllers and the metrics' sources, scan after scan, allocate
// nothing.
// The paper 004 projects: TRANSIENT_SYNC (every rule) and scripted and random
// STEP_RAMP_SEQUENCE; plus NONLINEAR_FILTER on its own.
TEST(ScanPath, SynchronizedFiltersDoNotAllocate) {
  for (const char* file : {"three_signals.yaml", "six_axes.yaml"})
    for (const char* rule : {"0", "1", "2"}) {
      LoadOptions lo;
      lo.overrides = {{"sync", "rule", rule}};
      auto r = load_project(std::string(SYNCPLC_SOURCE_DIR) + "/projects/paper004_sync/" + file, lo);
      for (const auto& d : r.diagnostics.list()) ADD_FAILURE() << d.text();
      ASSERT_TRUE(r.program);
      VirtualClock clock(*r.program);
      EXPECT_EQ(allocations_while_running(clock, 100'000'000, 30'000'000'000), 0) << file << " rule " << rule;
    }
  auto p = load_test_project(R"(
tasks: [{name: servo, period: 1ms}]
blocks:
  - {name: steps, type: STEP_RAMP_SEQUENCE, params: {min_hold: 0.2, max_hold: 0.6, r_min: -1, r_max: 1}, inputs: {enable: TRUE}}
  - {name: f, type: NONLINEAR_FILTER, inputs: {v_min: -2, v_max: 3, a_min: -20, a_max: 15}}
connections:
  - steps.r -> f.r
  - steps.r_dot -> f.r_dot
)");
  ASSERT_TRUE(p);
  VirtualClock clock(*p);
  EXPECT_EQ(allocations_while_running(clock, 10'000'000, 5'000'000'000), 0);
}

TEST(ScanPath, FourAxisDemoDoesNotAllocate) {
  for (const char* file : {"sync.yaml", "pd.yaml"}) {
    LoadOptions lo;
    lo.overrides = {{"ring", "loss.p", "0.2"}, {"ring", "loss.scope", "link"}};
    auto r = load_project(std::string(SYNCPLC_SOURCE_DIR) + "/projects/four_axis_table/" + file, lo);
    for (const auto& d : r.diagnostics.list()) ADD_FAILURE() << d.text();
    ASSERT_TRUE(r.program);
    VirtualClock clock(*r.program);
    EXPECT_EQ(allocations_while_running(clock, 10'000'000, 3'000'000'000), 0) << file;
    EXPECT_GT(r.program->tasks[0]->stats.summary().scans, 2990u);
  }
}

}  // namespace
}  // namespace syncplc

namespace syncplc {
namespace {

// The PLCopen blocks on simulated drives: power, moves (aborting, buffered,
// blended), a stop held and released, a drive fault and its reset, a homing
// search, a group move re-targeted in flight. Nothing on their scan path
// allocates.
TEST(ScanPath, PlcopenAxesAndTheirBlocksDoNotAllocate) {
  LoadOptions lo;
  auto r = load_project_text(R"(
tasks: [{name: motion, period: 1ms}]
tags:
  - {name: power, type: BOOL}
  - {name: go, type: BOOL}
  - {name: go2, type: BOOL}
  - {name: mode2, type: INT}
  - {name: stop, type: BOOL}
  - {name: fault, type: BOOL}
  - {name: reset, type: BOOL}
  - {name: home, type: BOOL}
  - {name: group, type: BOOL}
  - {name: targets, type: "ARRAY[1..2] OF LREAL"}
blocks:
  - {name: x, type: MC_AXIS, params: {v_max: 50, a_max: 500, d_max: 500, home_mode: 1, home_velocity: 5}}
  - {name: y, type: MC_AXIS, params: {v_max: 30, a_max: 300, d_max: 400}}
  - {name: dx, type: SIM_SERVO, params: {home_at: 0.2}}
  - {name: dy, type: SIM_SERVO}
  - {name: px, type: MC_Power, params: {Axis: x}}
  - {name: py, type: MC_Power, params: {Axis: y}, inputs: {Enable: TRUE}}
  - {name: hm, type: MC_Home, params: {Axis: x}, inputs: {Position: 0}}
  - {name: mv, type: MC_MoveAbsolute, params: {Axis: x}, inputs: {Position: 3, Velocity: 20}}
  - {name: mv2, type: MC_MoveRelative, params: {Axis: x}, inputs: {Distance: 2, Velocity: 20}}
  - {name: stp, type: MC_Stop, params: {Axis: x}}
  - {name: rst, type: MC_Reset, params: {Axis: x}}
  - {name: st, type: MC_ReadStatus, params: {Axis: x}, inputs: {Enable: TRUE}}
  - {name: rp, type: MC_ReadParameter, params: {Axis: x}, inputs: {Enable: TRUE, ParameterNumber: 1}}
  - {name: grp, type: MC_GroupMoveAbsolute, params: {n: 2, Axes: [x, y]}, inputs: {ContinuousUpdate: TRUE}}
connections:
  - x.enable -> dx.enable
  - x.reset -> dx.reset
  - x.drive_position -> dx.target
  - dx.position -> x.actual_position
  - dx.power_on -> x.power_on
  - dx.fault -> x.fault
  - dx.fault_code -> x.fault_code
  - dx.home_switch -> x.home_switch
  - y.enable -> dy.enable
  - y.drive_position -> dy.target
  - dy.position -> y.actual_position
  - dy.power_on -> y.power_on
  - power -> px.Enable
  - home -> hm.Execute
  - go -> mv.Execute
  - go2 -> mv2.Execute
  - mode2 -> mv2.BufferMode
  - stop -> stp.Execute
  - fault -> dx.inject_fault
  - reset -> rst.Execute
  - group -> grp.Execute
  - targets -> grp.Position
)", "plcopen_alloc.yaml", lo);
  for (const auto& d : r.diagnostics.list()) ADD_FAILURE() << d.text();
  ASSERT_TRUE(r.program);
  Program& p = *r.program;
  auto cell = [&](const char* name) -> Cell& { return *p.live_cell(*p.resolve(name), ::syncplc::testing::image_key()); };
  VirtualClock clock(p);
  clock.run_until(5'000'000);  // warm up, uncounted
  std::int64_t t = 5'000'000;
  long allocations = 0;
  auto window = [&](std::int64_t ms) {
    g_allocations = 0;
    g_counting = true;
    t += ms * 1'000'000;
    clock.run_until(t);
    g_counting = false;
    allocations += g_allocations.load();
  };
  cell("power").set<bool>(true);
  window(10);
  cell("home").set<bool>(true);
  window(300);  // the search, the edge, the stop
  cell("home").set<bool>(false);
  cell("go").set<bool>(true);
  window(20);
  cell("mode2").set<std::int16_t>(2);  // BlendingLow behind the move
  cell("go2").set<bool>(true);
  window(500);
  cell("go").set<bool>(false);
  cell("go2").set<bool>(false);
  cell("targets[1]").set<double>(-1.0);
  cell("targets[2]").set<double>(4.0);
  cell("group").set<bool>(true);
  window(50);
  cell("targets[2]").set<double>(-2.0);  // re-targeted in flight
  window(500);
  cell("group").set<bool>(false);
  cell("go").set<bool>(true);
  window(20);
  cell("stop").set<bool>(true);  // takes over, holds
  window(100);
  cell("stop").set<bool>(false);
  cell("go").set<bool>(false);
  window(10);
  cell("fault").set<bool>(true);
  window(10);
  cell("fault").set<bool>(false);
  cell("reset").set<bool>(true);
  window(50);
  cell("power").set<bool>(false);
  window(10);
  EXPECT_EQ(allocations, 0);
  EXPECT_TRUE(cell("x.homed").get<bool>()) << "the homing search ran";
  EXPECT_GT(p.tasks[0]->stats.summary().scans, 1000u);
}

// Synchronized motion (mc_gear.cpp, mc_cam.cpp): gearing in, locked, out;
// a periodic spline cam taking the table at its edge, wrapping, a buffered
// cam taking over at the end of the profile, camming out.
TEST(ScanPath, GearAndCamBlocksDoNotAllocate) {
  LoadOptions lo;
  auto r = load_project_text(R"(
tasks: [{name: motion, period: 1ms}]
tags:
  - {name: run, type: BOOL}
  - {name: gear, type: BOOL}
  - {name: gout, type: BOOL}
  - {name: cam, type: BOOL}
  - {name: cam2, type: BOOL}
  - {name: cout, type: BOOL}
blocks:
  - {name: x, type: MC_AXIS, params: {v_max: 100, a_max: 1000, d_max: 1000}}
  - {name: y, type: MC_AXIS, params: {v_max: 50, a_max: 500, d_max: 800}}
  - {name: dx, type: SIM_SERVO}
  - {name: dy, type: SIM_SERVO}
  - {name: px, type: MC_Power, params: {Axis: x}, inputs: {Enable: TRUE}}
  - {name: py, type: MC_Power, params: {Axis: y}, inputs: {Enable: TRUE}}
  - {name: mv, type: MC_MoveVelocity, params: {Axis: x}, inputs: {Velocity: 10, Acceleration: 100}}
  - {name: gi, type: MC_GearIn, params: {Master: x, Slave: y}, inputs: {RatioNumerator: 3, RatioDenominator: 2}}
  - {name: go, type: MC_GearOut, params: {Slave: y}}
  - {name: ci, type: MC_CamIn, params: {n: 5, Master: x, Slave: y}, inputs: {StartMode: 1, Interpolation: 1, MasterPositions: [0, 1, 2, 3, 4], SlavePositions: [0, 1.5, 3, 4.5, 6]}}
  - {name: ci2, type: MC_CamIn, params: {n: 5, Master: x, Slave: y}, inputs: {StartMode: 1, BufferMode: 1, Interpolation: 1, MasterPositions: [0, 1, 2, 3, 4], SlavePositions: [0, 1.5, 3, 4.5, 6]}}
  - {name: co, type: MC_CamOut, params: {Slave: y}}
connections:
  - x.enable -> dx.enable
  - x.drive_position -> dx.target
  - dx.position -> x.actual_position
  - dx.power_on -> x.power_on
  - y.enable -> dy.enable
  - y.drive_position -> dy.target
  - dy.position -> y.actual_position
  - dy.power_on -> y.power_on
  - run -> mv.Execute
  - gear -> gi.Execute
  - gout -> go.Execute
  - cam -> ci.Execute
  - cam2 -> ci2.Execute
  - cout -> co.Execute
)", "sync_alloc.yaml", lo);
  for (const auto& d : r.diagnostics.list()) ADD_FAILURE() << d.text();
  ASSERT_TRUE(r.program);
  Program& p = *r.program;
  auto cell = [&](const char* name) -> Cell& { return *p.live_cell(*p.resolve(name), ::syncplc::testing::image_key()); };
  VirtualClock clock(p);
  clock.run_until(5'000'000);  // warm up, uncounted
  std::int64_t t = 5'000'000;
  long allocations = 0;
  auto window = [&](std::int64_t ms) {
    g_allocations = 0;
    g_counting = true;
    t += ms * 1'000'000;
    clock.run_until(t);
    g_counting = false;
    allocations += g_allocations.load();
  };
  cell("run").set<bool>(true);
  window(50);
  cell("gear").set<bool>(true);
  window(300);  // the ramp, the lock
  EXPECT_TRUE(cell("gi.InGear").get<bool>());
  cell("gout").set<bool>(true);
  window(10);
  EXPECT_TRUE(cell("go.Done").get<bool>());
  cell("cam").set<bool>(true);
  window(100);
  cell("cam2").set<bool>(true);
  window(600);  // wraps; the buffered cam takes over
  EXPECT_TRUE(cell("ci2.InSync").get<bool>());
  cell("cout").set<bool>(true);
  window(10);
  EXPECT_TRUE(cell("co.Done").get<bool>());
  EXPECT_EQ(allocations, 0);
}

}  // namespace
}  // namespace syncplc

namespace syncplc {
namespace {

// NURBS_PATH (fblocks/contour): the shipped contours run to their end (the
// last, shortened step and Done included), and an instance restarted every
// other scan (Execute from a toggling bit: the arrays latched and checked
// each time, a bad knot vector rejected with its event) allocate nothing.
TEST(ScanPath, NurbsPathDoesNotAllocate) {
  for (const char* file : {"circle.yaml", "butterfly.yaml"}) {
    auto r = load_project(std::string(SYNCPLC_SOURCE_DIR) + "/projects/contouring/" + file, LoadOptions{});
    for (const auto& d : r.diagnostics.list()) ADD_FAILURE() << d.text();
    ASSERT_TRUE(r.program);
    VirtualClock clock(*r.program);
    EXPECT_EQ(allocations_while_running(clock, 10'000'000, 7'000'000'000), 0) << file;
    EXPECT_GT(r.program->tasks[0]->stats.summary().scans, 6990u);
  }
  LoadOptions lo;
  lo.blocks = &builtin_blocks();
  auto r = load_project_text(R"(
tasks:
  - {name: servo, period: 1ms, priority: 80}
tags:
  - {name: go, type: BOOL}
blocks:
  - {name: flip, type: NOT, task: servo}
  - {name: fb, type: UNIT_DELAY, task: servo, datatype: BOOL}
  - name: good
    type: NURBS_PATH
    task: servo
    params: {points: 4, order: 4, knots: 8, axes: 3, feed: 1}
    inputs: {px: [0, 1, 2, 3], py: [0, 1, -1, 0], pz: [0, 0.5, 0.5, 1], w: [1, 2, 0.5, 1], knot: [0, 0, 0, 0, 1, 1, 1, 1]}
  - name: bad
    type: NURBS_PATH
    task: servo
    params: {points: 4, order: 2, knots: 6, feed: 1}
    inputs: {px: [0, 1, 2, 3], py: [0, 1, -1, 0], knot: [0, 0, 0.5, 0.4, 1, 1]}
connections:
  - fb.OUT -> flip.IN
  - flip.OUT -> fb.IN
  - flip.OUT -> go
  - go -> good.Execute
  - go -> bad.Execute
)", "nurbs_restart.yaml", lo);
  for (const auto& d : r.diagnostics.list()) ADD_FAILURE() << d.text();
  ASSERT_TRUE(r.program);
  VirtualClock clock(*r.program);
  EXPECT_EQ(allocations_while_running(clock, 10'000'000, 1'000'000'000), 0);
  EXPECT_GT(r.program->tasks[0]->stats.summary().scans, 990u);
}

}  // namespace
}  // namespace syncplc
