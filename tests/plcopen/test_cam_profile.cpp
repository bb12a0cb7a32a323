// The cam table's interpolation alone (fblocks/plcopen/cam_profile.hpp):
// linear, the natural cubic spline against a value worked by hand, the
// periodic spline (C1 and C2 across the wrap, a rising cam repeating with
// its rise), single shot outside the table, and the tables refused.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <vector>

#include "fblocks/plcopen/cam_profile.hpp"

namespace syncplc::plcopen {
namespace {

using Interp = CamProfile::Interpolation;

double at(const CamProfile& p, double u, double* ds = nullptr, long long* period = nullptr) {
  double s = 0, d = 0;
  long long k = 0;
  p.eval(u, &s, &d, &k);
  if (ds) *ds = d;
  if (period) *period = k;
  return s;
}

TEST(CamProfile, LinearIsExactAtTheKnotsAndStraightBetween) {
  const double m[] = {0, 1, 3, 4}, s[] = {0, 2, 2, -1};
  CamProfile p(8);
  ASSERT_TRUE(p.load(m, s, 4, Interp::Linear, false));
  for (int i = 0; i < 4; ++i) EXPECT_DOUBLE_EQ(at(p, m[i]), s[i]);
  double ds = 0;
  EXPECT_DOUBLE_EQ(at(p, 0.25, &ds), 0.5);
  EXPECT_DOUBLE_EQ(ds, 2);
  EXPECT_DOUBLE_EQ(at(p, 3.5, &ds), 0.5);
  EXPECT_DOUBLE_EQ(ds, -3);
}

TEST(CamProfile, SingleShotHoldsTheEndValuesOutsideTheTable) {
  const double m[] = {0, 1, 2}, s[] = {1, 2, 5};
  CamProfile p(3);
  ASSERT_TRUE(p.load(m, s, 3, Interp::CubicSpline, false));
  double ds = 0;
  long long k = 0;
  EXPECT_EQ(at(p, -3, &ds, &k), 1);
  EXPECT_EQ(ds, 0);
  EXPECT_EQ(k, -1);
  EXPECT_EQ(at(p, 7, &ds, &k), 5);
  EXPECT_EQ(ds, 0);
  EXPECT_EQ(k, 1);
  at(p, 1.5, &ds, &k);
  EXPECT_EQ(k, 0);
}

// Points (0,0), (1,1), (2,0), second derivative 0 at the ends: the inner one
// is M1 = 6 (-1 - 1) / (2 (1 + 1)) = -3, and at u = 0.5 the spline is
// 0.5 + (0.125 - 0.5) (-3) / 6 = 0.6875; its slope at 0 is 1 - (-3)/6 = 1.5.
TEST(CamProfile, NaturalSplineMatchesAValueWorkedByHand) {
  const double m[] = {0, 1, 2}, s[] = {0, 1, 0};
  CamProfile p(3);
  ASSERT_TRUE(p.load(m, s, 3, Interp::CubicSpline, false));
  EXPECT_NEAR(at(p, 0.5), 0.6875, 1e-15);
  EXPECT_NEAR(at(p, 1.5), 0.6875, 1e-15);
  double ds = 0;
  at(p, 1e-12, &ds);
  EXPECT_NEAR(ds, 1.5, 1e-9);
  // Second derivative 0 at the ends (one-sided difference).
  const double h = 1e-4;
  EXPECT_NEAR((at(p, 2 * h) - 2 * at(p, h) + at(p, 0 + 1e-15)) / (h * h), 0, 1e-3);
}

TEST(CamProfile, PeriodicSplineOfASineIsC2AcrossTheWrapAndClose) {
  const int n = 25;
  std::vector<double> m(n), s(n);
  for (int i = 0; i < n; ++i) {
    m[i] = 2 * std::numbers::pi * i / (n - 1);
    s[i] = std::sin(m[i]);
  }
  s[n - 1] = 0;
  CamProfile p(n);
  ASSERT_TRUE(p.load(m.data(), s.data(), n, Interp::CubicSpline, true));
  for (int i = 0; i < n; ++i) EXPECT_NEAR(at(p, m[i]), s[i], 1e-15);
  for (double u = 0; u < 2 * std::numbers::pi; u += 0.01) EXPECT_NEAR(at(p, u), std::sin(u), 2e-4) << u;
  const double P = 2 * std::numbers::pi, h = 1e-5;
  double d_below = 0, d_above = 0;
  at(p, P - h, &d_below);
  at(p, P + h, &d_above);
  EXPECT_NEAR(d_below, d_above, 1e-8);
  EXPECT_NEAR(d_above, 1, 1e-3);
  // Second derivative: the same from both sides of the wrap.
  const double c_below = (at(p, P) - 2 * at(p, P - h) + at(p, P - 2 * h)) / (h * h);
  const double c_above = (at(p, P + 2 * h) - 2 * at(p, P + h) + at(p, P)) / (h * h);
  EXPECT_NEAR(c_below, c_above, 1e-3);
}

TEST(CamProfile, ARisingPeriodicCamRepeatsWithItsRise) {
  const int n = 13;
  std::vector<double> m(n), s(n);
  for (int i = 0; i < n; ++i) {
    m[i] = 30.0 * i;
    s[i] = m[i] + 10 * std::sin(m[i] * std::numbers::pi / 180);
  }
  for (Interp how : {Interp::Linear, Interp::CubicSpline}) {
    CamProfile p(n);
    ASSERT_TRUE(p.load(m.data(), s.data(), n, how, true));
    long long k = 0;
    EXPECT_NEAR(at(p, 3 * 360 + 47.5, nullptr, &k), 3 * 360 + at(p, 47.5), 1e-9);
    EXPECT_EQ(k, 3);
    EXPECT_NEAR(at(p, -360 + 47.5, nullptr, &k), -360 + at(p, 47.5), 1e-9);
    EXPECT_EQ(k, -1);
    // Continuous in position across the wrap.
    EXPECT_NEAR(at(p, 360 - 1e-9), at(p, 360 + 1e-9), 1e-6);
    EXPECT_NEAR(at(p, 360), 360, 1e-12);
  }
}

TEST(CamProfile, TwoAndThreePointPeriodicTables) {
  const double m2[] = {0, 2}, s2[] = {0, 4};
  CamProfile p(4);
  ASSERT_TRUE(p.load(m2, s2, 2, Interp::CubicSpline, true));
  EXPECT_NEAR(at(p, 5), 10, 1e-12);  // a straight line rising 4 per 2
  const double m3[] = {0, 1, 2}, s3[] = {0, 1, 0};
  ASSERT_TRUE(p.load(m3, s3, 3, Interp::CubicSpline, true));
  EXPECT_NEAR(at(p, 1), 1, 1e-15);
  double d0 = 0, d2 = 0;
  at(p, 1e-9, &d0);
  at(p, 2 - 1e-9, &d2);
  EXPECT_NEAR(d0, d2, 1e-6);
}

TEST(CamProfile, TablesThatAreNotStrictlyIncreasingOrNotFiniteAreRefused) {
  CamProfile p(4);
  const double up[] = {0, 1, 2}, flat[] = {0, 1, 1}, down[] = {0, 2, 1}, s[] = {0, 1, 2};
  const double nan_s[] = {0, std::nan(""), 2};
  EXPECT_TRUE(p.load(up, s, 3, Interp::Linear, false));
  EXPECT_FALSE(p.load(flat, s, 3, Interp::Linear, false));
  EXPECT_FALSE(p.load(down, s, 3, Interp::CubicSpline, true));
  EXPECT_FALSE(p.load(up, nan_s, 3, Interp::Linear, false));
  EXPECT_FALSE(p.load(up, s, 1, Interp::Linear, false));
  const double five[] = {0, 1, 2, 3, 4};
  EXPECT_FALSE(p.load(five, five, 5, Interp::Linear, false));  // beyond the capacity
}

}  // namespace
}  // namespace syncplc::plcopen
