// The simulated table: the plant of paper 000 eq. (25) discretised exactly,
// deferred actuation, saturation, disturbance schedule, encoder and noise.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "runtime/core/virtual_clock.hpp"
#include "runtime/io/sim_table.hpp"
#include "tests/project/loader_test_util.hpp"
#include "tests/support/project_fixture.hpp"

namespace syncplc {
namespace {

// Analytic response of k/(s(tau s + 1)) from theta0, omega0 to a constant u over t.
struct Exact {
  double theta, omega;
};
Exact analytic(double tau, double k, double theta0, double omega0, double u, double t) {
  double a = std::exp(-t / tau);
  return {theta0 + tau * (1 - a) * omega0 + k * u * (t - tau * (1 - a)), a * omega0 + k * u * (1 - a)};
}

TEST(AxisPlant, DiscretisationIsTheExactZeroOrderHoldAtAnyPeriod) {
  for (double tau : {0.055, 0.040, 0.3})
    for (double h : {50e-6, 1e-3, 3.7e-3, 0.02, 0.5, 2.0}) {
      AxisModel m{tau, 36.3872};
      ZohStep s = discretize(m, h);
      // Columns of Phi: responses to unit initial states; Gamma: to a unit command.
      auto e1 = analytic(tau, m.gain, 1, 0, 0, h), e2 = analytic(tau, m.gain, 0, 1, 0, h), eu = analytic(tau, m.gain, 0, 0, 1, h);
      EXPECT_NEAR(s.phi(0, 0), e1.theta, 1e-12);
      EXPECT_NEAR(s.phi(1, 0), e1.omega, 1e-12);
      EXPECT_NEAR(s.phi(0, 1), e2.theta, 1e-12 * (1 + h));
      EXPECT_NEAR(s.phi(1, 1), e2.omega, 1e-12);
      EXPECT_NEAR(s.gamma(0), eu.theta, 1e-10 * m.gain * (1 + h));
      EXPECT_NEAR(s.gamma(1), eu.omega, 1e-11 * m.gain);
    }
}

TEST(AxisPlant, StepResponseMatchesTheAnalyticSolutionSampleBySample) {
  for (std::int64_t period : {1'000'000LL, 3'700'000LL, 250'000LL}) {
    AxisPlant p(AxisModel{0.055, 35.6206});
    p.prepare(period);
    double worst = 0;
    for (int k = 1; k <= 2000; ++k) {
      p.advance(0.3, period);
      double t = static_cast<double>(period) * 1e-9 * k;
      auto e = analytic(0.055, 35.6206, 0, 0, 0.3, t);
      worst = std::max(worst, std::abs(p.position() - e.theta) / (1 + std::abs(e.theta)));
      ASSERT_NEAR(p.velocity(), e.omega, 1e-9);
    }
    EXPECT_LT(worst, 1e-11) << "period " << period;
  }
}

TEST(AxisPlant, PiecesOfAnIntervalGiveTheWholeInterval) {
  AxisPlant a(AxisModel{0.04, 52.2836}), b(AxisModel{0.04, 52.2836});
  a.set_state(0.3, -2);
  b.set_state(0.3, -2);
  a.advance(0.7, 1'000'000);
  b.advance(0.7, 123'457);
  b.advance(0.7, 876'543);
  EXPECT_NEAR(a.position(), b.position(), 1e-13);
  EXPECT_NEAR(a.velocity(), b.velocity(), 1e-12);
}

// Drives the driver the way a task does: latch, (program), write.
struct TableRig {
  explicit TableRig(SimTableConfig cfg) : drv(std::move(cfg)) {
    const auto n = drv.axes();
    cmd.assign(n, Cell{});
    pos.assign(n, Cell{});
    vel.assign(n, Cell{});
    applied.assign(n, Cell{});
    load.assign(n, Cell{});
    drv.bind({cmd.data(), pos.data(), vel.data(), applied.data(), load.data()});
  }
  void scan(std::int64_t t, const std::vector<double>& u, const std::vector<double>& l = {}) {
    ScanContext ctx;
    ctx.now_ns = t;
    drv.latch_inputs(ctx);
    for (std::size_t i = 0; i < u.size(); ++i) cmd[i].set<double>(u[i]);
    for (std::size_t i = 0; i < load.size(); ++i) load[i].set<double>(i < l.size() ? l[i] : 0.0);
    drv.write_outputs(ctx);
  }
  double p(std::size_t i) const { return pos[i].get<double>(); }
  SimTableDriver drv;
  std::vector<Cell> cmd, pos, vel, applied, load;
};

SimTableConfig paper_table(std::int64_t period = 1'000'000) {
  SimTableConfig c;
  c.axes = {{0.055, 35.6206}, {0.056, 36.3872}, {0.040, 52.2836}, {0.056, 36.3872}};
  c.period_ns = period;
  return c;
}

TEST(SimTable, DeferredActuationActsOnEveryAxisAtTheSameInstant) {
  auto cfg = paper_table();
  cfg.actuation_delay_ns = 300'000;
  TableRig r(cfg);
  r.scan(0, {0, 0, 0, 0});
  r.scan(1'000'000, {0.2, 0.2, 0.2, 0.2});  // written at 1 ms, acts from 1.3 ms
  r.scan(2'000'000, {0.2, 0.2, 0.2, 0.2});
  for (std::size_t i = 0; i < 4; ++i) {
    const auto& m = cfg.axes[i];
    auto e = analytic(m.tau, m.gain, 0, 0, 0.2, 0.7e-3);  // 0.7 ms of command by t = 2 ms
    EXPECT_NEAR(r.p(i), e.theta, 1e-14) << "axis " << i + 1;
    EXPECT_NEAR(r.vel[i].get<double>(), e.omega, 1e-12);
    EXPECT_NEAR(r.applied[i].get<double>(), 0.2 * 0.7, 1e-12);  // mean input over the period
  }
}

TEST(SimTable, SaturatesTheCommandAndRefusesNonNumbers) {
  TableRig r(paper_table());
  r.scan(0, {5, -5, NAN, 0.5});
  r.scan(1'000'000, {0, 0, 0, 0});
  EXPECT_NEAR(r.applied[0].get<double>(), 1.0, 1e-15);
  EXPECT_NEAR(r.applied[1].get<double>(), -1.0, 1e-15);
  EXPECT_EQ(r.applied[2].get<double>(), 0.0);
  EXPECT_NEAR(r.applied[3].get<double>(), 0.5, 1e-15);
  EXPECT_EQ(r.drv.bad_commands(), 1u);
  Cell last[4];
  ASSERT_TRUE(r.drv.read_output(SimTableDriver::kCmd, last));
  EXPECT_EQ(last[0].get<double>(), 0.0);
}

TEST(SimTable, DisturbanceScheduleIsIntegratedExactlyEvenBetweenScans) {
  auto cfg = paper_table();
  // The paper's disturbance, shifted off the scan grid to show the edges are exact.
  cfg.disturbances = {{3, 2'000'400'000, 4'000'400'000, 0.05}};
  TableRig r(cfg);
  for (std::int64_t k = 0; k <= 5000; ++k) r.scan(k * 1'000'000, {0, 0, 0, 0});
  // Axis 4 (same model as axis 2) integrates the pulse; axis 2 stays still.
  const double tau = 0.056, g = 36.3872;
  auto on = analytic(tau, g, 0, 0, 0.05, 2.0);                          // during the pulse
  auto off = analytic(tau, g, on.theta, on.omega, 0, 5.0 - 4.0004);      // after it, to 5 s
  EXPECT_NEAR(r.p(3), off.theta, 1e-10);
  EXPECT_NEAR(r.vel[3].get<double>(), off.omega, 1e-12);
  EXPECT_EQ(r.p(1), 0.0);
}

// The load a program sets (the four-axis table on DDS nodes schedules axis
// 4's disturbance on the master's time, docs/four-axis-dds.md) acts as the
// scheduled disturbance does: beyond the drive's limit, from the instant the
// command acts, and it stays in the safe state (it is the machine's, not the drive's).
TEST(SimTable, LoadActsBeyondTheLimitWithTheCommandAndStaysInTheSafeState) {
  auto cfg = paper_table();
  cfg.actuation_delay_ns = 300'000;
  TableRig r(cfg);
  r.scan(0, {0, 0, 0, 0});
  r.scan(1'000'000, {5, 0, 0, 0}, {0.05, 0, NAN, -0.05});  // act from 1.3 ms
  r.scan(2'000'000, {5, 0, 0, 0}, {0.05, 0, NAN, -0.05});
  EXPECT_NEAR(r.applied[0].get<double>(), 1.05 * 0.7, 1e-12);  // limited command + load, for 0.7 ms
  EXPECT_EQ(r.applied[2].get<double>(), 0.0);                  // a non-number is no load
  EXPECT_NEAR(r.applied[3].get<double>(), -0.05 * 0.7, 1e-12);
  auto e = analytic(0.056, 36.3872, 0, 0, -0.05, 0.7e-3);
  EXPECT_NEAR(r.p(3), e.theta, 1e-14);
  const SafeOutput safe[] = {{SimTableDriver::kCmd, 0, Cell{}}};
  ASSERT_TRUE(r.drv.write_safe_outputs(safe, 1));
  r.scan(3'000'000, {1, 1, 1, 1}, {0, 0, 0, 0});  // the safe state takes over at this latch
  r.scan(4'000'000, {1, 1, 1, 1}, {0, 0, 0, 0});
  EXPECT_NEAR(r.applied[0].get<double>(), 0.05, 1e-12);   // safe command 0, the load still there
  EXPECT_NEAR(r.applied[3].get<double>(), -0.05, 1e-12);  // its command kept (0), its load too
}

TEST(SimTable, EncoderQuantisationCountsFourEdgesPerLine) {
  auto cfg = paper_table();
  cfg.encoder_lines = 500;  // 2000 counts per revolution
  TableRig r(cfg);
  const double q = 2 * std::numbers::pi / 2000;
  for (int k = 0; k < 300; ++k) {
    r.scan(k * 1'000'000LL, {0.4, -0.4, 0.1, 0});
    for (std::size_t i = 0; i < 3; ++i) {
      double truth = r.drv.axis(i).position();
      double m = r.p(i);
      EXPECT_NEAR(std::remainder(m, q), 0.0, 1e-9);
      EXPECT_LE(m, truth + 1e-12);
      EXPECT_GT(m, truth - q);
    }
  }
}

TEST(SimTable, NoiseIsSeededAndHasTheConfiguredSpread) {
  auto run = [](std::uint64_t seed) {
    auto cfg = paper_table();
    cfg.noise = 1e-3;
    cfg.seed = seed;
    TableRig r(cfg);
    std::vector<double> v;
    for (int k = 0; k < 20000; ++k) {
      r.scan(k * 1'000'000LL, {0, 0, 0, 0});
      v.push_back(r.p(0));
    }
    return v;
  };
  auto a = run(7), b = run(7), c = run(8);
  EXPECT_EQ(a, b);
  EXPECT_NE(a, c);
  double mean = 0, sq = 0;
  for (double x : a) mean += x;
  mean /= static_cast<double>(a.size());
  for (double x : a) sq += (x - mean) * (x - mean);
  double sd = std::sqrt(sq / static_cast<double>(a.size()));
  EXPECT_NEAR(mean, 0.0, 5 * 1e-3 / std::sqrt(20000.0));
  EXPECT_NEAR(sd, 1e-3, 0.03e-3);
}

TEST(SimTable, LoadsFromAProjectWithThePapersDefaults) {
  auto p = load_test_project(R"(
tasks: [{name: servo, period: 1ms}]
tags:
  - {name: u, type: "ARRAY[1..4] OF LREAL", init: [0.1, 0.1, 0.1, 0.1]}
  - {name: theta, type: "ARRAY[1..4] OF LREAL"}
drivers:
  - name: table
    type: sim_table
    disturbance: [{axis: 4, from: 2s, to: 4s, value: 0.05 PWM}]
    bind: {cmd: u, pos: theta}
)");
  ASSERT_TRUE(p);
  VirtualClock clock(*p);
  clock.run_until(1'000'000'000, true);  // scans at 0 .. 1 s: the command acted for 1 s
  const double k[4] = {35.6206, 36.3872, 52.2836, 36.3872}, tau[4] = {0.055, 0.056, 0.040, 0.056};
  for (int i = 0; i < 4; ++i) {
    auto r = p->resolve("theta[" + std::to_string(i + 1) + "]");
    ASSERT_TRUE(r);
    EXPECT_NEAR(p->live_cell(*r, ::syncplc::testing::image_key())->get<double>(), analytic(tau[i], k[i], 0, 0, 0.1, 1.0).theta, 1e-10);
  }
}

// One node of a distributed table: a table of one axis that is the paper's axis 3.
TEST(SimTable, PaperAxisGivesTheFirstAxisThatAxissParameters) {
  auto p = load_test_project(R"(
tasks: [{name: servo, period: 1ms}]
tags:
  - {name: u, type: "ARRAY[1..2] OF LREAL", init: [0.1, 0.1]}
  - {name: theta, type: "ARRAY[1..2] OF LREAL"}
drivers:
  - name: table
    type: sim_table
    axes: 2
    paper_axis: 3
    bind: {cmd: u, pos: theta}
)");
  ASSERT_TRUE(p);
  VirtualClock clock(*p);
  clock.run_until(1'000'000'000, true);
  // Axis 1 is the paper's axis 3, axis 2 its axis 4 (axis 2's model again).
  const double k[2] = {52.2836, 36.3872}, tau[2] = {0.040, 0.056};
  for (int i = 0; i < 2; ++i) {
    auto r = p->resolve("theta[" + std::to_string(i + 1) + "]");
    ASSERT_TRUE(r);
    EXPECT_NEAR(p->live_cell(*r, ::syncplc::testing::image_key())->get<double>(), analytic(tau[i], k[i], 0, 0, 0.1, 1.0).theta, 1e-10);
  }
}

TEST(SimTable, ConfigurationErrorsCarryTheirPlace) {
  LoadOptions o;
  o.blocks = &testing::test_blocks();
  auto r = load_project_text(loadertest::yaml(R"(
tasks: [{name: servo, period: 1ms}]
drivers:
  - name: table
    type: sim_table
    axes: 3
    tau: [0.05, 0.05]
    gain: 12 m/s
    actuation_delay: 1ms
    colour: blue
    disturbance: [{axis: 5, from: 2s, to: 1s, value: 0.05}]
    paper_axis: 5
)"),
                             "p.yaml", o);
  using loadertest::has_error;
  auto e = loadertest::errors(r);
  EXPECT_THAT(e, has_error("p.yaml:6:10", "tau: expected one value for every axis or a list of 3"));
  EXPECT_THAT(e, has_error("p.yaml:7:11", "gain: unit"));
  EXPECT_THAT(e, has_error("p.yaml:8:22", "actuation_delay 1ms is outside 0ms .. 999us999ns"));
  EXPECT_THAT(e, has_error("p.yaml:9:13", "unknown key 'colour' for a sim_table driver"));
  EXPECT_THAT(e, has_error("p.yaml:10:26", "disturbance axis = 5 is outside 1 .. 3"));
  EXPECT_THAT(e, has_error("p.yaml:10:43", "disturbance 'to' must be later than 'from'"));
  EXPECT_THAT(e, has_error("p.yaml:11:17", "paper_axis must be an integer 1..4"));
}

}  // namespace
}  // namespace syncplc
