// COSINE_TRAJECTORY (paper 000 Fig. 4), CIRCLE (paper 002) and
// STEP_RAMP_SEQUENCE (paper 004 Figs. 5 and 10) through BlockHarness:
// closed-form values, derivatives checked by finite differences, timing,
// enable/restart, seeded reproducibility, scripted segments.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <functional>
#include <map>
#include <numbers>
#include <string>
#include <vector>

#include "fblocks/library.hpp"
#include "runtime/core/block_harness.hpp"

namespace syncplc::motion {
namespace {

constexpr double kPi = std::numbers::pi;
constexpr std::int64_t kMs = 1'000'000;

BlockHarness make(const char* type, std::map<std::string, std::string> params, std::int64_t period_ns = kMs,
                  std::uint64_t seed = 1) {
  BlockHarness::Options o;
  o.params = std::move(params);
  o.period_ns = period_ns;
  o.seed = seed;
  return BlockHarness(builtin_blocks(), type, o);
}

std::string harness_errors(const BlockHarness& h) {
  std::string s;
  for (const auto& e : h.errors()) s += e + "\n";
  return s;
}
#define ASSERT_OK(h) ASSERT_TRUE((h).ok()) << harness_errors(h)

// Samples of named outputs, one per scan.
struct Trace {
  std::map<std::string, std::vector<double>> v;
  std::vector<double> t;
  void record(BlockHarness& h, const std::vector<std::string>& pins) {
    t.push_back(static_cast<double>(h.now_ns()) * 1e-9);
    h.scan();
    for (const auto& p : pins) v[p].push_back(h.get<double>(p));
  }
};

// Central differences of `x` against `dx` at interior samples k (skipping
// those where skip(k)); returns the largest mismatch.
double fd_mismatch(const std::vector<double>& x, const std::vector<double>& dx, double T,
                   const std::function<bool(std::size_t)>& skip = nullptr) {
  double worst = 0;
  for (std::size_t k = 1; k + 1 < x.size(); ++k) {
    if (skip && skip(k)) continue;
    worst = std::max(worst, std::abs((x[k + 1] - x[k - 1]) / (2 * T) - dx[k]));
  }
  return worst;
}

// ---- COSINE_TRAJECTORY -----------------------------------------------------

TEST(CosineTrajectory, AmplitudeAndOmegaAreRequired) {
  auto h = make("COSINE_TRAJECTORY", {{"omega", "1"}});
  EXPECT_FALSE(h.ok());
  auto g = make("COSINE_TRAJECTORY", {{"amplitude", "1"}, {"omega", "1"}});
  EXPECT_TRUE(g.ok()) << harness_errors(g);
  EXPECT_FALSE(make("COSINE_TRAJECTORY", {{"amplitude", "1"}, {"omega", "0"}}).ok());
  EXPECT_FALSE(make("COSINE_TRAJECTORY", {{"amplitude", "1"}, {"omega", "1"}, {"cycles", "-1"}}).ok());
}

// Paper 000: A = 4 pi rad, w = 1 rad/s; peak speed A w = 4 pi rad/s = 753.98 rad/min.
TEST(CosineTrajectory, PaperProfileAndPeakSpeed) {
  const double A = 4 * kPi, T = 1e-3;
  auto h = make("COSINE_TRAJECTORY", {{"amplitude", "12.566370614359172"}, {"omega", "1"}});
  ASSERT_OK(h);
  Trace tr;
  const int n = static_cast<int>(2 * kPi / T) + 200;
  for (int k = 0; k < n; ++k) tr.record(h, {"x", "v", "a"});
  double vmax = 0;
  for (std::size_t k = 0; k < tr.t.size(); ++k) {
    const double t = tr.t[k];
    if (t < 2 * kPi) {
      EXPECT_NEAR(tr.v["x"][k], A * (1 - std::cos(t)), 1e-12) << k;
      EXPECT_NEAR(tr.v["v"][k], A * std::sin(t), 1e-12) << k;
      EXPECT_NEAR(tr.v["a"][k], A * std::cos(t), 1e-12) << k;
    }
    vmax = std::max(vmax, tr.v["v"][k]);
  }
  EXPECT_NEAR(vmax * 60, 753.98, 0.005);  // rad/min
  EXPECT_NEAR(A * 60, 753.98, 0.005);
  // Derivatives: central differences within the motion (A w^3 T^2 / 6 truncation).
  const auto edge = [&](std::size_t k) { return tr.t[k + 1] >= 2 * kPi; };
  EXPECT_LT(fd_mismatch(tr.v["x"], tr.v["v"], T, edge), A * T * T / 6 * 1.01 + 1e-9);
  EXPECT_LT(fd_mismatch(tr.v["v"], tr.v["a"], T, edge), A * T * T / 6 * 1.01 + 1e-9);
  // After one period: holds still at the start point, done.
  EXPECT_TRUE(h.get<bool>("done"));
  EXPECT_NEAR(h.get<double>("x"), 0.0, 1e-12);
  EXPECT_EQ(h.get<double>("v"), 0.0);
  EXPECT_EQ(h.get<double>("a"), 0.0);
}

TEST(CosineTrajectory, DelayOffsetCyclesAndEnable) {
  auto h = make("COSINE_TRAJECTORY",
                {{"amplitude", "2"}, {"omega", "3.141592653589793"}, {"cycles", "1.5"}, {"delay", "0.25"},
                 {"offset", "10"}});
  ASSERT_OK(h);
  h.set<bool>("enable", false);
  h.scans(100);
  EXPECT_EQ(h.get<double>("x"), 10.0);
  EXPECT_FALSE(h.get<bool>("done"));
  h.set<bool>("enable", true);  // starts at this scan: t = 0
  const std::int64_t t0 = h.now_ns();
  h.scans(251);  // last scan at t = 0.25 s: still resting
  EXPECT_EQ(h.get<double>("x"), 10.0);
  EXPECT_EQ(h.get<double>("v"), 0.0);
  h.scan();  // t = 0.251: tau = 1 ms
  EXPECT_NEAR(h.get<double>("x"), 10 + 2 * (1 - std::cos(kPi * 1e-3)), 1e-12);
  h.set_now_ns(t0 + 1'250'000'000);  // tau = 1 s: half a period, x = offset + 2A
  h.scan();
  EXPECT_NEAR(h.get<double>("x"), 14.0, 1e-12);
  EXPECT_NEAR(h.get<double>("a"), -2 * kPi * kPi, 1e-9);
  h.set_now_ns(t0 + 3'300'000'000);  // tau past 3 s = 1.5 periods: done, holds x(3 pi) = 14
  h.scan();
  EXPECT_TRUE(h.get<bool>("done"));
  EXPECT_NEAR(h.get<double>("x"), 14.0, 1e-12);
  EXPECT_EQ(h.get<double>("v"), 0.0);
  h.set<bool>("enable", false);  // reset to the start
  h.scan();
  EXPECT_EQ(h.get<double>("x"), 10.0);
  EXPECT_FALSE(h.get<bool>("done"));
}

// Time comes from the scan's planned release, not a count of scans.
TEST(CosineTrajectory, IrregularScansFollowTime) {
  auto h = make("COSINE_TRAJECTORY", {{"amplitude", "1"}, {"omega", "2"}, {"cycles", "0"}});
  ASSERT_OK(h);
  const std::int64_t times[] = {0, 3 * kMs, 4 * kMs, 50 * kMs, 51 * kMs, 9000 * kMs};
  for (std::int64_t t : times) {
    h.set_now_ns(t);
    h.scan();
    const double s = static_cast<double>(t) * 1e-9;
    EXPECT_NEAR(h.get<double>("x"), 1 - std::cos(2 * s), 1e-12);
    EXPECT_NEAR(h.get<double>("v"), 2 * std::sin(2 * s), 1e-12);
    EXPECT_FALSE(h.get<bool>("done"));  // cycles 0: endless
  }
}

// ---- CIRCLE -------------------------------------------------------------------

constexpr double kFeed2500 = 2500.0 / 60 / 1000;  // m/s

TEST(Circle, RadiusFeedDirectionAndDerivatives) {
  for (const char* cw : {"FALSE", "TRUE"}) {
    auto h = make("CIRCLE", {{"radius", "0.32"}, {"feed", "0.16666666666666666"}, {"cx", "0.1"}, {"cy", "-0.2"},
                             {"start_angle", "0.5"}, {"clockwise", cw}, {"ramp_time", "0.3"}});
    ASSERT_OK(h);
    const double T = 1e-3, R = 0.32, F = 10000.0 / 60 / 1000;
    Trace tr;
    const int n = static_cast<int>((2 * kPi * R / F + 0.3) / T) + 50;
    for (int k = 0; k < n; ++k) tr.record(h, {"x", "y", "vx", "vy", "ax", "ay", "s"});
    const double dir = std::string(cw) == "TRUE" ? -1 : 1;
    double vmax = 0;
    for (std::size_t k = 0; k < tr.t.size(); ++k) {
      const double dx = tr.v["x"][k] - 0.1, dy = tr.v["y"][k] + 0.2;
      EXPECT_NEAR(std::hypot(dx, dy), R, 1e-12);
      const double speed = std::hypot(tr.v["vx"][k], tr.v["vy"][k]);
      vmax = std::max(vmax, speed);
      if (speed > 1e-9) {
        EXPECT_GT(dir * (dx * tr.v["vy"][k] - dy * tr.v["vx"][k]), 0) << k;  // anticlockwise: +
      }
      if (tr.t[k] > 0.3 && tr.t[k] < 2 * kPi * R / F) {
        EXPECT_NEAR(speed, F, 1e-12) << k;
      }
    }
    EXPECT_NEAR(vmax, F, 1e-12);
    EXPECT_NEAR(tr.v["x"][0], 0.1 + R * std::cos(0.5), 1e-15);
    // Consistent derivatives, ramps included: the truncation of a central
    // difference is (third derivative) T^2 / 6; the jerk of the ramp is
    // F pi^2 / (2 Ta^2) = 9.1 m/s^3, so 1.5e-6 m/s for x -> v. For v -> a,
    // skip the samples whose stencil straddles a ramp junction (the jerk
    // steps there, which costs about jump T / 4).
    const double D = 2 * kPi * R / F + 0.3;
    const auto junction = [&](std::size_t k) {
      for (double j : {0.3, D - 0.3, D})
        if (tr.t[k - 1] < j && j < tr.t[k + 1]) return true;
      return false;
    };
    EXPECT_LT(fd_mismatch(tr.v["x"], tr.v["vx"], T), 2e-6);
    EXPECT_LT(fd_mismatch(tr.v["y"], tr.v["vy"], T), 2e-6);
    EXPECT_LT(fd_mismatch(tr.v["vx"], tr.v["ax"], T, junction), 3e-5);
    EXPECT_LT(fd_mismatch(tr.v["vy"], tr.v["ay"], T, junction), 3e-5);
    // Ends at rest back at the start point.
    EXPECT_TRUE(h.get<bool>("done"));
    EXPECT_NEAR(h.get<double>("x"), 0.1 + R * std::cos(0.5), 1e-12);
    EXPECT_NEAR(h.get<double>("s"), 2 * kPi * R, 1e-12);
    EXPECT_EQ(h.get<double>("vx"), 0.0);
  }
}

// Paper 002: R = 320 mm at 2500 mm/min takes 2 pi 320 / 2500 min = 48.255 s;
// the paper's 48.656 s (Ts 4 ms) and 12.164 s (10000 mm/min, Ts 1 ms) are
// both 12164 periods, what a start/stop ramp of 100 periods adds.
int scans_until_done(BlockHarness& h, int limit) {
  for (int k = 0; k < limit; ++k) {
    h.scan();
    if (h.get<bool>("done")) return k;
  }
  return -1;
}

TEST(Circle, PaperExecutionTimes) {
  const double one_turn = 2 * kPi * 0.32 / kFeed2500;
  EXPECT_NEAR(one_turn, 48.2549, 1e-4);
  {
    auto h = make("CIRCLE", {{"radius", "0.32"}, {"feed", "0.041666666666666664"}}, 4 * kMs);
    ASSERT_OK(h);
    EXPECT_EQ(scans_until_done(h, 20000), static_cast<int>(std::ceil(one_turn / 0.004)));  // 12064 periods
  }
  {
    auto h = make("CIRCLE", {{"radius", "0.32"}, {"feed", "0.041666666666666664"}, {"ramp_time", "0.4"}}, 4 * kMs);
    ASSERT_OK(h);
    const int k = scans_until_done(h, 20000);
    EXPECT_EQ(k, 12164);
    EXPECT_NEAR(k * 0.004, 48.656, 1e-9);
  }
  {
    auto h = make("CIRCLE", {{"radius", "0.32"}, {"feed", "0.16666666666666666"}, {"ramp_time", "0.1"}}, kMs);
    ASSERT_OK(h);
    const int k = scans_until_done(h, 20000);
    EXPECT_EQ(k, 12164);
    EXPECT_NEAR(k * 0.001, 12.164, 1e-9);
  }
}

TEST(Circle, BadParametersAreErrors) {
  EXPECT_FALSE(make("CIRCLE", {{"feed", "1"}}).ok());  // radius required
  EXPECT_FALSE(make("CIRCLE", {{"radius", "0"}, {"feed", "1"}}).ok());
  EXPECT_FALSE(make("CIRCLE", {{"radius", "1"}, {"feed", "-1"}}).ok());
  EXPECT_FALSE(make("CIRCLE", {{"radius", "1"}, {"feed", "1"}, {"ramp_time", "-0.1"}}).ok());
  EXPECT_TRUE(make("CIRCLE", {{"radius", "1"}, {"feed", "1"}}).ok());
}

TEST(Circle, ShortPathLowersTheFeedAndEndlessTurns) {
  // A quarter turn of R = 0.1 m (0.157 m) with a 2 s ramp at 1 m/s: too short to
  // cruise; the top speed drops to 0.157/2 m/s and the motion takes 2 Ta.
  auto h = make("CIRCLE", {{"radius", "0.1"}, {"feed", "1"}, {"turns", "0.25"}, {"ramp_time", "2"}});
  ASSERT_OK(h);
  double vmax = 0;
  int done_at = -1;
  for (int k = 0; k < 5000 && done_at < 0; ++k) {
    h.scan();
    vmax = std::max(vmax, std::hypot(h.get<double>("vx"), h.get<double>("vy")));
    if (h.get<bool>("done")) done_at = k;
  }
  EXPECT_NEAR(vmax, 0.25 * 2 * kPi * 0.1 / 2, 1e-6);
  EXPECT_NEAR(done_at, 4000, 1);  // 2 Ta = 4 s
  EXPECT_NEAR(h.get<double>("y"), 0.1, 1e-12);  // a quarter turn anticlockwise from angle 0
  auto e = make("CIRCLE", {{"radius", "1"}, {"feed", "1"}, {"turns", "0"}});
  ASSERT_OK(e);
  e.set_now_ns(1000 * 1'000'000'000LL);  // enable rises at t = 1000 s: starts there
  e.scan();
  e.set_now_ns(1010 * 1'000'000'000LL);
  e.scan();
  EXPECT_FALSE(e.get<bool>("done"));
  EXPECT_NEAR(e.get<double>("s"), 10.0, 1e-9);
  EXPECT_NEAR(e.get<double>("x"), std::cos(10.0), 1e-9);
}

// ---- STEP_RAMP_SEQUENCE -------------------------------------------------------

struct SeqTrace {
  std::vector<double> r, rd;
  std::vector<bool> changed;
  std::vector<std::int32_t> seg;
};

SeqTrace run_seq(BlockHarness& h, int n) {
  SeqTrace s;
  for (int k = 0; k < n; ++k) {
    h.scan();
    s.r.push_back(h.get<double>("r"));
    s.rd.push_back(h.get<double>("r_dot"));
    s.changed.push_back(h.get<bool>("changed"));
    s.seg.push_back(h.get<std::int32_t>("segment"));
  }
  return s;
}

const std::map<std::string, std::string> kRandom = {{"min_hold", "0.1"}, {"max_hold", "0.5"}, {"r_min", "-2"},
                                                     {"r_max", "3"},      {"slope_max", "4"},  {"ramp_probability", "0.5"}};

TEST(StepRampSequence, RandomSegmentsRespectTheirBounds) {
  auto h = make("STEP_RAMP_SEQUENCE", kRandom, kMs, 77);
  ASSERT_OK(h);
  const double T = 1e-3;
  const SeqTrace s = run_seq(h, 60000);
  int changes = 0, ramps = 0, steps = 0, last_change = -1;
  for (std::size_t k = 0; k < s.r.size(); ++k) {
    EXPECT_GE(s.r[k], -2 - 1e-12);
    EXPECT_LE(s.r[k], 3 + 1e-12);
    EXPECT_LE(std::abs(s.rd[k]), 4.0);
    if (s.changed[k]) {
      ++changes;
      EXPECT_EQ(s.seg[k], k == 0 ? 0 : s.seg[k - 1] + 1);
      if (last_change >= 0) {
        const double held = (static_cast<double>(k) - last_change) * T;
        EXPECT_GE(held, 0.1 - T - 1e-9) << k;  // segment boundaries fall between scans
        EXPECT_LE(held, 0.5 + T + 1e-9) << k;  // paper 004: changed at least every half second
      }
      last_change = static_cast<int>(k);
      (s.rd[k] != 0 ? ramps : steps)++;
    } else if (k > 0) {
      EXPECT_EQ(s.seg[k], s.seg[k - 1]);
      EXPECT_NEAR((s.r[k] - s.r[k - 1]) / T, s.rd[k], 1e-8) << k;  // r_dot is the slope of r
      EXPECT_EQ(s.rd[k], s.rd[k - 1]);
    }
  }
  EXPECT_TRUE(s.changed[0]);
  EXPECT_GT(changes, 60000 * T / 0.5);
  EXPECT_LT(changes, 60000 * T / 0.1);
  EXPECT_GT(ramps, changes / 4);  // about half are ramps
  EXPECT_GT(steps, changes / 4);
}

TEST(StepRampSequence, SeededReproducibleAndPerInstance) {
  auto a = make("STEP_RAMP_SEQUENCE", kRandom, kMs, 5);
  auto b = make("STEP_RAMP_SEQUENCE", kRandom, kMs, 5);
  auto c = make("STEP_RAMP_SEQUENCE", kRandom, kMs, 6);
  ASSERT_OK(a);
  const SeqTrace sa = run_seq(a, 5000), sb = run_seq(b, 5000), sc = run_seq(c, 5000);
  EXPECT_EQ(sa.r, sb.r);
  EXPECT_EQ(sa.rd, sb.rd);
  EXPECT_NE(sa.r, sc.r);
  // Segment times are continuous-time: a 10 ms task sees the same reference at
  // its scans as the 1 ms one.
  auto d = make("STEP_RAMP_SEQUENCE", kRandom, 10 * kMs, 5);
  const SeqTrace sd = run_seq(d, 500);
  for (std::size_t k = 0; k < 500; ++k) EXPECT_NEAR(sd.r[k], sa.r[10 * k], 1e-12) << k;
  // A restart (enable FALSE, then TRUE) repeats the sequence.
  a.set<bool>("enable", false);
  a.scan();
  EXPECT_EQ(a.get<double>("r_dot"), 0.0);
  EXPECT_EQ(a.get<double>("r"), sa.r[0]);
  EXPECT_EQ(a.get<std::int32_t>("segment"), -1);
  a.set<bool>("enable", true);
  const SeqTrace again = run_seq(a, 5000);
  EXPECT_EQ(again.r, sa.r);
}

TEST(StepRampSequence, BadRangesAreLoadErrors) {
  auto h = make("STEP_RAMP_SEQUENCE", {{"r_min", "1"}, {"r_max", "0"}});
  EXPECT_FALSE(h.ok());
  auto g = make("STEP_RAMP_SEQUENCE", {{"min_hold", "0.5"}, {"max_hold", "0.2"}});
  EXPECT_FALSE(g.ok());
  EXPECT_FALSE(make("STEP_RAMP_SEQUENCE", {{"min_hold", "0"}}).ok());
  EXPECT_FALSE(make("STEP_RAMP_SEQUENCE", {{"ramp_probability", "1.5"}}).ok());
  EXPECT_TRUE(make("STEP_RAMP_SEQUENCE", {}).ok());
}

TEST(StepRampSequence, ScriptedSegments) {
  auto h = make("STEP_RAMP_SEQUENCE", {{"mode", "1"}, {"segments", "3"}});
  ASSERT_OK(h);
  ASSERT_EQ(h.length("t"), 3u);
  const double t[] = {0.2, 0.5, 1.2}, v[] = {1, 2, -1}, sl[] = {0, 4, -0.5};
  for (std::uint32_t i = 0; i < 3; ++i) {
    h.set<double>("t", i, t[i]);
    h.set<double>("value", i, v[i]);
    h.set<double>("slope", i, sl[i]);
  }
  const SeqTrace s = run_seq(h, 2000);  // scans at 0, 1 ms, ...
  for (std::size_t k = 0; k < s.r.size(); ++k) {
    const double tk = static_cast<double>(k) * 1e-3;
    double r, rd;
    std::int32_t seg;
    if (tk < 0.2 - 1e-12) r = 1, rd = 0, seg = -1;
    else if (tk < 0.5 - 1e-12) r = 1, rd = 0, seg = 0;
    else if (tk < 1.2 - 1e-12) r = 2 + 4 * (tk - 0.5), rd = 4, seg = 1;
    else r = -1 - 0.5 * (tk - 1.2), rd = -0.5, seg = 2;
    EXPECT_NEAR(s.r[k], r, 1e-9) << k;
    EXPECT_EQ(s.rd[k], rd) << k;
    EXPECT_EQ(s.seg[k], seg) << k;
    EXPECT_EQ(s.changed[k], k == 200 || k == 500 || k == 1200) << k;
  }
}

}  // namespace
}  // namespace syncplc::motion
