// A NURBS curve (paper 003 eqs. (7)-(8)) and the speed-controlled parameter
// update of Yeh & Hsu (1999): evaluation by the rational basis with the
// B-spline basis from the Cox-de Boor recursion, derivatives up to the third,
// validation of the data. Storage is sized once by the constructor; nothing
// after it allocates (the scan path of NURBS_PATH). See docs/motion/nurbs.md.
#pragma once

#include <cstdint>
#include <vector>

namespace syncplc::nurbs {

// Highest order k (degree k - 1) the fixed-size basis tables hold.
inline constexpr int kNurbsMaxOrder = 8;

struct Vec3 {
  double x = 0, y = 0, z = 0;
};

// Why a curve's data cannot be interpolated (0: it can). Also NURBS_PATH's ErrorID.
enum class NurbsFault : std::uint16_t {
  kNone = 0,
  kKnotsDecrease = 1,       // the knot vector is not non-decreasing
  kWeightNotPositive = 2,   // a weight is <= 0 (the denominator of eq. (8) could vanish)
  kNotClamped = 3,          // the first k or the last k knots are not equal
  kEmptyRange = 4,          // u_end <= u_begin: the curve is a single point of parameter
  kInteriorMultiplicity = 5,// an interior knot repeats k or more times: the curve breaks there
  kNotFinite = 6,           // a point, weight or knot is NaN or infinite
};

// Static text for a fault (for events: no allocation).
const char* nurbs_fault_text(NurbsFault f) noexcept;

class NurbsCurve {
 public:
  // n control points, order k (2..kNurbsMaxOrder, n >= k); n + k knots.
  NurbsCurve(int points, int order);

  int points() const noexcept { return n_; }
  int order() const noexcept { return k_; }
  // The data, written in place (x, y, z of each point, its weight, the knots).
  double* px() noexcept { return x_.data(); }
  double* py() noexcept { return y_.data(); }
  double* pz() noexcept { return z_.data(); }
  double* weights() noexcept { return w_.data(); }
  double* knots() noexcept { return u_.data(); }
  const double* knots() const noexcept { return u_.data(); }
  Vec3 point(int i) const noexcept { return {x_[static_cast<std::size_t>(i)], y_[static_cast<std::size_t>(i)], z_[static_cast<std::size_t>(i)]}; }

  // Checks the data; on a fault `where` is the 0-based element concerned (of
  // the points and weights for kNotFinite/kWeightNotPositive on them, else of the knots).
  NurbsFault validate(int* where = nullptr) const noexcept;

  // The parameter range [U[k-1], U[n]] (clamped: the curve runs from point 0 to point n-1).
  double u_begin() const noexcept { return u_[static_cast<std::size_t>(k_ - 1)]; }
  double u_end() const noexcept { return u_[static_cast<std::size_t>(n_)]; }

  // Knot span s with U[s] <= u < U[s+1], k-1 <= s <= n-1 (u = u_end: the last
  // non-empty span). `hint` is the span of a nearby earlier call (the
  // interpolator moves forward): it is searched from there first.
  int span(double u, int hint = -1) const noexcept;

  // The k B-spline basis functions of order k non-zero on span s at u
  // (N[j] = N_{s-k+1+j, k}(u), eq. (8)'s Z), by the Cox-de Boor recursion.
  void basis(double u, int s, double* N) const noexcept;

  // C(u) and its derivatives d[r] = d^r C / du^r for r = 0..nd (nd <= 3),
  // by eq. (7) in homogeneous form and the quotient rule. Returns the span.
  int derivatives(double u, int nd, Vec3* d, int hint = -1) const noexcept;

 private:
  int n_, k_;
  std::vector<double> x_, y_, z_, w_, u_;
};

double dot(const Vec3& a, const Vec3& b) noexcept;
double norm(const Vec3& a) noexcept;
Vec3 cross(const Vec3& a, const Vec3& b) noexcept;

// Curvature |C' x C''| / |C'|^3 (in the plane: |x'y'' - y'x''| / |C'|^3).
double nurbs_curvature(const Vec3& d1, const Vec3& d2) noexcept;

// The speed-controlled interpolator (Yeh & Hsu 1999): the parameter after a
// path step ds from u, where C'(u) = d1, C''(u) = d2, by the second-order
// Taylor expansion of u(s):
//   u+ = u + ds/|C'| - ds^2 (C'.C'') / (2 |C'|^4).
// Where the second term would reverse the step (|C'| small against |C''|)
// only the first-order term is taken; where C' vanishes (a cusp of the
// parametrization) the step is sqrt(2 ds / |C''|).
double nurbs_next_u(double u, double ds, const Vec3& d1, const Vec3& d2) noexcept;

// One interpolator step along the curve from u (on span `span`, C'(u) = d1,
// C''(u) = d2) by the path length ds: nurbs_next_u, except that a step that
// would cross the end of the span is split at the knot (the arc to the knot
// by the second-order expansion of s(u), the rest by nurbs_next_u from the
// knot's derivatives on the next span), because C'' jumps at a knot of a
// curve that is only C1 there and one expansion across it errs in the first
// order. The result may pass u_end (the caller ends the path there).
double nurbs_advance(const NurbsCurve& curve, double u, double ds, int span, const Vec3& d1, const Vec3& d2) noexcept;

// The leading term of the relative chord-feed error of one step of
// nurbs_next_u (docs/motion/nurbs.md):
//   e = ds^2/6 [(|C''|^2 + C'.C''') / |C'|^4 - 4 (C'.C'')^2 / |C'|^6] - K^2 ds^2 / 24.
double nurbs_predicted_feed_error(double ds, const Vec3& d1, const Vec3& d2, const Vec3& d3) noexcept;

}  // namespace syncplc::nurbs
