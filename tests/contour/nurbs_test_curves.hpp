// Curves the NURBS tests share: the exact quadratic NURBS circle (9 control
// points, weights 1, sqrt(2)/2, ...), a cubic free-form curve, and random
// clamped knot vectors.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdint>
#include <random>
#include <string>
#include <vector>

namespace syncplc::nurbs::nurbs_test {

struct CurveData {
  std::vector<double> x, y, z, w, knots;
  int order = 3;
  int points() const { return static_cast<int>(x.size()); }
};

// The full circle of radius r about (cx, cy), anticlockwise from (cx + r, cy).
inline CurveData circle(double r, double cx = 0, double cy = 0) {
  const double h = std::sqrt(2.0) / 2;
  CurveData c;
  c.order = 3;
  const double px[] = {1, 1, 0, -1, -1, -1, 0, 1, 1};
  const double py[] = {0, 1, 1, 1, 0, -1, -1, -1, 0};
  for (int i = 0; i < 9; ++i) {
    c.x.push_back(cx + r * px[i]);
    c.y.push_back(cy + r * py[i]);
    c.z.push_back(0);
    c.w.push_back(i % 2 ? h : 1.0);
  }
  c.knots = {0, 0, 0, 0.25, 0.25, 0.5, 0.5, 0.75, 0.75, 1, 1, 1};
  return c;
}

// A cubic free-form curve in space with uneven weights and knots: its
// parametrization is far from arc length (the interpolator's second term matters).
inline CurveData freeform() {
  CurveData c;
  c.order = 4;
  c.x = {0, 0.01, 0.03, 0.05, 0.04, 0.07, 0.09};
  c.y = {0, 0.02, 0.025, 0.0, -0.02, -0.01, 0.01};
  c.z = {0, 0.005, 0.0, 0.01, 0.02, 0.015, 0.0};
  c.w = {1, 0.5, 2, 1, 3, 0.7, 1};
  c.knots = {0, 0, 0, 0, 0.1, 0.45, 0.6, 2, 2, 2, 2};
  return c;
}

// A clamped knot vector for n points of order k, random interior knots in
// [0, 3] (sorted; repeats of at most k - 1 when `repeat`).
inline std::vector<double> random_knots(int n, int k, std::mt19937_64& g) {
  std::uniform_real_distribution<double> u(0, 3);
  std::vector<double> in;
  while (static_cast<int>(in.size()) < n - k) {
    const double v = std::round(u(g) * 8) / 8;  // coarse: equal knots happen
    int same = 0;
    for (double e : in) same += e == v;
    if (same < k - 1 && v > 0 && v < 3) in.push_back(v);
  }
  std::sort(in.begin(), in.end());
  std::vector<double> knots(static_cast<std::size_t>(k), 0.0);
  knots.insert(knots.end(), in.begin(), in.end());
  knots.insert(knots.end(), static_cast<std::size_t>(k), 3.0);
  return knots;
}

inline std::string number(double v) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.17g", v);
  return buf;
}

}  // namespace syncplc::nurbs::nurbs_test
