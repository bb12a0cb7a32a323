// SYNC_CONTROLLER through BlockHarness: declaration, parameter checks, the
// per-axis law of eq. (16) against the centralized eq. (11), the eq. (15)
// delay compensation and the filling of lost samples.
#include <cmath>
#include <random>

#include "fblocks/motion/sync_control_math.hpp"
#include "tests/motion/control_sim.hpp"

namespace syncplc::motiontest {
namespace {

using motion::backward_difference;
using motion::CentralizedSyncController;
using motion::RobustTerm;
using motion::SyncGains;

BlockHarness::Options sync_opts(int axis, int n, std::map<std::string, std::string> extra = {},
                                std::set<std::string> connected = {"x_d", "v_d", "a_d", "x", "e_rx", "e_valid"}) {
  BlockHarness::Options o;
  o.params = {{"axis", std::to_string(axis)}, {"n", std::to_string(n)}};
  for (auto& [k, v] : extra) o.params[k] = v;
  o.connected = std::move(connected);
  return o;
}

TEST(SyncController, Declaration) {
  const BlockTypeInfo* t = registry().find("SYNC_CONTROLLER");
  ASSERT_NE(t, nullptr);
  EXPECT_EQ(t->category, "Motion");
  EXPECT_NE(t->reference.find("(3)-(16)"), std::string::npos);
  EXPECT_NE(t->doc.find("21/8"), std::string::npos);
  for (const char* p : {"x_d", "v_d", "a_d", "x", "v", "e_rx", "e_valid", "tau", "e", "e_dot", "E", "eps",
                        "saturated", "estimated"})
    EXPECT_GE(t->pin_index(p), 0) << p;
  EXPECT_EQ(t->pins[static_cast<std::size_t>(t->pin_index("e_rx"))].length_param, "n");
  EXPECT_EQ(t->pins[static_cast<std::size_t>(t->pin_index("e_valid"))].length_param, "n");
  EXPECT_EQ(t->pins[static_cast<std::size_t>(t->pin_index("tau"))].unit, "PWM");
  EXPECT_EQ(t->params[static_cast<std::size_t>(t->param_index("K_D"))].unit, "PWM.s/rad");
  EXPECT_EQ(t->params[static_cast<std::size_t>(t->param_index("K_H"))].unit, "PWM.s^2/rad");
  BlockHarness h(registry(), "SYNC_CONTROLLER", sync_opts(3, 5));
  ASSERT_CTL_OK(h);
  EXPECT_EQ(h.length("e_rx"), 5u);
  EXPECT_EQ(h.length("e_valid"), 5u);
  EXPECT_TRUE(h.get<bool>("e_valid", 4));  // unconnected elements count as received
}

TEST(SyncController, InvalidParametersFailAtLoad) {
  struct Bad {
    std::map<std::string, std::string> p;
    const char* what;
  };
  const std::vector<Bad> bad = {
      {{{"axis", "4"}, {"n", "3"}}, "axis 4 is not one of"},
      {{{"axis", "0"}, {"n", "3"}}, "axis must be in"},
      {{{"axis", "1"}, {"n", "257"}}, "n must be in"},
      {{{"axis", "1"}, {"n", "2"}, {"alpha", "-0.1"}}, "alpha must be >="},
      {{{"axis", "1"}, {"n", "2"}, {"m", "-1"}}, "m must be >="},
      {{{"axis", "1"}, {"n", "2"}, {"robust", "3"}}, "robust must be in"},
      {{{"axis", "1"}, {"n", "2"}, {"robust", "2"}, {"phi", "0"}}, "phi > 0"},
      {{{"axis", "1"}, {"n", "2"}, {"out_min", "1"}, {"out_max", "1"}}, "out_min must be less"},
      {{{"axis", "1"}, {"n", "2"}, {"rx_delay", "2"}}, "rx_delay must be in"},
  };
  for (const auto& b : bad) {
    BlockHarness::Options o;
    o.params = b.p;
    BlockHarness h(registry(), "SYNC_CONTROLLER", o);
    EXPECT_FALSE(h.ok()) << b.what;
    EXPECT_NE(errors_of(h).find(b.what), std::string::npos) << errors_of(h);
  }
  // axis and n have no default.
  BlockHarness none(registry(), "SYNC_CONTROLLER");
  EXPECT_FALSE(none.ok());
  // eq9 and sign do not need phi.
  BlockHarness eq9(registry(), "SYNC_CONTROLLER", sync_opts(1, 2, {{"robust", "1"}, {"phi", "0"}}));
  ASSERT_CTL_OK(eq9);
}

// Axis 1 has no preceding axis: eq. (16) is a PD with feed-forward and the m ė term.
TEST(SyncController, FirstAxisIsFeedForwardPlusPd) {
  BlockHarness h(registry(), "SYNC_CONTROLLER",
                 sync_opts(1, 3, {{"K_N", "0"}, {"out_min", "-100"}, {"out_max", "100"}},
                           {"x_d", "v_d", "a_d", "x", "v", "e_rx", "e_valid"}));
  ASSERT_CTL_OK(h);
  h.set<double>("x_d", 1.0);
  h.set<double>("v_d", 2.0);
  h.set<double>("a_d", 3.0);
  h.set<double>("x", 0.75);
  h.set<double>("v", 1.5);
  h.set<double>("e_rx", 1, 1e6);  // ignored: only preceding axes count
  h.scan();
  const PaperGains g;
  const double e = 0.25, ed = 0.5;
  EXPECT_DOUBLE_EQ(h.get<double>("tau"), g.K_H * 3 + g.K_C * 2 + g.K_P * e + g.K_D * ed + g.m * ed);
  EXPECT_DOUBLE_EQ(h.get<double>("e"), e);
  EXPECT_DOUBLE_EQ(h.get<double>("e_dot"), ed);
  EXPECT_DOUBLE_EQ(h.get<double>("E"), e);
  EXPECT_EQ(h.get<double>("eps"), 0.0);
  EXPECT_FALSE(h.get<bool>("saturated"));
}

TEST(SyncController, BackwardDifferenceWithoutV) {
  BlockHarness h(registry(), "SYNC_CONTROLLER", sync_opts(1, 1, {{"K_N", "0"}}));
  ASSERT_CTL_OK(h);
  h.set<double>("x_d", 0.5);
  h.scan();
  EXPECT_EQ(h.get<double>("e_dot"), 0.0);  // first scan: no history
  h.set<double>("x", 0.1);
  h.scan();
  EXPECT_NEAR(h.get<double>("e_dot"), -0.1 / 1e-3, 1e-9);
  h.set_period_ns(2'000'000);  // the difference uses the actual scan interval
  h.scan();
  h.set<double>("x_d", 0.6);
  h.scan();
  EXPECT_NEAR(h.get<double>("e_dot"), 0.1 / 2e-3, 1e-9);
}

TEST(SyncController, OutputLimit) {
  BlockHarness h(registry(), "SYNC_CONTROLLER", sync_opts(1, 1, {{"out_min", "-0.2"}, {"out_max", "0.3"}}));
  ASSERT_CTL_OK(h);
  h.set<double>("x_d", 10.0);
  h.scan();
  EXPECT_EQ(h.get<double>("tau"), 0.3);
  EXPECT_TRUE(h.get<bool>("saturated"));
  h.set<double>("x_d", -10.0);
  h.scan();
  EXPECT_EQ(h.get<double>("tau"), -0.2);
  EXPECT_TRUE(h.get<bool>("saturated"));
  h.set<double>("x_d", 0.0);
  h.scan();
  h.scan();
  EXPECT_EQ(h.get<double>("tau"), 0.0);
  EXPECT_FALSE(h.get<bool>("saturated"));
}

// With rx_delay = 0 (e_rx holds the current errors) the n decentralized blocks
// compute exactly what the centralized eq. (11) computes from the full e, ė.
void expect_decentralized_equals_centralized(int n, RobustTerm robust, std::uint32_t seed) {
  SyncGains g;
  g.K_P = 0.6221;
  g.K_D = 0.6221e-3;
  g.K_H = 0.001544;
  g.K_C = 0.02807;
  g.m = 0.2586268;
  g.K_N = robust == RobustTerm::Sat ? 10 : 0.05;
  g.Delta_H = 0.0008;
  g.Delta_C = 0.009;
  g.phi = 100;
  g.robust = robust;
  g.out_min = -0.4;
  g.out_max = 0.3;
  const double kappa = 1.3;
  std::map<std::string, std::string> p = {
      {"alpha", "1.3"},        {"K_P", "0.6221"},   {"K_D", "0.0006221"}, {"K_H", "0.001544"},
      {"K_C", "0.02807"},      {"m", "0.2586268"},  {"K_N", robust == RobustTerm::Sat ? "10" : "0.05"},
      {"Delta_H", "0.0008"},   {"Delta_C", "0.009"}, {"phi", "100"},
      {"robust", std::to_string(static_cast<int>(robust))},
      {"out_min", "-0.4"},     {"out_max", "0.3"},  {"rx_delay", "0"}};
  std::vector<std::unique_ptr<BlockHarness>> blocks;
  for (int k = 1; k <= n; ++k) {
    blocks.push_back(std::make_unique<BlockHarness>(registry(), "SYNC_CONTROLLER", sync_opts(k, n, p)));
    ASSERT_CTL_OK(*blocks.back());
  }
  CentralizedSyncController c(n, kappa, g);
  std::mt19937 rng(seed);
  std::normal_distribution<double> noise(0, 1e-4);
  Eigen::VectorXd a(n), v(n), e(n), ed(n), e_prev(n);
  std::vector<double> x(static_cast<std::size_t>(n), 0.0);
  int compared = 0, saturated = 0;
  for (int j = 0; j < 1500; ++j) {
    const double t = j * 1e-3;
    const double A = 4 * std::numbers::pi;
    const double xd = A * (1 - std::cos(t)), vd = A * std::sin(t), ad = A * std::cos(t);
    for (int i = 0; i < n; ++i) {
      x[static_cast<std::size_t>(i)] = xd - 0.1 * std::sin(3 * t + i) + noise(rng);  // error-ish random walk
      a[i] = ad;
      v[i] = vd;
      e[i] = xd - x[static_cast<std::size_t>(i)];
      ed[i] = j == 0 ? 0.0 : backward_difference(e[i], e_prev[i], 1'000'000);
    }
    e_prev = e;
    c.compute(a, v, e, ed);
    for (int k = 0; k < n; ++k) {
      BlockHarness& h = *blocks[static_cast<std::size_t>(k)];
      h.set<double>("x_d", xd);
      h.set<double>("v_d", vd);
      h.set<double>("a_d", ad);
      h.set<double>("x", x[static_cast<std::size_t>(k)]);
      for (int i = 0; i < n; ++i) h.set<double>("e_rx", static_cast<std::uint32_t>(i), e[i]);
      h.scan();
      // Exact: the same operations in the same order.
      ASSERT_EQ(h.get<double>("tau"), c.tau()[k]) << "n=" << n << " axis " << k + 1 << " scan " << j;
      ASSERT_EQ(h.get<double>("E"), c.E()[k]) << "n=" << n << " axis " << k + 1 << " scan " << j;
      ASSERT_EQ(h.get<double>("eps"), c.eps()[k]) << "n=" << n << " axis " << k + 1 << " scan " << j;
      ASSERT_EQ(h.get<double>("e_dot"), ed[k]);
      ASSERT_EQ(h.get<bool>("saturated"), c.saturated(k));
      saturated += c.saturated(k) ? 1 : 0;
      ++compared;
    }
  }
  EXPECT_EQ(compared, 1500 * n);
  EXPECT_GT(saturated, 0) << "the limit was exercised, n=" << n;
  EXPECT_LT(saturated, compared / 2) << "mostly unsaturated";
}

TEST(SyncController, DecentralizedEqualsCentralizedWithoutDelay) {
  for (int n = 1; n <= 8; ++n)
    for (RobustTerm r : {RobustTerm::Sign, RobustTerm::Eq9, RobustTerm::Sat})
      expect_decentralized_equals_centralized(n, r, 1000u + static_cast<std::uint32_t>(n));
}

// Eq. (15) on the one-scan-late errors: with compensation the block uses
// ê_i(j) = 21/8 e_i(j−1) − 19/8 e_i(j−2) + 7/8 e_i(j−3) − 1/8 e_i(j−4), and the
// same predictor on the backward differences for Ė; without, e_i(j−1).
TEST(SyncController, DelayCompensationIsEq15) {
  const int n = 3, k = 3;
  // Isolate E (output E) and Ė (tau = K_D Ė with every other gain zero).
  std::map<std::string, std::string> p = {{"alpha", "0.8"}, {"K_P", "0"}, {"K_H", "0"}, {"K_C", "0"}, {"m", "0"},
                                          {"K_N", "0"},     {"K_D", "1"}, {"out_min", "-1e9"}, {"out_max", "1e9"}};
  auto pc = p;
  pc["compensation"] = "FALSE";
  BlockHarness with(registry(), "SYNC_CONTROLLER", sync_opts(k, n, p));
  BlockHarness without(registry(), "SYNC_CONTROLLER", sync_opts(k, n, pc));
  ASSERT_CTL_OK(with);
  ASSERT_CTL_OK(without);
  auto sig = [](int i, int j) { return 0.3 * std::sin(0.01 * j + i) + 1e-5 * j * j; };  // e_i(j)
  const double Ts = 1e-3, kap = 0.8;
  std::vector<std::vector<double>> hist(2);  // received e_i(j−1), newest last
  for (int j = 0; j < 60; ++j) {
    for (BlockHarness* h : {&with, &without}) {
      h->set<double>("x_d", 0.0);
      h->set<double>("x", -0.01 * j);  // own error e_3 = 0.01 j
      for (int i = 0; i < 2; ++i) h->set<double>("e_rx", static_cast<std::uint32_t>(i), j == 0 ? 0.0 : sig(i, j - 1));
      h->scan();
    }
    for (int i = 0; i < 2; ++i) hist[static_cast<std::size_t>(i)].push_back(j == 0 ? 0.0 : sig(i, j - 1));
    if (j < 6) continue;  // the estimator ramps its order up over the first samples
    const double e3 = 0.01 * j, ed3 = 0.01 / Ts;
    double E_c = 0, Ed_c = 0, E_n = 0, Ed_n = 0;
    for (int i = 0; i < 2; ++i) {
      const auto& hi = hist[static_cast<std::size_t>(i)];
      const std::size_t L = hi.size();
      auto r = [&](std::size_t back) { return hi[L - 1 - back]; };  // r(0) = e_i(j−1)
      const double pred = 21.0 / 8 * r(0) - 19.0 / 8 * r(1) + 7.0 / 8 * r(2) - 1.0 / 8 * r(3);
      auto d = [&](std::size_t back) { return (r(back) - r(back + 1)) / Ts; };
      const double pred_d = 21.0 / 8 * d(0) - 19.0 / 8 * d(1) + 7.0 / 8 * d(2) - 1.0 / 8 * d(3);
      E_c += -kap / 2 * pred;
      Ed_c += -kap / 2 * pred_d;
      E_n += -kap / 2 * r(0);
      Ed_n += -kap / 2 * d(0);
    }
    E_c += (1 + kap) * e3;
    Ed_c += (1 + kap) * ed3;
    E_n += (1 + kap) * e3;
    Ed_n += (1 + kap) * ed3;
    EXPECT_NEAR(with.get<double>("E"), E_c, 1e-12) << j;
    EXPECT_NEAR(with.get<double>("tau"), Ed_c, 1e-8) << j;
    EXPECT_NEAR(without.get<double>("E"), E_n, 1e-12) << j;
    EXPECT_NEAR(without.get<double>("tau"), Ed_n, 1e-8) << j;
    // ε_3 = e_3 − mean of the two (predicted / delayed) preceding errors.
    EXPECT_NEAR(with.get<double>("eps"), (E_c - e3) / kap, 1e-11) << j;
  }
  EXPECT_EQ(with.get<std::uint32_t>("estimated"), 0u);
}

// On errors that are linear in time the eq. (15) predictor is exact, so the
// compensated one-scan-late block equals the centralized law on current errors.
TEST(SyncController, CompensationRemovesTheDelayOnRamps) {
  const int n = 4;
  SyncGains g;
  g.K_P = 0.6221;
  g.K_D = 0.6221e-3;
  g.K_H = 0.001544;
  g.K_C = 0.02807;
  g.m = 0.2586268;
  g.K_N = 10;
  g.phi = 100;
  g.robust = RobustTerm::Sat;
  g.out_min = -1e9;
  g.out_max = 1e9;
  CentralizedSyncController c(n, 1.3, g);
  std::vector<std::unique_ptr<BlockHarness>> late, uncomp;
  for (int k = 1; k <= n; ++k) {
    late.push_back(std::make_unique<BlockHarness>(registry(), "SYNC_CONTROLLER",
                                                  sync_opts(k, n, {{"out_min", "-1e9"}, {"out_max", "1e9"}})));
    uncomp.push_back(std::make_unique<BlockHarness>(
        registry(), "SYNC_CONTROLLER",
        sync_opts(k, n, {{"out_min", "-1e9"}, {"out_max", "1e9"}, {"compensation", "FALSE"}})));
  }
  Eigen::VectorXd a = Eigen::VectorXd::Constant(n, 2.0), v = Eigen::VectorXd::Constant(n, 1.0), e(n), ed(n);
  double worst_uncomp = 0;
  for (int j = 0; j < 50; ++j) {
    for (int i = 0; i < n; ++i) {
      e[i] = 0.01 * (i + 1) + 0.05 * (i + 1) * j * 1e-3 * (i % 2 ? -1 : 1);  // ramps, different slopes
      ed[i] = j == 0 ? 0.0 : 0.05 * (i + 1) * (i % 2 ? -1 : 1);
    }
    for (int k = 0; k < n; ++k)
      for (auto* set : {&late, &uncomp}) {
        BlockHarness& h = *(*set)[static_cast<std::size_t>(k)];
        h.set<double>("x_d", 0.0);
        h.set<double>("x", -e[k]);
        h.set<double>("v_d", 1.0);
        h.set<double>("a_d", 2.0);
        for (int i = 0; i < n; ++i)
          h.set<double>("e_rx", static_cast<std::uint32_t>(i),
                        j == 0 ? 0.0 : e[i] - 0.05 * (i + 1) * 1e-3 * (i % 2 ? -1 : 1));  // e_i(j−1)
        h.scan();
      }
    c.compute(a, v, e, ed);
    if (j < 6) continue;  // start-up of the estimators (order ramps up)
    for (int k = 0; k < n; ++k) {
      EXPECT_NEAR(late[static_cast<std::size_t>(k)]->get<double>("tau"), c.tau()[k], 1e-9) << k << " " << j;
      EXPECT_NEAR(late[static_cast<std::size_t>(k)]->get<double>("E"), c.E()[k], 1e-12) << k << " " << j;
      worst_uncomp =
          std::max(worst_uncomp, std::abs(uncomp[static_cast<std::size_t>(k)]->get<double>("E") - c.E()[k]));
    }
  }
  EXPECT_GT(worst_uncomp, 1e-5) << "without compensation the one-scan delay shows";
}

// A lost sample (e_valid FALSE) is filled by the message estimator and counted;
// the garbage in the lost element is never used.
TEST(SyncController, LostSamplesAreEstimatedAndCounted) {
  const int n = 3;
  BlockHarness h(registry(), "SYNC_CONTROLLER", sync_opts(3, n, {{"K_N", "0"}, {"out_min", "-1e9"}, {"out_max", "1e9"}}));
  BlockHarness ref(registry(), "SYNC_CONTROLLER", sync_opts(3, n, {{"K_N", "0"}, {"out_min", "-1e9"}, {"out_max", "1e9"}}));
  ASSERT_CTL_OK(h);
  ASSERT_CTL_OK(ref);
  auto sig = [](int i, int j) { return 0.01 * (i + 1) * j * 1e-3 + 0.2; };  // linear: the estimator is exact
  std::uint32_t lost = 0;
  for (int j = 0; j < 200; ++j) {
    for (BlockHarness* b : {&h, &ref}) {
      b->set<double>("x_d", 0.1);
      for (int i = 0; i < 2; ++i) {
        const bool drop = b == &h && j > 10 && (j % 7 == i || j % 11 == 0);
        if (drop && b == &h) ++lost;
        b->set<double>("e_rx", static_cast<std::uint32_t>(i), drop ? 1e6 : sig(i, j - 1));
        b->set<bool>("e_valid", static_cast<std::uint32_t>(i), !drop);
      }
      b->scan();
    }
    ASSERT_NEAR(h.get<double>("tau"), ref.get<double>("tau"), 1e-9) << j;
    ASSERT_NEAR(h.get<double>("E"), ref.get<double>("E"), 1e-12) << j;
  }
  EXPECT_GT(lost, 20u);
  EXPECT_EQ(h.get<std::uint32_t>("estimated"), lost);
  EXPECT_EQ(ref.get<std::uint32_t>("estimated"), 0u);
}

}  // namespace
}  // namespace syncplc::motiontest
