// Velocity-bound scaling of the n-axis synchronizer, paper 004 Section III
// (eqs. 23-34), with the corrections derived in docs/motion/transient-sync.md
// (sections 1 and 2, "Every scan"). Pure functions, no state, no
// allocation; the synchronizer's scan algorithm (TransientSyncCore,
// transient_sync_core.cpp, behind TRANSIENT_SYNC) calls them every scan for
// every filter that is neither tracking, nor the slowest, nor in its final
// approach.
//
// Continuous-time model (Fig. 6). A filter at x0 with velocity v0 must meet the
// reference r(t) = r0 + rdot*t at t = tf with velocity rdot. With r0 > x0 it
// changes its velocity to v̂ with the acceleration bound (U+ when v̂ > v0),
// cruises at v̂, and brakes to rdot with U- (eqs. 25-29). The distance covered
// (eq. 30) equals the reference's displacement rdot*tf (eq. 31, the text's
// "r0 + rdot*tf" counts r0 twice) plus the gap r0 - x0 (eq. 32). That is a
// quadratic in v̂; with dU = U- - U+, dv = v0 - rdot, dx = x0 - r0:
//
//   (33) r0 > x0:  v̂ = (U-U+ tf + U- v0 - U+ rdot + G~) / dU,
//        G~ = sqrt(U-U+ [tf U- (tf U+ + 2 dv) + 2 dx dU + dv^2])
//   (34) r0 < x0:  v̂ = -(U-U+ tf + U+ v0 - U- rdot + G^) / dU,
//        G^ = sqrt(U-U+ [tf U+ (tf U- + 2 dv) - 2 dx dU + dv^2])
//
// Both roots of the quadratic can be positive. The cruise time t2 (eq. 29) is
// the derivative of the covered distance with respect to v̂, so the profile is
// physical (t2 >= 0) only at the smaller root for (33) (the larger for (34),
// the mirror image); the printed "+G" is that root. A negative radicand means tf
// is shorter than the profile allows; a v̂ on the wrong side of rdot means the
// gap cannot be closed with a positive cruise speed relative to the reference:
// in both cases the nominal bounds stay.
//
// Extensions (unified rule). (a) Eqs. (25)-(27) assume v0 <= v̂ (the first
// phase accelerates). When the filter already moves towards the reference
// faster than the solution, its controller first brakes with U- down to the
// new bound; that profile is linear in v̂ (see cruise_bound_up). (b) The side
// of the final approach is not the sign of r0 - x0 but that of the stopping
// offset (where the filter would come to rest relative to the reference if it
// braked at once): a filter just behind the reference but too fast to stop
// before it ends up ahead, and is synchronized with (34), whose quadratic holds
// for either sign of dx. The paper's rule keeps the printed closed form and
// the sign of r0 - x0.
#pragma once

#include <cstdint>
#include <limits>

#include "fblocks/motion/nonlinear_filter_math.hpp"

namespace syncplc::motion {

// How the synchronizer chooses the scaled bound (the block's parameter `rule`).
enum class SyncRule : std::uint8_t {
  Unified = 0,  // (33) whenever r > x, (34) whenever r < x, whatever the sign of rdot
  Paper = 1,    // (33) only with rdot >= 0, (34) only with rdot <= 0; otherwise park at 0
  Off = 2,      // no synchronization: n independent filters
};

// What happened to a filter's velocity bounds this scan.
enum class BoundAction : std::uint8_t {
  Nominal = 0,      // both nominal
  ScaledUpper = 1,  // x+ := v̂ of eq. (33)
  ScaledLower = 2,  // x- := v̂ of eq. (34)
  ParkedUpper = 3,  // paper rule, rdot < 0 with r > x: x+ := 0 (Fig. 7)
  ParkedLower = 4,  // paper rule, rdot > 0 with r < x: x- := 0
};

inline constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// Both roots of the quadratic behind eq. (33) (r0 > x0, upper bound scaled),
// as printed: `printed` takes +G~, `other` takes -G~. real = false (and NaNs)
// when the radicand is negative or dU is not negative.
struct CruiseRoots {
  bool real = false;
  double printed = kNaN;
  double other = kNaN;
};
CruiseRoots eq33_roots(double x0, double v0, double r0, double rdot, double tf, double u_min,
                       double u_max) noexcept;
// Same for eq. (34) (r0 < x0, lower bound scaled): printed takes +G^.
CruiseRoots eq34_roots(double x0, double v0, double r0, double rdot, double tf, double u_min,
                       double u_max) noexcept;

// Where the filter comes to rest relative to the reference if it brakes at
// once with its acceleration bounds (continuous time): (x0 - r0) + dv|dv|/(2Ub),
// dv = v0 - rdot, Ub = -U- for dv > 0 and U+ for dv < 0. Negative: it ends
// behind the reference.
double stopping_offset(double x0, double v0, double r0, double rdot, double u_min, double u_max) noexcept;

// The cruise velocity v̂ that makes the continuous profile of a filter behind
// its reference meet it exactly at tf, or NaN if there is none (radicand
// negative, tf <= 0, v̂ <= rdot, or no solution of the branch). brake_first =
// false: eq. (33) as printed (smaller root), for r0 > x0. brake_first = true
// (unified): for stopping_offset < 0, eq. (33) or, when v0 is above the
// solution, the profile that starts by braking with U- (linear:
// v̂ - rdot = (D - dv^2/(2|U-|)) / (tf - dv/|U-|), D = r0 - x0).
double cruise_bound_up(double x0, double v0, double r0, double rdot, double tf, double u_min, double u_max,
                       bool brake_first) noexcept;
// Mirror image for a filter ahead of its reference (r0 < x0, or
// stopping_offset > 0 with brake_first): the new lower bound v̂ < rdot of
// eq. (34), or NaN.
double cruise_bound_down(double x0, double v0, double r0, double rdot, double tf, double u_min, double u_max,
                         bool brake_first) noexcept;

// The same for the discrete filter with sampling time T > 0: the relative
// position at which it comes to rest if it brakes at full acceleration from
// now, in z-coordinates (eq. 6) z1 + sum of the next J velocities,
// J = floor(|z2|/Ub) full braking samples (a last partial sample lands on
// z2 = 0 without moving z1), times T^2. It differs from stopping_offset by up
// to about |dv| T/2 + Ub T^2: near zero the two can disagree on the side.
double discrete_stopping_offset(double x0, double v0, double r0, double rdot, double u_min, double u_max,
                                double T) noexcept;

// Decision of one filter's applied velocity bounds, given that the
// synchronizer wants it to arrive at tf (> 0). Nominal bounds v_min < rdot <
// v_max and u_min < 0 < u_max. Applied bounds never leave [v_min, v_max] and
// always keep v_min <= rdot <= v_max. With the unified rule and T > 0, x0 is
// first shifted so that the continuous stopping offset equals the discrete
// one (side and gap then agree with what the discrete filter can do; without
// it a filter whose braking ends within a few mm of the reference was
// released early in about 1 of 1000 random transients at 10 ms); T = 0: the
// continuous model as is.
struct ScaledBounds {
  double v_min = 0;
  double v_max = 0;
  BoundAction action = BoundAction::Nominal;
};
ScaledBounds scale_bounds(SyncRule rule, double x0, double v0, double r0, double rdot, double tf, double v_min,
                          double v_max, double u_min, double u_max, double T = 0) noexcept;
// The same with the state's z-coordinates z = to_z({x0, v0}, {r0, rdot}, T)
// given (T > 0): the discrete stopping point starts from them.
ScaledBounds scale_bounds(SyncRule rule, double x0, double v0, double r0, double rdot, double tf, double v_min,
                          double v_max, double u_min, double u_max, double T, const ZState& z) noexcept;

// ---- controller C from a precomputed target -----------------------------------
// The synchronizer evaluates controller C of nonlinear_filter_math.hpp for up
// to three velocity bounds per filter and scan (nominal, reduced, previous).
// The target w* = target_velocity(z1, zb) depends on z1 and the acceleration
// bounds only, so one evaluation (a square root) serves all of them. These two
// restate control() and in_final_approach() with w* given; the tests check
// that they agree with them exactly.

// control(z, zb) with w = target_velocity(z.z1, zb).
inline double control_from_target(const ZState& z, const ZBounds& zb, double w) noexcept {
  const double wt = w > zb.z2_max ? zb.z2_max : (w < zb.z2_min ? zb.z2_min : w);
  const double u = wt - z.z2;
  const double eps = accel_deadband(zb);
  if (u > zb.u_max + eps) return zb.u_max;
  if (u < zb.u_min - eps) return zb.u_min;
  return u;
}

// in_final_approach(z, zb) with w = target_velocity(z.z1, zb).
inline bool final_approach_from_target(const ZState& z, const ZBounds& zb, double w) noexcept {
  const double wt = w > zb.z2_max ? zb.z2_max : (w < zb.z2_min ? zb.z2_min : w);
  const double u = wt - z.z2;
  const double eps = accel_deadband(zb);
  return u <= zb.u_max + eps && u >= zb.u_min - eps && w <= zb.z2_max && w >= zb.z2_min;
}

}  // namespace syncplc::motion
