// Tunable parameters: every one has a tuning input <param>_in that takes
// effect as if the parameter had been loaded with the value; retune_from and
// the tuning inputs are bumpless; invalid values are refused (ENO FALSE, a
// fault event, the last valid value kept).
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <set>
#include <string>
#include <vector>

#include "fblocks/library.hpp"
#include "runtime/core/block_harness.hpp"

namespace syncplc {
namespace {

constexpr double kQuietNaN = std::numeric_limits<double>::quiet_NaN();

std::set<std::string> ordinary_inputs(const BlockTypeInfo& t) {
  std::set<std::string> s;
  for (const auto& p : t.pins)
    if (p.dir == PinDir::In && p.tunes.empty()) s.insert(p.name);
  return s;
}

BlockHarness::Options base_options(const BlockTypeInfo& t) {
  BlockHarness::Options o;
  for (const auto& p : t.params)
    if (p.default_value.empty()) o.params[p.name] = "1";
  o.connected = ordinary_inputs(t);
  return o;
}

// A valid value different from the parameter's default (out_min lower,
// everything else higher: keeps out_min < out_max and positive rates).
double other_value(const ParamDecl& p, const BlockHarness::Options& o) {
  std::string text = p.default_value.empty() ? o.params.at(p.name) : p.default_value;
  const double d = std::stod(text);
  double v = p.name == "out_min" ? d - 0.5 : (d == 0 ? 0.25 : d * 1.5);
  if (p.max && v > *p.max) v = (d + *p.max) / 2;
  return v;
}

std::vector<std::uint64_t> output_cells(BlockHarness& h, const BlockTypeInfo& t) {
  std::vector<std::uint64_t> v;
  for (const auto& p : t.pins)
    if (p.dir == PinDir::Out)
      for (std::uint32_t k = 0; k < h.length(p.name); ++k) v.push_back(h.cell(p.name, k).raw);
  return v;
}

// Wiring a tuning input from the first scan is the same as loading the
// parameter with that value: checks, for every tunable parameter of every
// type, that the pin reaches the parameter it is named after.
TEST(Tuning, EveryTuningInputActsAsItsParameter) {
  int tunables = 0;
  for (const auto* t : builtin_blocks().all()) {
    for (const auto& p : t->params) {
      if (!p.tunable) continue;
      ++tunables;
      SCOPED_TRACE(t->name + "." + p.name);
      const std::string pin = p.name + kTuningSuffix;
      ASSERT_GE(t->pin_index(pin), 0);
      auto o = base_options(*t);
      // An integer parameter (MC_AXIS.home_method) gets the next integer
      // within its range and its tuning input its own type.
      const bool integer = p.type != IecType::LREAL && p.type != IecType::REAL;
      double v = other_value(p, o);
      if (integer) {
        const double d = std::stod(p.default_value.empty() ? o.params.at(p.name) : p.default_value);
        v = (p.max && d + 1 > *p.max) ? d - 1 : d + 1;
      }
      auto wired = o;
      wired.connected->insert(pin);
      auto loaded = o;
      loaded.params[p.name] = integer ? std::to_string(static_cast<long long>(v)) : std::to_string(v);
      BlockHarness a(builtin_blocks(), t->name, wired), b(builtin_blocks(), t->name, loaded);
      ASSERT_TRUE(a.ok());
      ASSERT_TRUE(b.ok()) << (b.errors().empty() ? "" : b.errors()[0]);
      switch (p.type) {
        case IecType::INT: a.set<std::int16_t>(pin, static_cast<std::int16_t>(v)); break;
        case IecType::DINT: a.set<std::int32_t>(pin, static_cast<std::int32_t>(v)); break;
        case IecType::LINT: a.set<std::int64_t>(pin, static_cast<std::int64_t>(v)); break;
        case IecType::REAL: a.set<float>(pin, std::stof(std::to_string(v))); break;
        default: ASSERT_EQ(p.type, IecType::LREAL) << "a tunable parameter of a type this test does not set";
                 a.set<double>(pin, std::stod(std::to_string(v)));
      }
      std::mt19937 rng(7);
      std::uniform_real_distribution<double> value(-1.0, 1.0);
      for (int scan = 0; scan < 50; ++scan) {
        for (const auto& q : t->pins)
          if (q.dir == PinDir::In && q.tunes.empty() && q.type == IecType::LREAL && q.cls == TypeClass::Exact)
            for (std::uint32_t k = 0; k < a.length(q.name); ++k) {
              const double x = value(rng);
              a.set<double>(q.name, k, x);
              b.set<double>(q.name, k, x);
            }
        a.scan();
        b.scan();
        ASSERT_EQ(output_cells(a, *t), output_cells(b, *t)) << "scan " << scan;
      }
      EXPECT_TRUE(a.events().empty());
    }
  }
  EXPECT_GE(tunables, 20);
}

// A PI loop on a first-order plant x' = (u - x)/1 s, setpoint 1.
struct PiLoop {
  BlockHarness pid;
  double x = 0;
  explicit PiLoop(BlockHarness::Options o) : pid(builtin_blocks(), "PID", std::move(o)) {
    pid.set<double>("setpoint", 1.0);
  }
  double step() {
    pid.set<double>("actual", x);
    pid.scan();
    const double u = pid.get<double>("y");
    x += 1e-3 * (u - x);
    return u;
  }
};

BlockHarness::Options pi_options(const std::string& kp, const std::string& ti) {
  BlockHarness::Options o;
  o.params = {{"Kp", kp}, {"Ti", ti}};
  return o;
}

// Largest |y(j) - y(j-1)| over n scans, and the last y.
double max_step(PiLoop& l, int n, double* last) {
  double prev = l.step(), m = 0;
  for (int i = 1; i < n; ++i) {
    const double y = l.step();
    m = std::max(m, std::fabs(y - prev));
    prev = y;
  }
  *last = prev;
  return m;
}

TEST(Tuning, PidRetuneInSteadyStateDoesNotBump) {
  PiLoop l(pi_options("1", "0.5"));
  double y0;
  max_step(l, 30000, &y0);  // 30 s: settled, the integral holds y = 1
  EXPECT_NEAR(y0, 1.0, 1e-6);
  BlockHarness fresh(builtin_blocks(), "PID", pi_options("4", "0.05"));
  ASSERT_TRUE(fresh.ok());
  l.pid.block().retune_from(fresh.block());
  EXPECT_NEAR(l.step(), y0, 1e-6);  // a Ki-times-integral form would jump to 10 y0
}

TEST(Tuning, PidIntegralTimeChangeMidTransientIsOneNormalStep) {
  PiLoop l(pi_options("1", "0.5"));
  double y0;
  const double normal = max_step(l, 200, &y0);  // rising: e is large
  BlockHarness fresh(builtin_blocks(), "PID", pi_options("1", "0.05"));
  l.pid.block().retune_from(fresh.block());
  EXPECT_LE(std::fabs(l.step() - y0), 1.5 * normal);
}

TEST(Tuning, PidTuningInputsAreValidatedAndBumpless) {
  auto o = pi_options("1", "0.5");
  o.connected = std::set<std::string>{"setpoint", "actual", "Kp_in", "Ti_in", "out_max_in"};
  PiLoop l(o);
  l.pid.set<double>("Kp_in", 1.0);
  l.pid.set<double>("Ti_in", 0.5);
  l.pid.set<double>("out_max_in", 100.0);
  double y0;
  max_step(l, 30000, &y0);
  EXPECT_TRUE(l.pid.get<bool>("ENO"));
  l.pid.set<double>("Ti_in", 0.05);
  l.pid.set<double>("Kp_in", 4.0);
  EXPECT_NEAR(l.step(), y0, 1e-6);
  EXPECT_TRUE(l.pid.get<bool>("ENO"));
  EXPECT_TRUE(l.pid.events().empty());

  // Below its range: refused, the last valid Ti stays, the loop keeps running.
  l.pid.set<double>("Ti_in", -1.0);
  l.x = 0.5;  // a disturbance: the controller must still act (P = 4 * 0.5)
  const double y = l.step();
  EXPECT_FALSE(l.pid.get<bool>("ENO"));
  EXPECT_NEAR(y, y0 + 2.0, 1e-3);
  ASSERT_EQ(l.pid.events().size(), 1u);
  EXPECT_STREQ(l.pid.events()[0].message, "tuning input invalid, last valid value kept");
  EXPECT_EQ(l.pid.events()[0].value, -1.0);
  l.pid.set<double>("Ti_in", kQuietNaN);
  l.step();
  EXPECT_FALSE(l.pid.get<bool>("ENO"));
  // out_max below out_min (-100): refused by the block.
  l.pid.set<double>("Ti_in", 0.05);
  l.pid.set<double>("out_max_in", -200.0);
  l.step();
  EXPECT_FALSE(l.pid.get<bool>("ENO"));
  l.pid.set<double>("out_max_in", 1.5);
  l.step();
  EXPECT_TRUE(l.pid.get<bool>("ENO"));
  l.x = -10;
  EXPECT_DOUBLE_EQ(l.step(), 1.5);  // the new limit acts
}

TEST(Tuning, PdAndSyncControllerRefuseCrossedLimits) {
  for (const char* type : {"PD_CONTROLLER", "SYNC_CONTROLLER"}) {
    SCOPED_TRACE(type);
    const BlockTypeInfo& t = *builtin_blocks().find(type);
    auto o = base_options(t);
    o.connected->insert("out_min_in");
    BlockHarness h(builtin_blocks(), type, o);
    ASSERT_TRUE(h.ok());
    h.set<double>("out_min_in", -1.0);
    h.set<double>("x_d", 10.0);
    h.scan();
    EXPECT_TRUE(h.get<bool>("ENO"));
    EXPECT_DOUBLE_EQ(h.get<double>("tau"), 1.0);
    h.set<double>("out_min_in", 2.0);  // above out_max = 1
    h.scan();
    EXPECT_FALSE(h.get<bool>("ENO"));
    h.set<double>("x_d", -10.0);
    h.scan();
    EXPECT_DOUBLE_EQ(h.get<double>("tau"), -1.0);  // still running on the last valid limits
  }
}

TEST(Tuning, SyncControllerBoundaryLayerMustStayPositive) {
  const BlockTypeInfo& t = *builtin_blocks().find("SYNC_CONTROLLER");
  auto o = base_options(t);
  o.connected->insert("phi_in");
  BlockHarness h(builtin_blocks(), "SYNC_CONTROLLER", o);
  h.set<double>("phi_in", 0.0);  // robust 2 (sat) divides by phi
  h.scan();
  EXPECT_FALSE(h.get<bool>("ENO"));
  h.set<double>("phi_in", 50.0);
  h.scan();
  EXPECT_TRUE(h.get<bool>("ENO"));
}

// COSINE_TRAJECTORY: a new omega mid-motion changes the speed, x stays
// continuous (the scan after the change moves one step at the new speed).
TEST(Tuning, CosineOmegaChangeKeepsThePosition) {
  auto make = [](const char* omega) {
    BlockHarness::Options o;
    o.params = {{"amplitude", "1"}, {"omega", omega}, {"cycles", "0"}};
    return o;
  };
  for (bool by_pin : {false, true}) {
    SCOPED_TRACE(by_pin ? "tuning input" : "retune_from");
    auto o = make("2");
    if (by_pin) o.connected = std::set<std::string>{"enable", "omega_in"};
    BlockHarness h(builtin_blocks(), "COSINE_TRAJECTORY", o);
    ASSERT_TRUE(h.ok());
    if (by_pin) h.set<double>("omega_in", 2.0);
    h.scans(700);
    const double x0 = h.get<double>("x");
    const double phi0 = 2.0 * 0.699;  // phase at the last scan (t = 699 ms)
    if (by_pin) {
      h.set<double>("omega_in", 5.0);
    } else {
      BlockHarness fresh(builtin_blocks(), "COSINE_TRAJECTORY", make("5"));
      h.block().retune_from(fresh.block());
    }
    h.scan();
    const double phi1 = phi0 + 5.0 * 0.001;
    EXPECT_NEAR(h.get<double>("x"), 1 - std::cos(phi1), 1e-12);
    EXPECT_NEAR(h.get<double>("v"), 5.0 * std::sin(phi1), 1e-12);
    EXPECT_LT(std::fabs(h.get<double>("x") - x0), 5.0 * 0.001 * 1.01);  // one step at the new speed
    EXPECT_TRUE(h.get<bool>("ENO"));
  }
}

}  // namespace
}  // namespace syncplc
