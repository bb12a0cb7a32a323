// The contour-error estimate and cross-coupled contour control (CCC) law of
// docs/motion/contouring.md, as plain functions (no block, no allocation):
//   - the reference path's local frame: unit tangent t, left normal n and
//     signed curvature kappa from the reference velocity and acceleration;
//   - the contour error of the actual point against the path's circle of
//     curvature (Yeh & Hsu 2002): exact on a circle and on a straight line;
//   - the coupling gains Cx, Cy of the linearised estimate
//     eps ~ -Cx ex + Cy ey;
//   - paper 003's robust CCC: the CCC gain scheduled by the path curvature.
#pragma once

#include <algorithm>
#include <cmath>

namespace syncplc::contour {

// The reference path at the reference point, in the plane of the contour.
struct PathFrame {
  double tx = 1, ty = 0;  // unit tangent (direction of travel)
  double kappa = 0;       // signed curvature, > 0 when the path turns left (anticlockwise)
};

// The frame from the reference velocity (vx, vy) and acceleration (ax, ay):
// t = v/|v|, kappa = (vx ay - vy ax) / |v|^3, the parametric curvature with
// time as the parameter. False (frame unchanged) when |v| <= v_min: at
// standstill the direction of travel is not defined.
inline bool path_frame(double vx, double vy, double ax, double ay, double v_min, PathFrame& f) {
  const double speed = std::hypot(vx, vy);
  if (!(speed > v_min)) return false;
  f.tx = vx / speed;
  f.ty = vy / speed;
  f.kappa = (vx * ay - vy * ax) / (speed * speed * speed);
  return true;
}

// Contour error of the actual point against the circle of curvature through
// the reference point (centre on the left normal n = (-ty, tx) at 1/kappa).
// With the tracking error e = reference - actual (ex, ey), the actual point
// lies at d = -e from the reference point; d_t = d.t, d_n = d.n. The
// distance from the osculating circle, rho - |P - C|, rewritten without 1/kappa
// so that it is well conditioned for kappa -> 0 (a straight line gives -d_n):
//   eps = -(2 d_n - kappa (d_t^2 + d_n^2)) / (1 + sqrt((1 - kappa d_n)^2 + (kappa d_t)^2))
// Sign: eps > 0 when the actual point is to the right of the direction of
// travel (outside an anticlockwise circle: there eps = |r| - R exactly).
inline double contour_error(const PathFrame& f, double ex, double ey) {
  const double dt = -(ex * f.tx + ey * f.ty);
  const double dn = -(-ex * f.ty + ey * f.tx);
  const double k = f.kappa;
  const double a = 1 - k * dn, b = k * dt;
  return -(2 * dn - k * (dt * dt + dn * dn)) / (1 + std::sqrt(a * a + b * b));
}

// The coupling gains of the first-order expansion of contour_error in e
// (Yeh & Hsu's form): eps ~ -Cx ex + Cy ey with, theta the tangent angle,
//   Cx = sin(theta) - kappa ex / 2,  Cy = cos(theta) + kappa ey / 2.
// With kappa = 0 they are Koren's gains of a straight line.
struct CouplingGains {
  double cx = 0, cy = 0;
};
inline CouplingGains coupling_gains(const PathFrame& f, double ex, double ey) {
  return {f.ty - f.kappa * ex / 2, f.tx + f.kappa * ey / 2};
}

// Paper 003's robust CCC: the gain chosen by the path curvature K = |kappa|.
// The paper prints K but not the map from K to the gain; the one chosen here
// (docs/motion/contouring.md) runs linearly from gain_low on a straight path
// to gain_high at K >= k_ref and stays there: the high gain where the
// tracking lag turns into contour error (curves), the low gain, with its
// wider stability margin, where it does not (straight lines).
inline double scheduled_gain(double curvature, double gain_low, double gain_high, double k_ref) {
  if (!(k_ref > 0)) return gain_high;
  const double w = std::clamp(std::abs(curvature) / k_ref, 0.0, 1.0);
  return gain_low + (gain_high - gain_low) * w;
}

}  // namespace syncplc::contour
