// The contour-error estimate of CCC_2AXIS (fblocks/contour/ccc_math.hpp)
// against the exact distance: on a circle (the circle of curvature is the
// path itself) and on a straight line the estimate is exact; the coupling
// gains are the estimate's gradient, with Koren's signs.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>

#include "fblocks/contour/ccc_math.hpp"

namespace syncplc::contour {
namespace {

constexpr double kPi = std::numbers::pi;

// The frame of a circle of radius R centred at 0, at angle th, travelled at
// speed f (anticlockwise d = 1, clockwise d = -1), as CIRCLE outputs it.
PathFrame circle_frame(double r, double th, double f, double d, double sdd = 0) {
  const double vx = -d * f * std::sin(th), vy = d * f * std::cos(th);
  const double cen = f * f / r;
  const double ax = -cen * std::cos(th) - d * sdd * std::sin(th), ay = -cen * std::sin(th) + d * sdd * std::cos(th);
  PathFrame fr;
  EXPECT_TRUE(path_frame(vx, vy, ax, ay, 1e-12, fr));
  return fr;
}

TEST(CccEstimate, ExactOnACircleAnticlockwiseAndClockwise) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> ang(-kPi, kPi), err(-0.005, 0.005), acc(-2, 2);
  const double r = 0.32;
  for (int i = 0; i < 2000; ++i) {
    const double th = ang(rng), d = i % 2 ? 1.0 : -1.0;
    const PathFrame f = circle_frame(r, th, 0.1667, d, acc(rng));  // tangential acceleration does not change kappa
    EXPECT_NEAR(f.kappa, d / r, 1e-12);
    const double xr = r * std::cos(th), yr = r * std::sin(th);
    const double x = xr + err(rng), y = yr + err(rng);  // the actual point, up to 5 mm off
    const double exact = std::hypot(x, y) - r;           // > 0 outside
    // Right of the direction of travel is outside for anticlockwise, inside for clockwise.
    EXPECT_NEAR(contour_error(f, xr - x, yr - y), d * exact, 1e-15) << "th " << th << " d " << d;
  }
}

TEST(CccEstimate, ExactOnAStraightLine) {
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> ang(-kPi, kPi), err(-0.5, 0.5);
  for (int i = 0; i < 1000; ++i) {
    const double phi = ang(rng);
    PathFrame f;
    ASSERT_TRUE(path_frame(0.2 * std::cos(phi), 0.2 * std::sin(phi), 0.3 * std::cos(phi), 0.3 * std::sin(phi), 1e-12, f));
    EXPECT_NEAR(f.kappa, 0.0, 1e-15);
    const double ex = err(rng), ey = err(rng);  // large errors too: the line's estimate is exact at any size
    // The actual point (-ex, -ey) from the reference; right of travel is along (sin phi, -cos phi).
    const double exact = -ex * std::sin(phi) + ey * std::cos(phi);
    EXPECT_NEAR(contour_error(f, ex, ey), exact, 1e-15);
  }
}

TEST(CccEstimate, StandstillHasNoDirection) {
  PathFrame f;
  f.tx = 0, f.ty = 1, f.kappa = 3;
  EXPECT_FALSE(path_frame(0, 0, 1, 1, 1e-9, f));
  EXPECT_EQ(f.ty, 1);  // unchanged: the caller holds the last frame
  EXPECT_EQ(f.kappa, 3);
}

// Koren's geometry: moving along +x, only y's error is contour error (Cx = 0,
// Cy = 1); moving along +y, only x's, with the sign of the right side (Cx = 1).
TEST(CccEstimate, CouplingGainSignsAndGeometry) {
  PathFrame fx;
  ASSERT_TRUE(path_frame(1, 0, 0, 0, 0, fx));
  auto g = coupling_gains(fx, 0, 0);
  EXPECT_DOUBLE_EQ(g.cx, 0);
  EXPECT_DOUBLE_EQ(g.cy, 1);
  // Actual point above the +x line (left of travel): y error negative, eps negative.
  EXPECT_LT(contour_error(fx, 0, -0.001), 0);
  PathFrame fy;
  ASSERT_TRUE(path_frame(0, 1, 0, 0, 0, fy));
  g = coupling_gains(fy, 0, 0);
  EXPECT_DOUBLE_EQ(g.cx, 1);
  EXPECT_DOUBLE_EQ(g.cy, 0);
  // Moving +y, the right side is +x: an actual point at x = +1 mm has ex = -1 mm, eps = +1 mm = -Cx ex.
  EXPECT_NEAR(contour_error(fy, -0.001, 0), 0.001, 1e-15);
}

// The gains are the gradient of the estimate at e = 0 (-Cx = d eps/d ex,
// Cy = d eps/d ey), and their curvature terms make the Yeh-Hsu form
// eps ~ -Cx ex + Cy ey exact to third order for a purely tangential error,
// where Koren's linear form (kappa = 0) errs by kappa e^2 / 2.
TEST(CccEstimate, CouplingGainsAreTheGradientWithCurvatureCorrection) {
  const double r = 0.32, th = 0.7;
  const PathFrame f = circle_frame(r, th, 0.04, 1);
  const auto g0 = coupling_gains(f, 0, 0);
  const double h = 1e-7;
  EXPECT_NEAR((contour_error(f, h, 0) - contour_error(f, -h, 0)) / (2 * h), -g0.cx, 1e-7);
  EXPECT_NEAR((contour_error(f, 0, h) - contour_error(f, 0, -h)) / (2 * h), g0.cy, 1e-7);
  for (double lag : {0.0005, 0.002, 0.01}) {  // the actual point lags the reference along the tangent
    const double ex = lag * f.tx, ey = lag * f.ty;
    const double exact = contour_error(f, ex, ey);
    EXPECT_NEAR(exact, std::hypot(r * std::cos(th) - ex, r * std::sin(th) - ey) - r, 1e-15);
    const auto g = coupling_gains(f, ex, ey);
    const double yeh_hsu = -g.cx * ex + g.cy * ey;
    const double koren = -f.ty * ex + f.tx * ey;
    EXPECT_NEAR(koren, 0.0, 1e-15);                     // the linear estimate sees no contour error at all
    EXPECT_NEAR(exact, f.kappa * lag * lag / 2, 1e-3 * exact);
    EXPECT_LT(std::abs(yeh_hsu - exact), 1e-2 * std::abs(exact));
  }
}

// Moving the actual point along the corrections (ux, uy) = (-Cx, Cy) u
// lowers |eps|: the distribution pulls the axes back onto the path.
TEST(CccEstimate, CorrectionPointsTowardsThePath) {
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> ang(-kPi, kPi), err(-0.001, 0.001);
  for (int i = 0; i < 500; ++i) {
    const double th = ang(rng);
    const PathFrame f = circle_frame(0.32, th, 0.1, i % 2 ? 1.0 : -1.0);
    const double ex = err(rng), ey = err(rng);
    const double eps = contour_error(f, ex, ey);
    const auto g = coupling_gains(f, ex, ey);
    const double step = 0.1 * eps;  // a positive command moves the axis up: e falls by it
    const double after = contour_error(f, ex - (-g.cx * step), ey - g.cy * step);
    EXPECT_LT(std::abs(after), std::abs(eps)) << i;
  }
}

TEST(CccEstimate, RobustGainFollowsCurvature) {
  EXPECT_DOUBLE_EQ(scheduled_gain(0, 100, 200, 4), 100);
  EXPECT_DOUBLE_EQ(scheduled_gain(1, 100, 200, 4), 125);
  EXPECT_DOUBLE_EQ(scheduled_gain(-2, 100, 200, 4), 150);  // the magnitude K = |kappa|
  EXPECT_DOUBLE_EQ(scheduled_gain(4, 100, 200, 4), 200);
  EXPECT_DOUBLE_EQ(scheduled_gain(40, 100, 200, 4), 200);
  double last = 0;
  for (double k = 0; k < 8; k += 0.25) {
    const double g = scheduled_gain(k, 100, 200, 4);
    EXPECT_GE(g, last);
    last = g;
  }
}

}  // namespace
}  // namespace syncplc::contour
