// PID and PD_CONTROLLER through BlockHarness: the control law, limits,
// anti-windup, bumpless manual/automatic transfer, derivative on measurement
// or error, the derivative filter, reset, and closed loops on first-order plants.
#include <cmath>
#include <cstdio>

#include "tests/motion/control_sim.hpp"

namespace syncplc::motiontest {
namespace {

BlockHarness::Options pid_opts(std::map<std::string, std::string> p) {
  BlockHarness::Options o;
  o.params = std::move(p);
  return o;
}

// First-order plant K/(Ts s + 1), exact ZOH.
struct FirstOrder {
  double a, b, y = 0;
  FirstOrder(double K, double Ts, double h) : a(std::exp(-h / Ts)), b(K * -std::expm1(-h / Ts)) {}
  void step(double u) { y = a * y + b * u; }
};

struct LoopResult {
  std::vector<double> y, u;
  double overshoot = 0;  // max(y) − setpoint
  bool saturated_seen = false;
};

// Closed loop of a PID instance on a first-order plant, setpoint step at t = 0.
LoopResult pid_loop(std::map<std::string, std::string> p, double K, double Ts, double sp, int scans,
                    double h = 1e-3) {
  BlockHarness::Options o = pid_opts(std::move(p));
  o.period_ns = std::llround(h * 1e9);
  BlockHarness pid(registry(), "PID", o);
  LoopResult r;
  EXPECT_TRUE(pid.ok()) << errors_of(pid);
  if (!pid.ok()) return r;
  FirstOrder plant(K, Ts, h);
  pid.set<double>("setpoint", sp);
  for (int j = 0; j < scans; ++j) {
    pid.set<double>("actual", plant.y);
    pid.scan();
    const double u = pid.get<double>("y");
    r.saturated_seen = r.saturated_seen || pid.get<bool>("saturated");
    r.y.push_back(plant.y);
    r.u.push_back(u);
    plant.step(u);
  }
  double mx = -1e300;
  for (double v : r.y) mx = std::max(mx, v);
  r.overshoot = mx - sp;
  return r;
}

TEST(Pid, Declaration) {
  const BlockTypeInfo* t = registry().find("PID");
  ASSERT_NE(t, nullptr);
  EXPECT_EQ(t->category, "Motion");
  for (const char* p : {"setpoint", "actual", "ff", "manual", "manual_value", "reset", "y", "error", "saturated"})
    EXPECT_GE(t->pin_index(p), 0) << p;
  for (const char* p : {"Kp", "Ti", "Td", "Tf", "Tt", "anti_windup", "d_on_error", "out_min", "out_max"})
    EXPECT_GE(t->param_index(p), 0) << p;
  EXPECT_EQ(t->params[static_cast<std::size_t>(t->param_index("Ti"))].unit, "s");
}

TEST(Pid, InvalidParametersFailAtLoad) {
  const std::vector<std::pair<std::map<std::string, std::string>, const char*>> bad = {
      {{{"out_min", "5"}, {"out_max", "5"}}, "out_min must be less"},
      {{{"Ti", "-1"}}, "Ti must be >="},
      {{{"Td", "-0.1"}}, "Td must be >="},
      {{{"Tf", "-0.1"}}, "Tf must be >="},
      {{{"anti_windup", "3"}}, "anti_windup must be in"},
  };
  for (const auto& [p, what] : bad) {
    BlockHarness h(registry(), "PID", pid_opts(p));
    EXPECT_FALSE(h.ok()) << what;
    EXPECT_NE(errors_of(h).find(what), std::string::npos) << errors_of(h);
  }
  BlockHarness ok(registry(), "PID");
  ASSERT_CTL_OK(ok);
}

TEST(Pid, ProportionalFeedForwardAndLimit) {
  BlockHarness h(registry(), "PID", pid_opts({{"Kp", "2"}, {"out_min", "-3"}, {"out_max", "4"}}));
  ASSERT_CTL_OK(h);
  h.set<double>("setpoint", 1.0);
  h.set<double>("actual", 0.25);
  h.set<double>("ff", 0.5);
  h.scan();
  EXPECT_DOUBLE_EQ(h.get<double>("y"), 2 * 0.75 + 0.5);
  EXPECT_DOUBLE_EQ(h.get<double>("error"), 0.75);
  EXPECT_FALSE(h.get<bool>("saturated"));
  h.set<double>("setpoint", 10.0);
  h.scan();
  EXPECT_EQ(h.get<double>("y"), 4.0);
  EXPECT_TRUE(h.get<bool>("saturated"));
  h.set<double>("setpoint", -10.0);
  h.scan();
  EXPECT_EQ(h.get<double>("y"), -3.0);
  EXPECT_TRUE(h.get<bool>("saturated"));
}

// PI with Ti = plant time constant cancels the plant pole: the closed loop is
// first order with time constant Ti/(Kp K).
TEST(Pid, StepResponseOnFirstOrderPlant) {
  const double K = 2, Ts = 0.5, Kp = 1;
  const LoopResult r = pid_loop({{"Kp", "1"}, {"Ti", "0.5"}, {"out_min", "-100"}, {"out_max", "100"}}, K, Ts, 1.0, 5000);
  ASSERT_EQ(r.y.size(), 5000u);
  const double tcl = Ts / (Kp * K);
  double worst = 0;
  for (std::size_t j = 0; j < r.y.size(); ++j)
    worst = std::max(worst, std::abs(r.y[j] - (1 - std::exp(-static_cast<double>(j) * 1e-3 / tcl))));
  std::printf("pid: PI step, max deviation from 1 - exp(-t/%.2f): %.2e\n", tcl, worst);
  EXPECT_LT(worst, 5e-3);  // discretization (one scan of delay) only
  EXPECT_NEAR(r.y.back(), 1.0, 1e-6);  // integral action: no steady-state error
  EXPECT_LT(r.overshoot, 1e-4);  // the continuous loop has none; the discrete one ~1e-6
  EXPECT_FALSE(r.saturated_seen);
}

// A step that saturates the actuator: without anti-windup the integral winds
// up and the output overshoots far; clamping and back-calculation do not.
TEST(Pid, AntiWindupPreventsOvershootBlowUp) {
  std::map<std::string, std::string> p = {{"Kp", "3"}, {"Ti", "0.3"}, {"out_min", "0"}, {"out_max", "1.2"}};
  auto run_aw = [&](const char* aw) {
    auto q = p;
    q["anti_windup"] = aw;
    return pid_loop(q, 1.0, 1.0, 1.0, 20000);
  };
  const LoopResult none = run_aw("0"), clamp = run_aw("1"), back = run_aw("2");
  auto unlimited_p = p;
  unlimited_p["out_max"] = "1e9";
  unlimited_p["out_min"] = "-1e9";
  const LoopResult unlimited = pid_loop(unlimited_p, 1.0, 1.0, 1.0, 20000);
  std::printf("pid: overshoot after saturation: none %.4f, clamping %.4f, back-calculation %.4f, unlimited %.4f\n",
              none.overshoot, clamp.overshoot, back.overshoot, unlimited.overshoot);
  EXPECT_TRUE(none.saturated_seen);
  EXPECT_TRUE(clamp.saturated_seen);
  EXPECT_TRUE(back.saturated_seen);
  EXPECT_GT(none.overshoot, 0.05);
  EXPECT_LT(clamp.overshoot, none.overshoot / 3);
  EXPECT_LT(back.overshoot, none.overshoot / 3);
  for (const auto* r : {&none, &clamp, &back}) {
    EXPECT_NEAR(r->y.back(), 1.0, 1e-4);  // all settle eventually
    for (double u : r->u) {
      ASSERT_GE(u, 0.0);
      ASSERT_LE(u, 1.2);
    }
  }
}

// Reverse action (negative Kp): clamping still stops the integral in the
// direction that pushes further into the limit.
TEST(Pid, ClampingWithReverseAction) {
  BlockHarness h(registry(), "PID", pid_opts({{"Kp", "-1"}, {"Ti", "0.01"}, {"out_min", "-1"}, {"out_max", "1"}}));
  ASSERT_CTL_OK(h);
  h.set<double>("setpoint", 0.0);
  h.set<double>("actual", 5.0);  // e = −5, Kp e = +5: at the upper limit
  h.scans(1000);
  EXPECT_EQ(h.get<double>("y"), 1.0);
  h.set<double>("actual", -0.5);  // e = +0.5: the output must leave the limit at once
  h.scan();
  EXPECT_LT(h.get<double>("y"), 1.0);
  EXPECT_FALSE(h.get<bool>("saturated"));
}

// Manual → automatic is bumpless: the integral tracks the manual output.
TEST(Pid, BumplessTransfer) {
  BlockHarness h(registry(), "PID",
                 pid_opts({{"Kp", "2"}, {"Ti", "0.5"}, {"Td", "0.05"}, {"Tf", "0.005"}, {"out_min", "-10"}, {"out_max", "10"}}));
  ASSERT_CTL_OK(h);
  h.set<double>("setpoint", 1.0);
  h.set<double>("actual", 0.2);
  h.set<double>("ff", 0.1);
  h.set<bool>("manual", true);
  h.set<double>("manual_value", 0.3);
  h.scans(100);
  EXPECT_EQ(h.get<double>("y"), 0.3);
  h.set<bool>("manual", false);
  h.scan();
  // Same inputs on the first automatic scan: the same output; then the integral acts.
  EXPECT_NEAR(h.get<double>("y"), 0.3, 1e-12);
  h.scan();
  EXPECT_NEAR(h.get<double>("y"), 0.3 + 2 * 1e-3 / 0.5 * 0.8, 1e-12);
  // Back to manual: the manual value, limited.
  h.set<bool>("manual", true);
  h.set<double>("manual_value", 50.0);
  h.scan();
  EXPECT_EQ(h.get<double>("y"), 10.0);
  EXPECT_TRUE(h.get<bool>("saturated"));
}

// In closed loop the transfer does not jump either: the step in y at the
// switch is no larger than the scan-to-scan change in manual mode.
TEST(Pid, BumplessTransferInClosedLoop) {
  BlockHarness h(registry(), "PID", pid_opts({{"Kp", "4"}, {"Ti", "0.2"}, {"out_min", "-5"}, {"out_max", "5"}}));
  ASSERT_CTL_OK(h);
  FirstOrder plant(1.0, 0.3, 1e-3);
  h.set<double>("setpoint", 2.0);
  h.set<bool>("manual", true);
  h.set<double>("manual_value", 0.7);
  double y_prev = 0, jump = 0;
  for (int j = 0; j < 3000; ++j) {
    if (j == 1500) h.set<bool>("manual", false);
    h.set<double>("actual", plant.y);
    h.scan();
    const double y = h.get<double>("y");
    if (j == 1500) jump = std::abs(y - y_prev);
    y_prev = y;
    plant.step(y);
  }
  // Without tracking (I = 0) y would jump from 0.7 to LIMIT(Kp·(2 − 0.7)) = 5.
  std::printf("pid: step in y at the manual -> automatic switch: %.2e\n", jump);
  EXPECT_LT(jump, 0.02);
  EXPECT_NEAR(plant.y, 2.0, 1e-3);
}

TEST(Pid, DerivativeOnMeasurementHasNoSetpointKick) {
  for (const bool on_error : {false, true}) {
    BlockHarness h(registry(), "PID",
                   pid_opts({{"Kp", "2"}, {"Td", "0.1"}, {"d_on_error", on_error ? "TRUE" : "FALSE"},
                             {"out_min", "-1e6"}, {"out_max", "1e6"}}));
    ASSERT_CTL_OK(h);
    h.scans(3);
    h.set<double>("setpoint", 1.0);
    h.scan();
    const double kick = on_error ? 2 * 0.1 * 1.0 / 1e-3 : 0.0;
    EXPECT_NEAR(h.get<double>("y"), 2 * 1.0 + kick, 1e-9) << on_error;
    h.scan();
    EXPECT_NEAR(h.get<double>("y"), 2.0, 1e-9) << on_error;
    // Both react to the measurement: a change of actual by −0.5.
    h.set<double>("actual", -0.5);
    h.scan();
    EXPECT_NEAR(h.get<double>("y"), 2 * 1.5 + 2 * 0.1 * 0.5 / 1e-3, 1e-9) << on_error;
  }
}

// D = (Tf D + Kp Td Δs)/(Tf + h): on a ramp of the measurement it converges
// to −Kp Td slope with the filter's time constant Tf.
TEST(Pid, DerivativeFilter) {
  const double Kp = 1.5, Td = 0.2, Tf = 0.02, h = 1e-3, slope = 0.3;
  BlockHarness b(registry(), "PID",
                 pid_opts({{"Kp", "1.5"}, {"Td", "0.2"}, {"Tf", "0.02"}, {"out_min", "-1e6"}, {"out_max", "1e6"}}));
  ASSERT_CTL_OK(b);
  double d = 0;
  for (int j = 0; j < 400; ++j) {
    const double pv = slope * j * h;
    b.set<double>("actual", pv);
    b.scan();
    if (j > 0) d = (Tf * d + Kp * Td * (-slope * h)) / (Tf + h);
    const double want = Kp * (0 - pv) + d;
    ASSERT_NEAR(b.get<double>("y"), want, 1e-12) << j;
  }
  EXPECT_NEAR(d, -Kp * Td * slope, 1e-6);  // after 20 Tf
}

TEST(Pid, ResetClearsTheState) {
  BlockHarness h(registry(), "PID", pid_opts({{"Kp", "1"}, {"Ti", "0.1"}, {"out_min", "-0.5"}, {"out_max", "10"}}));
  ASSERT_CTL_OK(h);
  h.set<double>("setpoint", 1.0);
  h.scans(200);  // integral 200·1e-3/0.1 = 2
  EXPECT_NEAR(h.get<double>("y"), 1 + 199 * 0.01, 1e-9);
  h.set<bool>("reset", true);
  h.set<bool>("manual", true);  // reset has priority
  h.scan();
  EXPECT_EQ(h.get<double>("y"), 0.0);
  h.set<bool>("reset", false);
  h.set<bool>("manual", false);
  h.scan();
  EXPECT_NEAR(h.get<double>("y"), 1.0, 1e-12);  // P only: the integral starts again from 0
}

// A retained PID (docs/store.md, "Retained block instances") restarts at its
// operating point with the integral it had: the first output after the
// restart is the output before it, where a fresh instance falls back to the
// P part alone (here 0: no error at steady state) and winds up again.
TEST(Pid, RetainedIntegralRestartsBumplessAtTheOperatingPoint) {
  const auto params = pid_opts({{"Kp", "4"}, {"Ti", "0.2"}, {"Td", "0.01"}, {"out_min", "-5"}, {"out_max", "5"}});
  BlockHarness a(registry(), "PID", params);
  ASSERT_CTL_OK(a);
  FirstOrder plant(0.5, 0.3, 1e-3);  // steady state needs u = 2 y: a bias only the integral holds
  a.set<double>("setpoint", 1.5);
  for (int j = 0; j < 6000; ++j) {
    a.set<double>("actual", plant.y);
    a.scan();
    plant.step(a.get<double>("y"));
  }
  const double u_before = a.get<double>("y");
  ASSERT_NEAR(u_before, 3.0, 1e-3);
  ASSERT_EQ(a.block().retain_cells(), 1u);
  Cell state;
  a.block().save_retain(&state);

  BlockHarness b(registry(), "PID", params), fresh(registry(), "PID", params);
  ASSERT_CTL_OK(b);
  b.block().load_retain(&state);
  for (BlockHarness* h : {&b, &fresh}) {
    h->set<double>("setpoint", 1.5);
    h->set<double>("actual", plant.y);
    h->scan();
  }
  EXPECT_NEAR(b.get<double>("y"), u_before, 1e-3) << "restored: no bump, no derivative kick";
  EXPECT_LT(fresh.get<double>("y"), 0.01) << "not restored: the integral starts from 0";
  Cell nan;
  nan.set<double>(std::nan(""));
  BlockHarness c(registry(), "PID", params);
  c.block().load_retain(&nan);  // a stored value that is not a number is not taken
  c.set<double>("setpoint", 1.0);
  c.scan();
  EXPECT_NEAR(c.get<double>("y"), 4.0, 1e-12);
}

// ---- PD_CONTROLLER ----------------------------------------------------------

TEST(PdController, LawAndLimit) {
  BlockHarness::Options o;
  o.params = {{"K_P", "2"}, {"K_D", "0.1"}, {"out_min", "-1"}, {"out_max", "1.5"}};
  BlockHarness h(registry(), "PD_CONTROLLER", o);
  ASSERT_CTL_OK(h);
  h.set<double>("x_d", 0.5);
  h.set<double>("x", 0.25);
  h.set<double>("v_d", 1.0);
  h.set<double>("v", 0.5);
  h.scan();
  EXPECT_DOUBLE_EQ(h.get<double>("tau"), 2 * 0.25 + 0.1 * 0.5);
  EXPECT_DOUBLE_EQ(h.get<double>("e_dot"), 0.5);
  h.set<double>("x_d", 5.0);
  h.scan();
  EXPECT_EQ(h.get<double>("tau"), 1.5);
  EXPECT_TRUE(h.get<bool>("saturated"));
  // Without v: backward difference of e.
  o.connected = std::set<std::string>{"x_d", "v_d", "x"};
  BlockHarness b(registry(), "PD_CONTROLLER", o);
  ASSERT_CTL_OK(b);
  b.set<double>("x_d", 0.1);
  b.scan();
  EXPECT_DOUBLE_EQ(b.get<double>("tau"), 0.2);  // ė = 0 on the first scan
  b.set<double>("x_d", 0.2);
  b.scan();
  EXPECT_NEAR(b.get<double>("e_dot"), 100.0, 1e-9);
  EXPECT_EQ(b.get<double>("tau"), 1.5);
  // Parameters.
  BlockHarness::Options bad;
  bad.params = {{"out_min", "1"}, {"out_max", "0"}};
  BlockHarness e(registry(), "PD_CONTROLLER", bad);
  EXPECT_FALSE(e.ok());
  bad.params = {{"K_P", "-1"}};
  BlockHarness e2(registry(), "PD_CONTROLLER", bad);
  EXPECT_FALSE(e2.ok());
}

}  // namespace
}  // namespace syncplc::motiontest
