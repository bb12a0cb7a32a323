// NURBS_PATH through BlockHarness: the exact circle at constant feed (radius
// and curvature at every sample, feed error within the stated bound, the end
// exactly on the last point), outputs against finite differences of the
// position, feed override and hold, restart, and bad parameters rejected
// with their messages (at load, or at Execute for the latched arrays).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <numbers>
#include <string>
#include <vector>

#include "fblocks/contour/nurbs_math.hpp"
#include "fblocks/library.hpp"
#include "runtime/core/block_harness.hpp"
#include "tests/contour/nurbs_test_curves.hpp"

namespace syncplc::nurbs::test_nurbs_block {
namespace {

using nurbs_test::CurveData;
constexpr std::int64_t kMs = 1'000'000;

std::string errors_of(const BlockHarness& h) {
  std::string s;
  for (const auto& e : h.errors()) s += e + "\n";
  return s;
}

BlockHarness make_block(const CurveData& c, double feed, std::int64_t period_ns, int axes = 2) {
  BlockHarness::Options o;
  o.params = {{"points", std::to_string(c.points())},
              {"order", std::to_string(c.order)},
              {"knots", std::to_string(c.knots.size())},
              {"axes", std::to_string(axes)},
              {"feed", nurbs_test::number(feed)}};
  o.period_ns = period_ns;
  BlockHarness h(builtin_blocks(), "NURBS_PATH", o);
  if (!h.ok()) return h;
  for (int i = 0; i < c.points(); ++i) {
    const auto j = static_cast<std::size_t>(i);
    const auto e = static_cast<std::uint32_t>(i);
    h.set<double>("px", e, c.x[j]);
    h.set<double>("py", e, c.y[j]);
    h.set<double>("pz", e, c.z[j]);
    h.set<double>("w", e, c.w[j]);
  }
  for (std::size_t i = 0; i < c.knots.size(); ++i) h.set<double>("knot", static_cast<std::uint32_t>(i), c.knots[i]);
  h.set<double>("override", 1.0);
  return h;
}

NurbsCurve curve_of(const CurveData& c) {
  NurbsCurve curve(c.points(), c.order);
  for (int i = 0; i < c.points(); ++i) {
    const auto j = static_cast<std::size_t>(i);
    curve.px()[i] = c.x[j], curve.py()[i] = c.y[j], curve.pz()[i] = c.z[j], curve.weights()[i] = c.w[j];
  }
  for (std::size_t i = 0; i < c.knots.size(); ++i) curve.knots()[i] = c.knots[i];
  return curve;
}

// Largest |stated feed error| over the curve for a path step ds.
double stated_bound(const CurveData& c, double ds) {
  const NurbsCurve curve = curve_of(c);
  double worst = 0;
  for (int i = 0; i <= 20000; ++i) {
    Vec3 d[4];
    curve.derivatives(curve.u_begin() + (curve.u_end() - curve.u_begin()) * i / 20000, 3, d);
    worst = std::max(worst, std::abs(nurbs_predicted_feed_error(ds, d[1], d[2], d[3])));
  }
  return worst;
}

struct Sample {
  double x, y, z, vx, vy, vz, ax, ay, az, k, u, fe;
  bool done, busy;
};

Sample read(BlockHarness& h) {
  return {h.get<double>("x"), h.get<double>("y"), h.get<double>("z"), h.get<double>("vx"), h.get<double>("vy"),
          h.get<double>("vz"), h.get<double>("ax"), h.get<double>("ay"), h.get<double>("az"),
          h.get<double>("curvature"), h.get<double>("u"), h.get<double>("feed_error"), h.get<bool>("Done"),
          h.get<bool>("Busy")};
}

// Runs from the rising edge of Execute until Done (at most `limit` scans).
std::vector<Sample> run(BlockHarness& h, int limit) {
  std::vector<Sample> out;
  h.set<bool>("Execute", true);
  for (int i = 0; i < limit; ++i) {
    h.scan();
    out.push_back(read(h));
    if (out.back().done) break;
  }
  return out;
}

// The paper 002 circle test's size and feed (R = 320 mm, 2500 mm/min, 4 ms)
// on the exact NURBS circle.
TEST(NurbsPath, CircleAtConstantFeed) {
  const double R = 0.32, feed = 2.5 / 60, T = 0.004;
  const CurveData c = nurbs_test::circle(R);
  BlockHarness h = make_block(c, feed, 4 * kMs);
  ASSERT_TRUE(h.ok()) << errors_of(h);
  const auto s = run(h, 20000);
  ASSERT_TRUE(s.back().done);
  const double ds = feed * T;
  const double bound = stated_bound(c, ds);
  // Steps: the path length over ds, the last one shortened (scan 0 is the start point).
  const double steps = 2 * std::numbers::pi * R / ds;
  EXPECT_EQ(static_cast<double>(s.size() - 1), std::ceil(steps * (1 + 1e-9)) ) << steps;
  double worst_fe = 0;
  for (std::size_t i = 0; i < s.size(); ++i) {
    EXPECT_NEAR(std::hypot(s[i].x, s[i].y), R, 8 * std::numeric_limits<double>::epsilon() * R) << "scan " << i;
    EXPECT_NEAR(s[i].k, 1 / R, 1e-12 / R) << "scan " << i;
    if (i + 1 < s.size()) {
      EXPECT_TRUE(s[i].busy);
      EXPECT_NEAR(std::hypot(s[i].vx, s[i].vy), feed, 1e-15);
      EXPECT_NEAR(std::hypot(s[i].ax, s[i].ay), feed * feed / R, 1e-12 * feed * feed / R);
      worst_fe = std::max(worst_fe, std::abs(s[i].fe));
    }
  }
  // The chord of a circle is shorter than its arc by ds^2/(24 R^2): the floor.
  EXPECT_LE(worst_fe, 1.01 * bound + 1e-13);
  EXPECT_GE(worst_fe, ds * ds / (24 * R * R) * 0.99);
  // Ends exactly on the last control point, at rest.
  EXPECT_EQ(s.back().x, c.x.back());
  EXPECT_EQ(s.back().y, c.y.back());
  EXPECT_EQ(s.back().vx, 0.0);
  EXPECT_EQ(s.back().vy, 0.0);
  EXPECT_FALSE(s.back().busy);
  EXPECT_EQ(s.back().u, 1.0);
  std::printf("circle R %.3f m, %.0f mm/min, T %.0f ms: %zu scans, |feed error| max %.3e (stated %.3e)\n", R,
              feed * 60000, T * 1000, s.size(), worst_fe, bound);
  // Done stays while Execute is TRUE, and falls one scan after Execute falls.
  h.scan();
  EXPECT_TRUE(h.get<bool>("Done"));
  h.set<bool>("Execute", false);
  h.scan();
  EXPECT_FALSE(h.get<bool>("Done"));
  EXPECT_EQ(h.get<double>("x"), c.x.back());
}

// Velocity and acceleration outputs against central differences of the
// position outputs, on a 3-axis free-form cubic far from arc-length
// parametrization; the feed error within the stated bound along it.
TEST(NurbsPath, OutputsMatchFiniteDifferencesOfPosition) {
  const double feed = 0.05, T = 0.001;
  const CurveData c = nurbs_test::freeform();
  BlockHarness h = make_block(c, feed, kMs, 3);
  ASSERT_TRUE(h.ok()) << errors_of(h);
  const auto s = run(h, 100000);
  ASSERT_TRUE(s.back().done);
  ASSERT_GT(s.size(), 1000u);
  double amax = 0;
  for (const auto& e : s) amax = std::max(amax, std::sqrt(e.ax * e.ax + e.ay * e.ay + e.az * e.az));
  const double bound = stated_bound(c, feed * T);
  // Central differences err by T^2/6 times the jerk (velocity) and T^2/12
  // times the snap (acceleration), estimated from the acceleration outputs;
  // the chord's feed error adds |eps| V to the velocity's.
  int checked = 0;
  for (std::size_t i = 2; i + 3 < s.size(); ++i) {
    bool near_knot = false;  // the third derivative of a cubic jumps at a knot
    for (double kn : c.knots) near_knot |= std::abs(s[i].u - kn) < 0.01;
    if (near_knot) continue;
    const double v_fd[3] = {(s[i + 1].x - s[i - 1].x) / (2 * T), (s[i + 1].y - s[i - 1].y) / (2 * T),
                            (s[i + 1].z - s[i - 1].z) / (2 * T)};
    const double a_fd[3] = {(s[i + 1].x - 2 * s[i].x + s[i - 1].x) / (T * T),
                            (s[i + 1].y - 2 * s[i].y + s[i - 1].y) / (T * T),
                            (s[i + 1].z - 2 * s[i].z + s[i - 1].z) / (T * T)};
    const double v_out[3] = {s[i].vx, s[i].vy, s[i].vz};
    const double a_out[3] = {s[i].ax, s[i].ay, s[i].az};
    const double a_next[3] = {s[i + 1].ax, s[i + 1].ay, s[i + 1].az};
    const double a_prev[3] = {s[i - 1].ax, s[i - 1].ay, s[i - 1].az};
    for (int d = 0; d < 3; ++d) {
      const double jerk = std::abs(a_next[d] - a_prev[d]) / (2 * T);
      const double snap = std::abs(a_next[d] - 2 * a_out[d] + a_prev[d]) / (T * T);
      EXPECT_NEAR(v_out[d], v_fd[d], 2 * (T * T / 6 * jerk + bound * feed) + 1e-12) << "scan " << i << " axis " << d;
      EXPECT_NEAR(a_out[d], a_fd[d], 2 * T * T / 12 * snap + 1e-3 * amax) << "scan " << i << " axis " << d;
    }
    EXPECT_NEAR(std::sqrt(s[i].vx * s[i].vx + s[i].vy * s[i].vy + s[i].vz * s[i].vz), feed, 1e-14);
    EXPECT_LE(std::abs(s[i].fe), 1.01 * bound + 1e-13) << i;
    ++checked;
  }
  EXPECT_GT(checked, 500);
  EXPECT_EQ(s.back().x, c.x.back());
  EXPECT_EQ(s.back().y, c.y.back());
  EXPECT_EQ(s.back().z, c.z.back());
}

TEST(NurbsPath, OverrideScalesTheFeedAndZeroHolds) {
  const CurveData c = nurbs_test::circle(0.1);
  BlockHarness full = make_block(c, 0.1, kMs);
  BlockHarness half = make_block(c, 0.1, kMs);
  ASSERT_TRUE(full.ok() && half.ok());
  half.set<double>("override", 0.5);
  const auto a = run(full, 100000), b = run(half, 100000);
  ASSERT_TRUE(a.back().done && b.back().done);
  EXPECT_NEAR(static_cast<double>(b.size() - 1), 2.0 * static_cast<double>(a.size() - 1), 2.0);
  EXPECT_NEAR(std::hypot(b[10].vx, b[10].vy), 0.05, 1e-15);
  // Feed hold: override 0 stops the parameter; 1 resumes.
  BlockHarness hold = make_block(c, 0.1, kMs);
  hold.set<bool>("Execute", true);
  hold.scans(100);
  const double u = hold.get<double>("u");
  hold.set<double>("override", 0.0);
  hold.scans(50);
  EXPECT_EQ(hold.get<double>("u"), u);
  EXPECT_TRUE(hold.get<bool>("Busy"));
  EXPECT_EQ(hold.get<double>("vx"), 0.0);
  hold.set<double>("override", 1.0);
  hold.scan();
  EXPECT_GT(hold.get<double>("u"), u);
}

TEST(NurbsPath, FeedIsTunableWhileRunning) {
  const CurveData c = nurbs_test::circle(0.1);
  BlockHarness h = make_block(c, 0.1, kMs);
  h.set<bool>("Execute", true);
  h.scans(10);
  EXPECT_TRUE(h.block().tune(4, 0.2));
  EXPECT_FALSE(h.block().tune(4, 0.0));
  h.scan();
  EXPECT_NEAR(std::hypot(h.get<double>("vx"), h.get<double>("vy")), 0.2, 1e-15);
}

TEST(NurbsPath, RestartRunsThePathAgain) {
  const CurveData c = nurbs_test::circle(0.05);
  BlockHarness h = make_block(c, 0.1, kMs);
  const auto first = run(h, 100000);
  ASSERT_TRUE(first.back().done);
  h.set<bool>("Execute", false);
  h.scan();
  const auto second = run(h, 100000);
  ASSERT_EQ(second.size(), first.size());
  for (std::size_t i = 0; i < first.size(); ++i) EXPECT_EQ(second[i].x, first[i].x);
}

TEST(NurbsPath, BadParametersAreRejectedAtLoad) {
  auto load = [](std::map<std::string, std::string> p) {
    BlockHarness::Options o;
    o.params = std::move(p);
    BlockHarness h(builtin_blocks(), "NURBS_PATH", o);
    return errors_of(h);
  };
  EXPECT_NE(load({{"points", "9"}, {"order", "3"}, {"knots", "11"}, {"feed", "0.1"}})
                .find("knots must be points + order = 12 (is 11)"),
            std::string::npos);
  EXPECT_NE(load({{"points", "3"}, {"order", "4"}, {"knots", "7"}, {"feed", "0.1"}})
                .find("points (3) must be at least the order k (4)"),
            std::string::npos);
  EXPECT_NE(load({{"points", "9"}, {"order", "3"}, {"knots", "12"}}).find("feed"), std::string::npos);
  const std::string order9 = load({{"points", "9"}, {"order", "9"}, {"knots", "18"}, {"feed", "0.1"}});
  EXPECT_NE(order9.find("order"), std::string::npos) << order9;
  const std::string axes4 = load({{"points", "9"}, {"order", "3"}, {"knots", "12"}, {"feed", "0.1"}, {"axes", "4"}});
  EXPECT_NE(axes4.find("axes"), std::string::npos) << axes4;
  EXPECT_EQ(load({{"points", "9"}, {"order", "3"}, {"knots", "12"}, {"feed", "0.1"}}), "");
}

// The arrays are inputs, latched at Execute: a bad curve sets Error and
// ErrorID, raises a BlockFault naming the element, and does not move.
TEST(NurbsPath, BadCurveIsRejectedAtExecute) {
  CurveData c = nurbs_test::circle(0.1);
  c.knots[5] = 0.1;  // 0.25, 0.25, 0.1: decreases at element 6 (1-based)
  BlockHarness h = make_block(c, 0.1, kMs);
  ASSERT_TRUE(h.ok());
  h.set<bool>("Execute", true);
  h.scan();
  EXPECT_TRUE(h.get<bool>("Error"));
  EXPECT_EQ(h.get<std::uint16_t>("ErrorID"), 1);
  EXPECT_FALSE(h.get<bool>("Busy"));
  ASSERT_EQ(h.events().size(), 1u);
  EXPECT_STREQ(h.events()[0].message, nurbs_fault_text(NurbsFault::kKnotsDecrease));
  EXPECT_EQ(h.events()[0].value, 6.0);
  h.scans(3);
  EXPECT_TRUE(h.get<bool>("Error"));
  EXPECT_EQ(h.get<double>("u"), 0.0);
  h.set<bool>("Execute", false);
  h.scan();
  EXPECT_FALSE(h.get<bool>("Error"));
  // Fixed and restarted: runs.
  h.set<double>("knot", 5, 0.5);
  h.set<double>("w", 2, -1.0);
  h.set<bool>("Execute", true);
  h.scan();
  EXPECT_EQ(h.get<std::uint16_t>("ErrorID"), 2);
  EXPECT_EQ(h.events().back().value, 3.0);
  h.set<double>("w", 2, 1.0);
  h.set<bool>("Execute", false);
  h.scan();
  h.set<bool>("Execute", true);
  h.scan();
  EXPECT_FALSE(h.get<bool>("Error"));
  EXPECT_TRUE(h.get<bool>("Busy"));
}

}  // namespace
}  // namespace syncplc::nurbs::test_nurbs_block
