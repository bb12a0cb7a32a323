// NURBS evaluation and the speed-controlled interpolator step; see nurbs_math.hpp.
#include "fblocks/contour/nurbs_math.hpp"

#include <algorithm>
#include <array>
#include <cmath>

namespace syncplc::nurbs {

const char* nurbs_fault_text(NurbsFault f) noexcept {
  switch (f) {
    case NurbsFault::kNone: return "";
    case NurbsFault::kKnotsDecrease: return "NURBS_PATH: the knot vector decreases (value: the element, 1-based)";
    case NurbsFault::kWeightNotPositive: return "NURBS_PATH: a weight is not positive (value: the element, 1-based)";
    case NurbsFault::kNotClamped:
      return "NURBS_PATH: the knot vector is not clamped: its first and last k knots must be equal (value: the element, 1-based)";
    case NurbsFault::kEmptyRange: return "NURBS_PATH: the knot vector's parameter range is empty";
    case NurbsFault::kInteriorMultiplicity:
      return "NURBS_PATH: an interior knot repeats k or more times, the curve breaks there (value: the element, 1-based)";
    case NurbsFault::kNotFinite: return "NURBS_PATH: a point, weight or knot is not finite (value: the element, 1-based)";
  }
  return "NURBS_PATH: invalid curve";
}

NurbsCurve::NurbsCurve(int points, int order)
    : n_(points),
      k_(order),
      x_(static_cast<std::size_t>(points)),
      y_(static_cast<std::size_t>(points)),
      z_(static_cast<std::size_t>(points)),
      w_(static_cast<std::size_t>(points), 1.0),
      u_(static_cast<std::size_t>(points + order)) {}

NurbsFault NurbsCurve::validate(int* where) const noexcept {
  auto fail = [where](NurbsFault f, int i) {
    if (where) *where = i;
    return f;
  };
  for (int i = 0; i < n_; ++i) {
    const auto j = static_cast<std::size_t>(i);
    if (!std::isfinite(x_[j]) || !std::isfinite(y_[j]) || !std::isfinite(z_[j]) || !std::isfinite(w_[j]))
      return fail(NurbsFault::kNotFinite, i);
    if (!(w_[j] > 0)) return fail(NurbsFault::kWeightNotPositive, i);
  }
  const int m = n_ + k_;
  for (int i = 0; i < m; ++i) {
    if (!std::isfinite(u_[static_cast<std::size_t>(i)])) return fail(NurbsFault::kNotFinite, i);
    if (i > 0 && u_[static_cast<std::size_t>(i)] < u_[static_cast<std::size_t>(i - 1)])
      return fail(NurbsFault::kKnotsDecrease, i);
  }
  for (int i = 1; i < k_; ++i) {
    if (u_[static_cast<std::size_t>(i)] != u_[0]) return fail(NurbsFault::kNotClamped, i);
    if (u_[static_cast<std::size_t>(m - 1 - i)] != u_[static_cast<std::size_t>(m - 1)])
      return fail(NurbsFault::kNotClamped, m - 1 - i);
  }
  if (!(u_end() > u_begin())) return fail(NurbsFault::kEmptyRange, 0);
  // Every knot value inside [u_begin, u_end] other than the ends may repeat at
  // most k - 1 times (C0 continuity); the ends exactly k times.
  int run = 1;
  for (int i = k_; i <= n_; ++i) {
    const auto j = static_cast<std::size_t>(i);
    run = u_[j] == u_[j - 1] ? run + 1 : 1;
    if (run >= k_) return fail(NurbsFault::kInteriorMultiplicity, i);
  }
  return NurbsFault::kNone;
}

int NurbsCurve::span(double u, int hint) const noexcept {
  const int lo = k_ - 1, hi = n_ - 1;
  auto U = [this](int i) { return u_[static_cast<std::size_t>(i)]; };
  if (u >= U(n_)) {  // the end: the last non-empty span
    int s = hi;
    while (s > lo && U(s) >= U(s + 1)) --s;
    return s;
  }
  if (u <= U(lo)) {
    int s = lo;
    while (s < hi && U(s + 1) <= U(lo)) ++s;
    return s;
  }
  if (hint >= lo && hint <= hi) {  // forward walk: the interpolator crosses a few knots at most
    int s = hint;
    for (int step = 0; step < 4 && s <= hi; ++step, ++s)
      if (U(s) <= u && u < U(s + 1)) return s;
  }
  int a = lo, b = hi + 1;  // U(a) <= u < U(b)
  while (b - a > 1) {
    const int mid = a + (b - a) / 2;
    (u < U(mid) ? b : a) = mid;
  }
  return a;
}

void NurbsCurve::basis(double u, int s, double* N) const noexcept {
  std::array<double, kNurbsMaxOrder> left{}, right{};
  N[0] = 1.0;
  for (int j = 1; j < k_; ++j) {
    left[static_cast<std::size_t>(j)] = u - u_[static_cast<std::size_t>(s + 1 - j)];
    right[static_cast<std::size_t>(j)] = u_[static_cast<std::size_t>(s + j)] - u;
    double saved = 0.0;
    for (int r = 0; r < j; ++r) {
      // U[s+r+1] - U[s+1-j+r] > 0 on a non-empty span s.
      const double t = N[r] / (right[static_cast<std::size_t>(r + 1)] + left[static_cast<std::size_t>(j - r)]);
      N[r] = saved + right[static_cast<std::size_t>(r + 1)] * t;
      saved = left[static_cast<std::size_t>(j - r)] * t;
    }
    N[j] = saved;
  }
}

namespace {
// Homogeneous point (w x, w y, w z, w).
struct NurbsHom {
  double x = 0, y = 0, z = 0, w = 0;
};
}  // namespace

int NurbsCurve::derivatives(double u, int nd, Vec3* d, int hint) const noexcept {
  const int s = span(u, hint);
  const int p = k_ - 1;
  // table[q][j] = N_{s-q+j} of degree q at u, q = 0..p (the Cox-de Boor
  // triangle kept level by level: the derivative curves use the lower degrees).
  double table[kNurbsMaxOrder][kNurbsMaxOrder];
  {
    std::array<double, kNurbsMaxOrder> left{}, right{}, N{};
    N[0] = 1.0;
    table[0][0] = 1.0;
    for (int j = 1; j <= p; ++j) {
      left[static_cast<std::size_t>(j)] = u - u_[static_cast<std::size_t>(s + 1 - j)];
      right[static_cast<std::size_t>(j)] = u_[static_cast<std::size_t>(s + j)] - u;
      double saved = 0.0;
      for (int r = 0; r < j; ++r) {
        const double t = N[static_cast<std::size_t>(r)] /
                         (right[static_cast<std::size_t>(r + 1)] + left[static_cast<std::size_t>(j - r)]);
        N[static_cast<std::size_t>(r)] = saved + right[static_cast<std::size_t>(r + 1)] * t;
        saved = left[static_cast<std::size_t>(j - r)] * t;
      }
      N[static_cast<std::size_t>(j)] = saved;
      for (int r = 0; r <= j; ++r) table[j][r] = N[static_cast<std::size_t>(r)];
    }
  }
  // The p + 1 homogeneous control points of span s; level r holds the
  // control points of the r-th derivative curve (degree p - r).
  NurbsHom D[kNurbsMaxOrder];
  for (int i = 0; i <= p; ++i) {
    const auto g = static_cast<std::size_t>(s - p + i);
    D[i] = {w_[g] * x_[g], w_[g] * y_[g], w_[g] * z_[g], w_[g]};
  }
  NurbsHom A[4];  // d^r (w C) / du^r and d^r w / du^r
  for (int r = 0; r <= nd; ++r) {
    NurbsHom sum;
    if (r <= p) {
      for (int i = 0; i <= p - r; ++i) {
        const double b = table[p - r][i];
        sum.x += b * D[i].x, sum.y += b * D[i].y, sum.z += b * D[i].z, sum.w += b * D[i].w;
      }
      if (r < nd) {  // D^{r+1}_i = (p - r)(D^r_{i+1} - D^r_i) / (U[g+p+1] - U[g+r+1]), g = s - p + i
        for (int i = 0; i < p - r; ++i) {
          const int g = s - p + i;
          const double den = u_[static_cast<std::size_t>(g + p + 1)] - u_[static_cast<std::size_t>(g + r + 1)];
          const double f = den > 0 ? (p - r) / den : 0.0;  // a zero-length interval: its basis is zero
          D[i] = {f * (D[i + 1].x - D[i].x), f * (D[i + 1].y - D[i].y), f * (D[i + 1].z - D[i].z),
                  f * (D[i + 1].w - D[i].w)};
        }
      }
    }
    A[r] = sum;
  }
  // Quotient rule for C = A / w: d^r C = (d^r A - sum_{i=1..r} binom(r,i) w^(i) d^(r-i) C) / w.
  static constexpr double kBinom[4][4] = {{1, 0, 0, 0}, {1, 1, 0, 0}, {1, 2, 1, 0}, {1, 3, 3, 1}};
  const double w0 = A[0].w;
  for (int r = 0; r <= nd; ++r) {
    Vec3 v{A[r].x, A[r].y, A[r].z};
    for (int i = 1; i <= r; ++i) {
      const double c = kBinom[r][i] * A[i].w;
      v.x -= c * d[r - i].x, v.y -= c * d[r - i].y, v.z -= c * d[r - i].z;
    }
    d[r] = {v.x / w0, v.y / w0, v.z / w0};
  }
  return s;
}

double dot(const Vec3& a, const Vec3& b) noexcept { return a.x * b.x + a.y * b.y + a.z * b.z; }
double norm(const Vec3& a) noexcept { return std::sqrt(dot(a, a)); }
Vec3 cross(const Vec3& a, const Vec3& b) noexcept {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}

double nurbs_curvature(const Vec3& d1, const Vec3& d2) noexcept {
  const double v = norm(d1);
  if (!(v > 0)) return 0.0;
  return norm(cross(d1, d2)) / (v * v * v);
}

double nurbs_next_u(double u, double ds, const Vec3& d1, const Vec3& d2) noexcept {
  const double v2 = dot(d1, d1);
  const double a = norm(d2);
  // |C'| negligible against the step's reach in |C''|: C ~ C'' du^2 / 2 there.
  if (v2 <= 1e-12 * a * ds || v2 == 0) return a > 0 ? u + std::sqrt(2 * ds / a) : u;
  const double v = std::sqrt(v2);
  const double first = ds / v;
  const double second = ds * ds * dot(d1, d2) / (2 * v2 * v2);
  const double du = first - second;
  return u + (du > 0 ? du : first);
}

double nurbs_advance(const NurbsCurve& curve, double u, double ds, int span, const Vec3& d1, const Vec3& d2) noexcept {
  double u_next = nurbs_next_u(u, ds, d1, d2);
  Vec3 a = d1, b = d2;
  // A few knots at most in one step (a longer step than a span is a feed far
  // beyond the curve's detail); past those the last expansion is kept.
  for (int crossing = 0; crossing < 8; ++crossing) {
    const double knot = curve.knots()[span + 1];
    if (u_next <= knot || knot >= curve.u_end()) break;
    const double du = knot - u, v = norm(a);
    if (!(v > 0)) break;
    const double to_knot = v * du + dot(a, b) / (2 * v) * du * du;  // arc length to the knot
    if (!(to_knot > 0) || to_knot >= ds) break;
    Vec3 d[3];
    span = curve.derivatives(knot, 2, d, span);  // the span that starts at the knot
    ds -= to_knot;
    u = knot;
    a = d[1], b = d[2];
    u_next = nurbs_next_u(u, ds, a, b);
  }
  return u_next;
}

double nurbs_predicted_feed_error(double ds, const Vec3& d1, const Vec3& d2, const Vec3& d3) noexcept {
  const double v2 = dot(d1, d1);
  if (!(v2 > 0)) return 0.0;
  const double c12 = dot(d1, d2);
  const double k = nurbs_curvature(d1, d2);
  const double bracket = (dot(d2, d2) + dot(d1, d3)) / (v2 * v2) - 4 * c12 * c12 / (v2 * v2 * v2);
  return ds * ds * (bracket / 6 - k * k / 24);
}

}  // namespace syncplc::nurbs
