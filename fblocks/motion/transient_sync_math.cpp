// Bound scaling of paper 004 Section III, eqs. (23)-(34); see the header and
// docs/motion/transient-sync.md, sections 1 and 2 ("Every scan").
#include "fblocks/motion/transient_sync_math.hpp"

#include <cmath>

namespace syncplc::motion {

CruiseRoots eq33_roots(double x0, double v0, double r0, double rdot, double tf, double u_min,
                       double u_max) noexcept {
  const double dU = u_min - u_max, dv = v0 - rdot, dx = x0 - r0;
  const double rad = u_min * u_max * (tf * u_min * (tf * u_max + 2 * dv) + 2 * dx * dU + dv * dv);
  CruiseRoots r;
  if (!(dU < 0) || !(rad >= 0)) return r;
  const double g = std::sqrt(rad);
  const double base = u_min * u_max * tf + u_min * v0 - u_max * rdot;
  r.real = true;
  r.printed = (base + g) / dU;
  r.other = (base - g) / dU;
  return r;
}

CruiseRoots eq34_roots(double x0, double v0, double r0, double rdot, double tf, double u_min,
                       double u_max) noexcept {
  const double dU = u_min - u_max, dv = v0 - rdot, dx = x0 - r0;
  const double rad = u_min * u_max * (tf * u_max * (tf * u_min + 2 * dv) - 2 * dx * dU + dv * dv);
  CruiseRoots r;
  if (!(dU < 0) || !(rad >= 0)) return r;
  const double g = std::sqrt(rad);
  const double base = u_min * u_max * tf + u_max * v0 - u_min * rdot;
  r.real = true;
  r.printed = -(base + g) / dU;
  r.other = -(base - g) / dU;
  return r;
}

double stopping_offset(double x0, double v0, double r0, double rdot, double u_min, double u_max) noexcept {
  const double w0 = v0 - rdot;
  return (x0 - r0) + (w0 > 0 ? w0 * w0 / (2 * -u_min) : -w0 * w0 / (2 * u_max));
}

namespace {

// cruise_bound_up once its side test has passed (tf > 0, u_min < 0 < u_max,
// and the filter ends behind the reference).
double cruise_up_body(double x0, double v0, double r0, double rdot, double tf, double u_min, double u_max,
                      bool brake_first) noexcept {
  const double gap = r0 - x0;  // D: how far the reference is ahead
  const double a = u_max, d = u_min;
  const double w0 = v0 - rdot;  // velocity relative to the reference
  if (brake_first && w0 > 0) {
    // Profile: brake with U- from w0 to w, cruise, brake with U- from w to 0.
    // The cruise lasts tf - w0/|U-| whatever w; at w = w0 it covers
    // w0*tf - w0^2/(2|U-|).
    const double cruise = tf + w0 / d;
    if (!(cruise > 0)) return kNaN;  // cannot even brake to rdot within tf
    if (w0 * tf + w0 * w0 / (2 * d) > gap) {
      const double num = gap + w0 * w0 / (2 * d);
      if (!(num > 0)) return kNaN;  // braking at once still overshoots
      return rdot + num / cruise;
    }
  }
  // Quadratic A w^2 + B w + C = 0 of eqs. (30)-(32) in w = v̂ - rdot:
  // A = U+ - U-, B = 2U-(U+ tf + w0), C = U-(2U+ dx - w0^2), dx = x0 - r0.
  // (B/2)^2 - AC is the radicand of G~; w = (-B/2 - G~)/A is the printed
  // (smaller) root, evaluated without cancellation as C / (-B/2 + G~).
  const double A = a - d, hb = d * (a * tf + w0), C = d * (-2 * a * gap - w0 * w0);
  const double rad = hb * hb - A * C;
  if (!(rad >= 0)) return kNaN;
  const double g = std::sqrt(rad);
  const double w = (-hb > 0) ? C / (-hb + g) : (-hb - g) / A;
  if (!(w > 0)) return kNaN;  // v̂ not above rdot: the gap cannot be closed this way
  return rdot + w;
}

// The same computation as discrete_stopping_offset from its z-coordinates
// z1 = (x0 - r0)/T^2 + (v0 - rdot)/(2T), z2 = (v0 - rdot)/T (eq. 6).
double discrete_stopping_offset_z(double z1, double z2, double u_min, double u_max, double T) noexcept {
  if (z2 > 0) {
    const double ub = -u_min, j = std::floor(z2 / ub);
    z1 += j * z2 - ub * j * (j + 1) / 2;
  } else if (z2 < 0) {
    const double ub = u_max, j = std::floor(-z2 / ub);
    z1 += j * z2 + ub * j * (j + 1) / 2;
  }
  return z1 * T * T;
}

}  // namespace

double cruise_bound_up(double x0, double v0, double r0, double rdot, double tf, double u_min, double u_max,
                       bool brake_first) noexcept {
  const double gap = r0 - x0;  // D: how far the reference is ahead
  if (!(tf > 0) || !(u_min < 0) || !(u_max > 0)) return kNaN;
  // Printed form: the reference ahead. Extended form: the filter ends behind
  // the reference when it brakes now (it may be past the reference, moving
  // back towards it).
  if (brake_first ? !(stopping_offset(x0, v0, r0, rdot, u_min, u_max) < 0) : !(gap > 0)) return kNaN;
  return cruise_up_body(x0, v0, r0, rdot, tf, u_min, u_max, brake_first);
}

double cruise_bound_down(double x0, double v0, double r0, double rdot, double tf, double u_min, double u_max,
                         bool brake_first) noexcept {
  // Mirror image z -> -z with (U-, U+) -> (-U+, -U-).
  return -cruise_bound_up(-x0, -v0, -r0, -rdot, tf, -u_max, -u_min, brake_first);
}

double discrete_stopping_offset(double x0, double v0, double r0, double rdot, double u_min, double u_max,
                                double T) noexcept {
  const double w = v0 - rdot;
  const double z2 = w / T;
  const double z1 = (x0 - r0) / (T * T) + w / (2 * T);  // eq. (6)
  return discrete_stopping_offset_z(z1, z2, u_min, u_max, T);
}

namespace {

// scale_bounds; z: the state's z-coordinates (eq. 6) when the caller has
// them (they are those discrete_stopping_offset computes), else nullptr.
ScaledBounds scale_bounds_impl(SyncRule rule, double x0, double v0, double r0, double rdot, double tf, double v_min,
                               double v_max, double u_min, double u_max, double T, const ZState* z) noexcept {
  ScaledBounds out{v_min, v_max, BoundAction::Nominal};
  if (rule == SyncRule::Off || !(tf > 0) || !(v_min <= rdot && rdot <= v_max)) return out;
  const bool brake_first = rule == SyncRule::Unified;
  if (brake_first && T > 0) {
    // Feed the continuous model the discrete filter's stopping point: shift x0
    // so that its continuous stopping offset equals the discrete one.
    const double dso = z ? discrete_stopping_offset_z(z->z1, z->z2, u_min, u_max, T)
                         : discrete_stopping_offset(x0, v0, r0, rdot, u_min, u_max, T);
    const double shift = dso - stopping_offset(x0, v0, r0, rdot, u_min, u_max);
    if (std::isfinite(shift)) x0 += shift;
  }
  // The side of the final approach: the paper's sign of r0 - x0, or (unified)
  // the side on which the filter comes to rest relative to the reference when
  // it brakes at once, which differs when it cannot stop before passing it.
  const double side = rule == SyncRule::Paper ? x0 - r0 : stopping_offset(x0, v0, r0, rdot, u_min, u_max);
  // cruise_bound_up/down repeat this side test (the stopping offset, or the
  // sign of the gap, of the mirror image for down: its negation); it passes
  // here by construction, so their bodies are called directly.
  const bool accel_ok = u_min < 0 && u_max > 0;
  if (side < 0) {
    if (rule == SyncRule::Paper && rdot < 0) {  // Fig. 7: park with x+ = 0
      out.v_max = std::fmin(0.0, v_max);
      out.action = BoundAction::ParkedUpper;
      return out;
    }
    const double v = accel_ok ? cruise_up_body(x0, v0, r0, rdot, tf, u_min, u_max, brake_first) : kNaN;
    if (v < v_max) {  // false for NaN
      out.v_max = v;
      out.action = BoundAction::ScaledUpper;
    }
  } else if (side > 0) {
    if (rule == SyncRule::Paper && rdot > 0) {  // mirror of Fig. 7: x- = 0
      out.v_min = std::fmax(0.0, v_min);
      out.action = BoundAction::ParkedLower;
      return out;
    }
    // cruise_bound_down: the mirror image.
    const double v = accel_ok ? -cruise_up_body(-x0, -v0, -r0, -rdot, tf, -u_max, -u_min, brake_first) : kNaN;
    if (v > v_min) {
      out.v_min = v;
      out.action = BoundAction::ScaledLower;
    }
  }
  return out;
}

}  // namespace

ScaledBounds scale_bounds(SyncRule rule, double x0, double v0, double r0, double rdot, double tf, double v_min,
                          double v_max, double u_min, double u_max, double T) noexcept {
  return scale_bounds_impl(rule, x0, v0, r0, rdot, tf, v_min, v_max, u_min, u_max, T, nullptr);
}

ScaledBounds scale_bounds(SyncRule rule, double x0, double v0, double r0, double rdot, double tf, double v_min,
                          double v_max, double u_min, double u_max, double T, const ZState& z) noexcept {
  return scale_bounds_impl(rule, x0, v0, r0, rdot, tf, v_min, v_max, u_min, u_max, T, &z);
}

}  // namespace syncplc::motion
