// SYNC_CONTROLLER and PD_CONTROLLER in closed loop on the paper-000 plant
// (section 5): four axes P(s) = k/(s(τs+1)), exact ZOH at T_s = 1 ms, the
// errors of the preceding axes one scan late (eq. 13), the +0.05 PWM input
// disturbance on axis 4 from 2 s to 4 s, the paper's gains in SI.
// The measured numbers are printed ("paper000:" lines) and reported in
// docs/motion/sync-controller.md; the assertions are the claims, not the numbers.
#include <cmath>
#include <array>
#include <cstdio>
#include <fstream>
#include <random>
#include <sstream>

#include "fblocks/motion/sync_control_math.hpp"
#include "tests/motion/control_sim.hpp"

namespace syncplc::motiontest {
namespace {

using motion::backward_difference;
using motion::CentralizedSyncController;
using motion::RobustTerm;
using motion::SyncGains;

void print(const char* name, const RunResult& r) {
  std::printf("paper000: %-34s Track-RSME %.6f  Sync-RSME %.6f  tau RMS %.4f  dtau RMS %.6f  sat %.3f\n", name,
              r.track_rsme, r.sync_rsme, r.tau_rms, r.dtau_rms, r.sat_fraction);
}

RunResult run(RunOptions o, const char* name) {
  RunResult r = run_paper_loop(o);
  EXPECT_TRUE(r.ok) << r.error;
  print(name, r);
  return r;
}

// The closed form used by ZohAxis against exp([A B; 0 0] T) by its series.
TEST(PaperPlant, ZohIsTheMatrixExponential) {
  for (const auto& [tau, k] : {std::pair{0.055, 35.6206}, std::pair{0.040, 52.2836}})
    for (const double T : {1e-3, 1e-2, 0.1}) {
      Eigen::Matrix3d M = Eigen::Matrix3d::Zero();
      M(0, 1) = 1;
      M(1, 1) = -1 / tau;
      M(1, 2) = k / tau;
      M *= T;
      Eigen::Matrix3d term = Eigen::Matrix3d::Identity(), sum = Eigen::Matrix3d::Identity();
      for (int i = 1; i < 60; ++i) {
        term = term * M / i;
        sum += term;
      }
      const ZohAxis z(tau, k, T);
      EXPECT_NEAR(z.phi12, sum(0, 1), 1e-14 * std::max(1.0, std::abs(sum(0, 1))));
      EXPECT_NEAR(z.phi22, sum(1, 1), 1e-14);
      EXPECT_NEAR(z.g1, sum(0, 2), 1e-12 * std::abs(sum(0, 2)));
      EXPECT_NEAR(z.g2, sum(1, 2), 1e-12 * std::abs(sum(1, 2)));
      EXPECT_EQ(sum(0, 0), 1.0);
    }
}

// Theorem 1: at a fixed final position (ẋ_d = ẍ_d = 0, so N = 0), with the
// one-scan delay and the eq. (15) compensation, e → 0 and ε → 0.
TEST(SyncLoop, StepConvergesAsTheorem1) {
  RunOptions o;
  o.ref = step_reference(0.5);
  o.samples = 10000;  // 10 s; the tail measured is the last second
  o.disturbance = false;
  o.x0 = {0.1, -0.2, 0.3, 0.0};  // the axes start apart: large initial ε
  for (const char* kn : {"10", "0"}) {
    o.params = {{"K_N", kn}};
    double max_e_start = 0;
    o.observe = [&](int j, const std::vector<double>& e, const std::vector<double>&) {
      if (j == 0)
        for (double v : e) max_e_start = std::max(max_e_start, std::abs(v));
    };
    const RunResult r = run_paper_loop(o);
    ASSERT_TRUE(r.ok) << r.error;
    std::printf("paper000: step 0.5 rad, K_N %s sat: max|e| over the last second %.3g, max|eps| %.3g, "
                "saturated %.4f of the scans\n", kn, r.final_max_e, r.final_max_eps, r.sat_fraction);
    EXPECT_GT(max_e_start, 0.5);
    EXPECT_LT(r.final_max_e, 1e-5);
    EXPECT_LT(r.final_max_eps, 1e-5);
  }
}

// Decentralized (rx_delay 0: current errors) and centralized eq. (11) drive
// two copies of the plant along identical trajectories.
TEST(SyncLoop, DecentralizedEqualsCentralizedInClosedLoop) {
  const double T = 1e-3;
  const int n = 4, N = 6283;
  auto p_dec = paper_plant(T), p_cen = paper_plant(T);
  SyncGains g;
  const PaperGains pg;
  g.K_P = pg.K_P;
  g.K_D = pg.K_D;
  g.K_H = pg.K_H;
  g.K_C = pg.K_C;
  g.m = pg.m;
  g.K_N = 10;
  g.phi = 100;
  g.robust = RobustTerm::Sat;
  g.out_min = -1;
  g.out_max = 1;
  CentralizedSyncController c(n, pg.alpha, g);
  std::vector<std::unique_ptr<BlockHarness>> blocks;
  for (int k = 1; k <= n; ++k) {
    BlockHarness::Options o;
    o.params = {{"axis", std::to_string(k)}, {"n", "4"}, {"rx_delay", "0"}};
    o.connected = std::set<std::string>{"x_d", "v_d", "a_d", "x", "e_rx", "e_valid"};
    blocks.push_back(std::make_unique<BlockHarness>(registry(), "SYNC_CONTROLLER", o));
    ASSERT_CTL_OK(*blocks.back());
  }
  const Reference ref = cosine_reference();
  Eigen::VectorXd a(n), v(n), e(n), ed(n), e_prev(n);
  for (int j = 0; j < N; ++j) {
    double xd, vd, ad;
    ref.at(j * T, xd, vd, ad);
    for (int i = 0; i < n; ++i) {
      a[i] = ad;
      v[i] = vd;
      e[i] = xd - p_cen[static_cast<std::size_t>(i)].x;
      ed[i] = j == 0 ? 0.0 : backward_difference(e[i], e_prev[i], 1'000'000);
    }
    e_prev = e;
    c.compute(a, v, e, ed);
    for (int k = 0; k < n; ++k) {
      BlockHarness& h = *blocks[static_cast<std::size_t>(k)];
      h.set<double>("x_d", xd);
      h.set<double>("v_d", vd);
      h.set<double>("a_d", ad);
      h.set<double>("x", p_dec[static_cast<std::size_t>(k)].x);
      for (int i = 0; i < n; ++i) h.set<double>("e_rx", static_cast<std::uint32_t>(i), xd - p_dec[static_cast<std::size_t>(i)].x);
      h.scan();
    }
    for (int k = 0; k < n; ++k) {
      const double u_dec = blocks[static_cast<std::size_t>(k)]->get<double>("tau");
      ASSERT_EQ(u_dec, c.tau()[k]) << "axis " << k + 1 << " scan " << j;
      const double d = (k == 3 && j * T >= 2.0 && j * T < 4.0) ? 0.05 : 0.0;
      p_dec[static_cast<std::size_t>(k)].step(u_dec + d);
      p_cen[static_cast<std::size_t>(k)].step(c.tau()[k] + d);
    }
  }
  for (int k = 0; k < n; ++k) EXPECT_EQ(p_dec[static_cast<std::size_t>(k)].x, p_cen[static_cast<std::size_t>(k)].x);
}

// Eqs. (26)–(27) on the cosine reference: the synchronous controller against
// the PD baseline with the same K_P, K_D (paper Table 1: −45.7 % Sync-RSME,
// −20.6 % Track-RSME in the experiment).
TEST(SyncLoop, CosineSyncBeatsPd) {
  RunOptions o;
  o.ctl = Ctl::Pd;
  const RunResult pd = run(o, "PD");
  o.ctl = Ctl::Sync;
  const RunResult sync = run(o, "sync (default: sat K_N 10 phi 100)");
  o.params = {{"K_N", "0"}};
  const RunResult sync0 = run(o, "sync K_N 0");
  std::printf("paper000: sync vs PD: Sync-RSME %+.1f %%, Track-RSME %+.1f %%\n",
              100 * (sync.sync_rsme / pd.sync_rsme - 1), 100 * (sync.track_rsme / pd.track_rsme - 1));
  EXPECT_LT(sync.sync_rsme, pd.sync_rsme);
  EXPECT_LT(sync.track_rsme, pd.track_rsme);
  EXPECT_LT(sync0.sync_rsme, pd.sync_rsme);
  EXPECT_LT(sync0.track_rsme, pd.track_rsme);
  EXPECT_EQ(sync.sat_fraction, 0.0);
  EXPECT_EQ(pd.sat_fraction, 0.0);
}

// The one-scan delay at 1 ms barely matters: T is lower triangular, so the
// predictor never sits inside a feedback loop, and one scan of a smooth error
// changes E by κ/(k−1)·ė·T_s, far below the errors themselves.
TEST(SyncLoop, CompensationChangesLittleAt1ms) {
  RunOptions o;
  const RunResult with = run(o, "sync, delay 1, compensation");
  o.params = {{"compensation", "FALSE"}};
  const RunResult without = run(o, "sync, delay 1, no compensation");
  o.params = {{"rx_delay", "0"}};
  const RunResult nodelay = run(o, "sync, no delay");
  const double dt = std::abs(with.track_rsme / without.track_rsme - 1);
  const double ds = std::abs(with.sync_rsme / without.sync_rsme - 1);
  std::printf("paper000: compensation on vs off: Track %.5f %%, Sync %.5f %%; on vs no delay: Sync %.5f %%\n", 100 * dt,
              100 * ds, 100 * std::abs(with.sync_rsme / nodelay.sync_rsme - 1));
  EXPECT_NE(with.sync_rsme, without.sync_rsme) << "the compensation must act";
  EXPECT_LT(dt, 0.01);
  EXPECT_LT(ds, 0.01);
  // With compensation the delayed loop is at least as close to the undelayed one.
  EXPECT_LE(std::abs(with.sync_rsme - nodelay.sync_rsme), std::abs(without.sync_rsme - nodelay.sync_rsme));
}

// K_N = 10 PWM with sign() switches at the Nyquist rate; the boundary layer does not.
TEST(SyncLoop, SignChattersBoundaryLayerDoesNot) {
  RunOptions o;
  const RunResult sat = run(o, "sync sat K_N 10 phi 100");
  o.params = {{"K_N", "0"}};
  const RunResult none = run(o, "sync K_N 0");
  o.params = {{"robust", "0"}, {"out_min", "-1e9"}, {"out_max", "1e9"}};
  const RunResult sign = run(o, "sync sign K_N 10, unlimited");
  // A layer too thin adds a derivative gain K_N/φ the own loop cannot take:
  // m + (1+κ)(K_D + K_N/φ) must stay below ≈ 2τ_3/(k_3 T_s) = 1.53 (φ > 18 rad/s).
  o.params = {{"phi", "10"}, {"out_min", "-1e9"}, {"out_max", "1e9"}};
  const RunResult thin = run(o, "sync sat K_N 10 phi 10, unlimited");
  o.params = {{"robust", "0"}};
  const RunResult sign_lim = run(o, "sync sign K_N 10, limit +-1 PWM");
  // Eq. (9) with Δ_H, Δ_C the true model mismatch bounds (H = τ/k, C = 1/k).
  const PaperGains pg;
  double dH = 0, dC = 0;
  for (const auto& ax : paper_plant(1e-3)) {
    dH = std::max(dH, std::abs(pg.K_H - ax.tau_c / ax.k));
    dC = std::max(dC, std::abs(pg.K_C - 1 / ax.k));
  }
  o.params = {{"robust", "1"}, {"Delta_H", std::to_string(dH)}, {"Delta_C", std::to_string(dC)}};
  const RunResult eq9 = run(o, "sync eq9 K_N(t), limit +-1 PWM");
  std::printf("paper000: command RMS sign/none %.1fx, sat/none %.4fx; eq9 Delta_H %.6f Delta_C %.6f\n",
              sign.tau_rms / none.tau_rms, sat.tau_rms / none.tau_rms, dH, dC);
  EXPECT_GT(sign.tau_rms, 10 * none.tau_rms);
  EXPECT_GT(sign.dtau_rms, 1.0);  // PWM per scan: switching every scan
  EXPECT_LT(sat.tau_rms, 1.01 * none.tau_rms);
  EXPECT_LT(sat.dtau_rms, 1e-2);
  EXPECT_GT(sign_lim.sat_fraction, 0.5);
  EXPECT_GT(sign_lim.track_rsme, 5 * sat.track_rsme);  // saturated chatter destroys tracking
  EXPECT_EQ(sat.sat_fraction, 0.0);
  EXPECT_GT(eq9.dtau_rms, 10 * sat.dtau_rms);  // eq. (9) still switches, at a smaller amplitude
  EXPECT_GT(thin.tau_rms, 10 * sat.tau_rms);   // unstable inside the layer: a limit cycle of amplitude K_N
}

// Lost messages of the preceding axes (Bernoulli, seeded) are filled by the
// estimator; on this smooth motion the RSMEs hardly move.
TEST(SyncLoop, LossIsFilledByTheEstimator) {
  RunOptions o;
  const RunResult clean = run(o, "sync, no loss");
  std::mt19937 rng(2017);
  std::bernoulli_distribution b(0.2);
  std::vector<std::array<bool, 4>> lost(static_cast<std::size_t>(o.samples));
  for (auto& row : lost)
    for (auto& l : row) l = b(rng);
  o.lost = [&](int j, int i) { return lost[static_cast<std::size_t>(j)][static_cast<std::size_t>(i)]; };
  const RunResult lossy = run(o, "sync, 20 % loss");
  std::printf("paper000: 20 %% loss: %u samples estimated\n", lossy.estimated);
  EXPECT_GT(lossy.estimated, 6000u);  // ≈ 0.2 × 6283 × (0 + 1 + 2 + 3) preceding elements
  EXPECT_LT(std::abs(lossy.sync_rsme / clean.sync_rsme - 1), 0.01);
  EXPECT_LT(std::abs(lossy.track_rsme / clean.track_rsme - 1), 0.01);
}

// The same loop as a project (tests/motion/projects/paper000_loop): the blocks loaded from
// YAML, the array pins wired to the simulated table and ring drivers (their
// own exact ZOH and one-frame delay), metrics by `syncplc sim --metrics`.
// Independent plant and network code, same numbers.
double json_number(const std::string& json, const std::string& key) {
  const auto i = json.find("\"" + key + "\":");
  if (i == std::string::npos) return -1;
  return std::stod(json.substr(i + key.size() + 3));
}

TEST(SyncLoop, ProjectOnTheSimulatedTableMatchesTheTestLoop) {
  for (const auto& [file, ctl] : {std::pair{"sync.yaml", Ctl::Sync}, std::pair{"pd.yaml", Ctl::Pd}}) {
    const std::string out = ::testing::TempDir() + "paper000_" + file + ".json";
    const std::string cmd = std::string(SYNCPLC_BINARY) + " sim -q -d 6.283s --metrics " + out + " " +
                            SYNCPLC_SOURCE_DIR + "/tests/motion/projects/paper000_loop/" + file + " > /dev/null 2>&1";
    ASSERT_EQ(std::system(cmd.c_str()), 0) << cmd;
    std::ifstream in(out);
    std::stringstream ss;
    ss << in.rdbuf();
    const std::string json = ss.str();
    ASSERT_EQ(json_number(json, "samples"), 6283) << json.substr(0, 300);
    RunOptions o;
    o.ctl = ctl;
    const RunResult r = run_paper_loop(o);
    const double track = json_number(json, "track_rsme"), sync = json_number(json, "sync_rsme");
    std::printf("paper000: project %-9s Track-RSME %.9f Sync-RSME %.9f (test loop %.9f %.9f)\n", file, track, sync,
                r.track_rsme, r.sync_rsme);
    EXPECT_NEAR(track, r.track_rsme, 1e-6 * r.track_rsme) << file;
    EXPECT_NEAR(sync, r.sync_rsme, 1e-6 * r.sync_rsme) << file;
  }
}

}  // namespace
}  // namespace syncplc::motiontest
