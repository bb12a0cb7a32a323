// NurbsCurve (fblocks/contour/nurbs_math.*): the basis against the textbook
// Cox-de Boor recursion written out here independently, partition of unity,
// the exact circle, derivatives against finite differences, curvature,
// validation, and the interpolator's step against its stated feed error.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "fblocks/contour/nurbs_math.hpp"
#include "tests/contour/nurbs_test_curves.hpp"

namespace syncplc::nurbs::test_nurbs_math {
namespace {

using nurbs_test::CurveData;

NurbsCurve make(const CurveData& c) {
  NurbsCurve curve(c.points(), c.order);
  for (int i = 0; i < c.points(); ++i) {
    const auto j = static_cast<std::size_t>(i);
    curve.px()[i] = c.x[j];
    curve.py()[i] = c.y[j];
    curve.pz()[i] = c.z[j];
    curve.weights()[i] = c.w[j];
  }
  for (std::size_t i = 0; i < c.knots.size(); ++i) curve.knots()[i] = c.knots[i];
  return curve;
}

// N_{i,k}(u) by the definition (order k, 0/0 = 0, half-open intervals; at
// the end of the range the last non-empty interval is taken closed).
double textbook_basis(const std::vector<double>& U, int i, int k, double u, int n) {
  if (k == 1) {
    const auto a = U[static_cast<std::size_t>(i)], b = U[static_cast<std::size_t>(i + 1)];
    if (a <= u && u < b) return 1;
    // u = u_end: the last non-empty interval holds it
    if (u == U[static_cast<std::size_t>(n)] && b == u && a < b) return 1;
    return 0;
  }
  double r = 0;
  const double d1 = U[static_cast<std::size_t>(i + k - 1)] - U[static_cast<std::size_t>(i)];
  const double d2 = U[static_cast<std::size_t>(i + k)] - U[static_cast<std::size_t>(i + 1)];
  if (d1 > 0) r += (u - U[static_cast<std::size_t>(i)]) / d1 * textbook_basis(U, i, k - 1, u, n);
  if (d2 > 0) r += (U[static_cast<std::size_t>(i + k)] - u) / d2 * textbook_basis(U, i + 1, k - 1, u, n);
  return r;
}

TEST(NurbsBasis, PartitionOfUnityAndTextbookRecursion) {
  std::mt19937_64 g(7);
  for (int k = 2; k <= kNurbsMaxOrder; ++k) {
    for (int trial = 0; trial < 5; ++trial) {
      const int n = k + 1 + trial * 2;
      CurveData c;
      c.order = k;
      c.x.assign(static_cast<std::size_t>(n), 0.0);
      c.y = c.z = c.x;
      c.w.assign(static_cast<std::size_t>(n), 1.0);
      c.knots = nurbs_test::random_knots(n, k, g);
      const NurbsCurve curve = make(c);
      ASSERT_EQ(curve.validate(), NurbsFault::kNone);
      for (int step = 0; step <= 300; ++step) {
        const double u = 3.0 * step / 300;
        const int s = curve.span(u);
        double N[kNurbsMaxOrder];
        curve.basis(u, s, N);
        double sum = 0;
        for (int j = 0; j < k; ++j) {
          EXPECT_GE(N[j], -1e-15);
          sum += N[j];
          const int i = s - k + 1 + j;
          EXPECT_NEAR(N[j], textbook_basis(c.knots, i, k, u, n), 1e-13) << "k " << k << " u " << u << " i " << i;
        }
        EXPECT_NEAR(sum, 1.0, 4 * std::numeric_limits<double>::epsilon()) << "k " << k << " u " << u;
      }
    }
  }
}

TEST(NurbsCurve, CircleRadiusExactToRoundingAndCurvatureOneOverR) {
  const double R = 0.32;
  const NurbsCurve curve = make(nurbs_test::circle(R, 0.1, -0.2));
  ASSERT_EQ(curve.validate(), NurbsFault::kNone);
  for (int step = 0; step <= 10000; ++step) {
    const double u = step / 10000.0;
    Vec3 d[3];
    curve.derivatives(u, 2, d);
    const double r = std::hypot(d[0].x - 0.1, d[0].y + 0.2);
    EXPECT_NEAR(r, R, 4 * std::numeric_limits<double>::epsilon() * R) << "u " << u;
    EXPECT_NEAR(nurbs_curvature(d[1], d[2]), 1 / R, 1e-13 / R) << "u " << u;
    EXPECT_EQ(d[0].z, 0.0);
  }
  Vec3 d[1];
  curve.derivatives(1.0, 0, d);
  EXPECT_NEAR(d[0].x, 0.42, 1e-16);
  EXPECT_NEAR(d[0].y, -0.2, 1e-16);
}

// C', C'', C''' against central differences of the next lower derivative
// (step h: truncation h^2/6 of the next derivative), away from knots.
TEST(NurbsCurve, DerivativesMatchFiniteDifferences) {
  for (const CurveData& c : {nurbs_test::circle(0.32), nurbs_test::freeform()}) {
    const NurbsCurve curve = make(c);
    ASSERT_EQ(curve.validate(), NurbsFault::kNone);
    const double u0 = curve.u_begin(), u1 = curve.u_end();
    const double h = 1e-5 * (u1 - u0);
    for (int step = 1; step < 200; ++step) {
      const double u = u0 + (u1 - u0) * (step + 0.37) / 200;
      bool near_knot = false;
      for (double kn : c.knots) near_knot |= std::abs(kn - u) < 2 * h;
      if (near_knot) continue;
      Vec3 d[4], lo[4], hi[4];
      curve.derivatives(u, 3, d);
      curve.derivatives(u - h, 3, lo);
      curve.derivatives(u + h, 3, hi);
      for (int r = 1; r <= 3; ++r) {
        const double scale = norm(d[r]) + norm(d[r - 1]) / (u1 - u0) + 1e-12;
        EXPECT_NEAR(d[r].x, (hi[r - 1].x - lo[r - 1].x) / (2 * h), 1e-6 * scale) << "r " << r << " u " << u;
        EXPECT_NEAR(d[r].y, (hi[r - 1].y - lo[r - 1].y) / (2 * h), 1e-6 * scale) << "r " << r << " u " << u;
        EXPECT_NEAR(d[r].z, (hi[r - 1].z - lo[r - 1].z) / (2 * h), 1e-6 * scale) << "r " << r << " u " << u;
      }
    }
  }
}

// Paper 003's K = |y''| / (1 + y'^2)^1.5 is the case x = u of |C' x C''| / |C'|^3.
TEST(NurbsCurve, CurvatureOfAGraphIsPaper003Formula) {
  // y = u^2 on [0, 1] as a non-rational quadratic Bezier: points (0,0), (0.5,0), (1,1).
  CurveData c;
  c.order = 3;
  c.x = {0, 0.5, 1};
  c.y = {0, 0, 1};
  c.z = {0, 0, 0};
  c.w = {1, 1, 1};
  c.knots = {0, 0, 0, 1, 1, 1};
  const NurbsCurve curve = make(c);
  for (double u : {0.0, 0.2, 0.5, 0.9, 1.0}) {
    Vec3 d[3];
    curve.derivatives(u, 2, d);
    EXPECT_NEAR(d[0].x, u, 1e-15);
    const double y1 = 2 * u, y2 = 2;
    EXPECT_NEAR(nurbs_curvature(d[1], d[2]), std::abs(y2) / std::pow(1 + y1 * y1, 1.5), 1e-14);
  }
}

TEST(NurbsCurve, ValidationNamesTheFaultAndElement) {
  auto check = [](CurveData c, NurbsFault want, int want_where) {
    const NurbsCurve curve = make(c);
    int where = -1;
    EXPECT_EQ(curve.validate(&where), want);
    EXPECT_EQ(where, want_where);
    EXPECT_NE(std::string(nurbs_fault_text(want)).find("NURBS_PATH: "), std::string::npos);
  };
  auto c = nurbs_test::circle(1);
  c.knots[4] = 0.2;  // 0.25 0.2: decreases
  check(c, NurbsFault::kKnotsDecrease, 4);
  c = nurbs_test::circle(1);
  c.w[3] = 0;
  check(c, NurbsFault::kWeightNotPositive, 3);
  c = nurbs_test::circle(1);
  c.w[5] = -1;
  check(c, NurbsFault::kWeightNotPositive, 5);
  c = nurbs_test::circle(1);
  c.knots[0] = -0.1;  // not clamped at the start
  check(c, NurbsFault::kNotClamped, 1);
  c = nurbs_test::circle(1);
  c.knots[11] = 1.1;  // not clamped at the end
  check(c, NurbsFault::kNotClamped, 10);
  c = nurbs_test::circle(1);
  for (auto& k : c.knots) k = 0.5;
  check(c, NurbsFault::kEmptyRange, 0);
  c = nurbs_test::circle(1);
  c.knots[5] = c.knots[6] = 0.25;  // 0.25 three times in a quadratic: the curve breaks
  check(c, NurbsFault::kInteriorMultiplicity, 5);
  c = nurbs_test::circle(1);
  c.y[2] = std::numeric_limits<double>::quiet_NaN();
  check(c, NurbsFault::kNotFinite, 2);
  c = nurbs_test::circle(1);
  c.knots[7] = std::numeric_limits<double>::infinity();
  check(c, NurbsFault::kNotFinite, 7);
  EXPECT_EQ(make(nurbs_test::circle(1)).validate(), NurbsFault::kNone);
  EXPECT_EQ(make(nurbs_test::freeform()).validate(), NurbsFault::kNone);
}

// One step of the speed-controlled interpolator: the chord it makes against
// ds, compared with its stated leading error term. On the free-form curve the
// parametrization is far from arc length, so the second-order term of the
// update does real work: without it the error is first order in ds.
TEST(NurbsInterpolator, StepErrorIsTheStatedSecondOrderTerm) {
  const NurbsCurve curve = make(nurbs_test::freeform());
  for (double ds : {1e-4, 3e-5, 1e-5}) {
    double worst_rel = 0, worst_first_order = 0, worst_second_order = 0;
    for (int step = 1; step < 400; ++step) {
      const double u = 2.0 * step / 400;
      Vec3 d[4], e[1], f[1];
      const int s = curve.derivatives(u, 3, d);
      const double un = nurbs_next_u(u, ds, d[1], d[2]);
      if (curve.span(un) != s) continue;  // the expansion holds within one polynomial piece
      curve.derivatives(un, 0, e);
      const double chord = norm({e[0].x - d[0].x, e[0].y - d[0].y, e[0].z - d[0].z});
      const double measured = chord / ds - 1;
      const double predicted = nurbs_predicted_feed_error(ds, d[1], d[2], d[3]);
      // The next term is O(ds^3): relative to ds^2 it shrinks with ds.
      const double scale = ds * ds * (dot(d[2], d[2]) / std::pow(dot(d[1], d[1]), 2) + 1e-300);
      worst_rel = std::max(worst_rel, std::abs(measured - predicted) / scale);
      worst_second_order = std::max(worst_second_order, std::abs(measured));
      curve.derivatives(u + ds / norm(d[1]), 0, f);  // first order only
      const double chord1 = norm({f[0].x - d[0].x, f[0].y - d[0].y, f[0].z - d[0].z});
      worst_first_order = std::max(worst_first_order, std::abs(chord1 / ds - 1));
    }
    EXPECT_LT(worst_rel, 0.05) << "ds " << ds;
    EXPECT_GT(worst_first_order, 10 * worst_second_order) << "ds " << ds;  // the first-order update is much worse
  }
}

}  // namespace
}  // namespace syncplc::nurbs::test_nurbs_math
