// The shipped contours (projects/contouring/circle.yaml, butterfly.yaml)
// loaded and run in virtual time: the path is sampled every scan, checked
// against the curve built from the project's own arrays (radius, stated feed
// error, duration from the arc length), ends on its last point with Done,
// and the simulated table's axes follow it.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <memory>
#include <string>

#include "fblocks/contour/nurbs_math.hpp"
#include "runtime/core/virtual_clock.hpp"
#include "runtime/project/loader.hpp"
#include "tests/support/image_key.hpp"

namespace syncplc::nurbs::test_nurbs_project {
namespace {

struct Loaded {
  std::unique_ptr<Program> p;
  Cell* cell(const std::string& ref) {
    auto r = p->resolve(ref);
    EXPECT_TRUE(r) << ref;
    return r ? p->live_cell(*r, ::syncplc::testing::image_key()) : nullptr;
  }
};

Loaded load(const char* file) {
  auto r = load_project(std::string(SYNCPLC_SOURCE_DIR) + "/projects/contouring/" + file, LoadOptions{});
  for (const auto& d : r.diagnostics.list()) ADD_FAILURE() << d.text();
  return {std::move(r.program)};
}

// The curve of the instance `path`, from its pins' constants.
NurbsCurve curve_of(Loaded& l, int points, int order) {
  NurbsCurve c(points, order);
  const Cell* px = l.cell("path.px");
  const Cell* py = l.cell("path.py");
  const Cell* w = l.cell("path.w");
  const Cell* knot = l.cell("path.knot");
  for (int i = 0; i < points; ++i) {
    c.px()[i] = px[i].get<double>();
    c.py()[i] = py[i].get<double>();
    c.pz()[i] = 0;
    c.weights()[i] = w[i].get<double>();
  }
  for (int i = 0; i < points + order; ++i) c.knots()[i] = knot[i].get<double>();
  return c;
}

struct PathRun {
  double worst_fe = 0, worst_e = 0, bound = 0, length = 0;
  int done_scan = -1;
};

PathRun run(const char* file, int points, int order, double feed, double T, void (*each)(double x, double y)) {
  Loaded l = load(file);
  PathRun out;
  if (!l.p) return out;
  const NurbsCurve c = curve_of(l, points, order);
  EXPECT_EQ(c.validate(), NurbsFault::kNone);
  // Arc length by Simpson on 20000 panels per curve; the stated bound's maximum.
  const int m = 20000;
  const double u0 = c.u_begin(), u1 = c.u_end(), h = (u1 - u0) / m;
  for (int i = 0; i <= m; ++i) {
    Vec3 d[4];
    c.derivatives(u0 + h * i, 3, d);
    out.length += (i == 0 || i == m ? 1 : (i % 2 ? 4 : 2)) * norm(d[1]) * h / 3;
    out.bound = std::max(out.bound, std::abs(nurbs_predicted_feed_error(feed * T, d[1], d[2], d[3])));
  }
  VirtualClock clock(*l.p);
  Cell *x = l.cell("ref[1]"), *y = l.cell("ref[2]"), *fe = l.cell("feed_error"), *done = l.cell("done");
  Cell *e1 = l.cell("e[1]"), *e2 = l.cell("e[2]");
  for (int scan = 0; scan < 7000; ++scan) {
    clock.run_until(static_cast<std::int64_t>(scan + 1) * 1'000'000);  // the scans at 0 .. scan ms
    each(x->get<double>(), y->get<double>());
    if (out.done_scan < 0) out.worst_fe = std::max(out.worst_fe, std::abs(fe->get<double>()));
    out.worst_e = std::max({out.worst_e, std::abs(e1->get<double>()), std::abs(e2->get<double>())});
    if (out.done_scan < 0 && done->get<bool>()) out.done_scan = scan;
  }
  EXPECT_EQ(x->get<double>(), 0.0);  // the last control point, exactly
  EXPECT_EQ(y->get<double>(), 0.0);
  EXPECT_TRUE(done->get<bool>());
  return out;
}

TEST(NurbsProject, CircleIsExactAndEndsOnItsStart) {
  const double feed = 0.05, T = 0.001;
  const PathRun r = run("circle.yaml", 9, 3, feed, T, [](double x, double y) {
    EXPECT_NEAR(std::hypot(x + 0.05, y), 0.05, 8 * std::numeric_limits<double>::epsilon() * 0.05);
  });
  EXPECT_NEAR(r.length, 2 * std::numbers::pi * 0.05, 1e-12);
  EXPECT_EQ(r.done_scan, static_cast<int>(std::ceil(r.length / (feed * T))));  // 6284
  EXPECT_LE(r.worst_fe, 1.01 * r.bound + 1e-13);
  EXPECT_LT(r.worst_e, 0.5e-3);  // the axes follow (start and stop are feed steps)
  std::printf("circle: L %.6f m, done at scan %d, |feed error| max %.3e (stated %.3e), |e| max %.3e m\n", r.length,
              r.done_scan, r.worst_fe, r.bound, r.worst_e);
}

TEST(NurbsProject, ButterflyRunsItsLengthAtTheFeed) {
  const double feed = 0.05, T = 0.001;
  const PathRun r = run("butterfly.yaml", 25, 4, feed, T, [](double x, double y) {
    EXPECT_LT(std::abs(x), 0.06);  // inside the wings' box
    EXPECT_GT(y, -0.02);
    EXPECT_LT(y, 0.08);
  });
  // Done on the scan the accumulated path passes L, within the feed error.
  EXPECT_NEAR(r.done_scan, r.length / (feed * T), 1 + r.length / (feed * T) * r.bound);
  EXPECT_LE(r.worst_fe, 1.01 * r.bound + 1e-13);
  EXPECT_LT(r.worst_e, 0.5e-3);
  std::printf("butterfly: L %.6f m, done at scan %d, |feed error| max %.3e (stated %.3e), |e| max %.3e m\n",
              r.length, r.done_scan, r.worst_fe, r.bound, r.worst_e);
}

}  // namespace
}  // namespace syncplc::nurbs::test_nurbs_project
