// The velocity/acceleration-limited discrete-time nonlinear filter used by
// paper 004 (C. Guarino Lo Bianco, "An efficient algorithm for the real-time
// generation of synchronous reference signals", Section II; the filter of its
// reference [21]) and the prediction of its transient time (Table I).
//
// Pure functions, double precision, noexcept, no allocation. Each function does
// one job; the comments cite the paper's equations. The controller C is not
// printed in the paper: the law here is the one derived in
// docs/motion/nonlinear-filter.md (section 2), which also lists the
// corrections of Table I (section 3).
//
// Notation (paper): T sampling time; state x = [x, xdot] (eq. 1-2); reference
// r = [r, rdot] given by steps and ramps; y = x - r (eq. 5);
// z1 = y1/T^2 + y2/(2T), z2 = y2/T (eq. 6), so that z' = Ad z + bd u (eqs. 7-8):
//   z1' = z1 + z2 + u,  z2' = z2 + u.
// z and u have the units of an acceleration. Bounds: xdot- < xdot+ (velocity),
// U- < 0 < U+ (acceleration). In z-space the velocity bounds are
// z2+ = (xdot+ - rdot)/T and z2- = (xdot- - rdot)/T (text after eq. 8).
//
// Halves: z1 < 0 means the output is behind the reference; its final approach
// brakes with U-. z1 > 0 is the mirror image: z -> -z together with
// (U-, U+, z2-, z2+) -> (-U+, -U-, -z2+, -z2-). The controller is exactly
// mirror-symmetric, and so is the transient-time prediction.
#pragma once

#include <cmath>
#include <cstdint>
#include <limits>

namespace syncplc::motion {

// ---- data -------------------------------------------------------------------

// Velocity and acceleration bounds (eqs. 3-4), in the reference's units
// (m/s and m/s^2 for a linear axis). Valid when finite, v_min < v_max and
// a_min < 0 < a_max. v_min/v_max need not straddle 0.
struct FilterBounds {
  double v_min = 0;  // xdot-
  double v_max = 0;  // xdot+
  double a_min = 0;  // U- (negative)
  double a_max = 0;  // U+ (positive)
};

// Filter state x = [x, xdot] (eq. 1).
struct FilterState {
  double x = 0;
  double v = 0;
};

// Reference r = [r, rdot]: a step/ramp signal, assumed to be a ramp over the
// coming sample (r_{i+1} = r_i + T rdot_i).
struct Reference {
  double r = 0;
  double v = 0;
};

// The z-coordinates (eq. 6).
struct ZState {
  double z1 = 0;
  double z2 = 0;
};

// The bounds in z-space: z2- and z2+ (text after eq. 8), U- and U+.
struct ZBounds {
  double z2_min = 0;  // z2- = (xdot- - rdot)/T
  double z2_max = 0;  // z2+ = (xdot+ - rdot)/T
  double u_min = 0;   // U-
  double u_max = 0;   // U+
};

// One filter step in the original coordinates.
struct FilterStep {
  FilterState next;  // state at the next sample
  double u = 0;      // acceleration applied over the sample
};

// "Never" for a transient time: the reference cannot be tracked with these
// bounds (rdot outside [xdot-, xdot+]), or the count exceeds kMaxSteps.
inline constexpr std::int64_t kNever = -1;
// Longest transient the prediction reports (about 32 years at 1 ms); beyond
// it the result is kNever.
inline constexpr std::int64_t kMaxSteps = std::int64_t{1} << 40;

// Where a state starts, in the terms of Table I and Fig. 3 (see
// docs/motion/nonlinear-filter.md). The region is that of the half in which
// the state enters the boundary layer (BL); `mirrored` says that half is the
// right one (z1 > 0).
enum class TransientRegion : std::uint8_t {
  Tracking,  // already within the tracking tolerance: 0 steps
  A,         // in the curved part of the BL: m (eq. 11)
  B,         // cruising on the velocity bound z2 = z2+: k_b + m (eq. 14)
  C,         // in the flat part of the BL, off the bound: 1 + k_b + m
  D,         // above the BL, enters its flat part braking: k_d + 1 + k_b + m (eq. 16)
  E,         // below the BL, enters its flat part: k_e + 1 + k_b + m (eq. 18)
  F,         // below the BL, enters its curved part: k_f + m (eqs. 20-22)
  G,         // above the BL, enters its curved part (not in Table I): k + m
  Never,     // rdot outside the velocity bounds (or beyond kMaxSteps)
};

struct TransientInfo {
  std::int64_t steps = kNever;  // samples until is_tracking(), or kNever
  TransientRegion region = TransientRegion::Never;
  bool mirrored = false;        // the state enters the BL in the right half (z1 > 0)
  std::int64_t k_entry = 0;     // samples of full acceleration before the BL (k_d, k_e, k_f)
  std::int64_t k_cruise = 0;    // samples on the velocity bound (k_b, incl. the entry step for C/D/E)
  std::int64_t m = 0;           // samples in the curved part of the BL (eq. 11)
  bool closed_form = true;      // false: a closed-form index failed its check and was searched
};

// ---- validation and coordinates ----------------------------------------------

// True when all four bounds are finite, v_min < v_max and a_min < 0 < a_max.
inline bool bounds_valid(const FilterBounds& b) noexcept;

// Eqs. (5)-(6): z from the state, the reference and the sampling time T > 0.
inline ZState to_z(const FilterState& s, const Reference& ref, double T) noexcept;

// Inverse of (5)-(6): y2 = T z2, y1 = T^2 (z1 - z2/2); x = r + y.
FilterState from_z(const ZState& z, const Reference& ref, double T) noexcept;

// The bounds in z-space for reference slope rdot (text after eq. 8).
inline ZBounds z_bounds(const FilterBounds& b, double r_dot, double T) noexcept;

// Eq. (9): abscissa where the curved part of the left BL meets z2 = z2+;
// 0 when z2+ <= 0.
double z1_plus(const ZBounds& zb) noexcept;

// Eq. (10): its mirror, where the right BL meets z2 = z2-; 0 when z2- >= 0.
double z1_minus(const ZBounds& zb) noexcept;

// ---- plant --------------------------------------------------------------------

// Eqs. (1)-(2): x' = x + T xdot + T^2/2 u, xdot' = xdot + T u.
inline FilterState plant_step(const FilterState& s, double u, double T) noexcept;

// Eqs. (7)-(8): z1' = z1 + z2 + u, z2' = z2 + u.
inline ZState z_step(const ZState& z, double u) noexcept;

// ---- controller C ---------------------------------------------------------------

// Eq. (11) in a rounding-safe integer form: the smallest N >= 2 with
// N(N-1)/2 >= a, for a >= 0 (a = |z1|/Ub, Ub the braking bound of the final
// approach). Returned as a double (exact integer) so that huge a cannot
// overflow.
double approach_steps(double a) noexcept;

// Relative velocity (z2) the controller targets for the next sample before the
// velocity clamp: w* = -sign(z1) Ub (a/(m-1) + (m-2)/2), Ub = -U- for z1 < 0 and
// U+ for z1 > 0, a = |z1|/Ub, m = approach_steps(a); 0 for z1 = 0. Inside the
// BL the filter lands on it exactly, then its |z2| falls by Ub per sample and
// z reaches 0 after m samples.
double target_velocity(double z1, const ZBounds& zb) noexcept;

// The same target clamped to the velocity bounds [z2-, z2+] (cruise).
double clamped_target_velocity(double z1, const ZBounds& zb) noexcept;

// Half-width of the acceleration deadband: a control beyond a bound by at most
// this much is applied as is (1e-7 max(U+, -U-)). Rounding noise on the bound
// then never costs a sample.
inline double accel_deadband(const ZBounds& zb) noexcept;

// Controller C, one sample: u = clamp(w_t - z2, U-, U+) with the deadband,
// w_t = clamped_target_velocity(z1). Memoryless; the bounds may change at any
// sample.
double control(const ZState& z, const ZBounds& zb) noexcept;

// One complete filter sample in the original coordinates: z from (s, ref),
// u = control(z), next = plant_step(s, u). T > 0, bounds valid.
FilterStep filter_step(const FilterState& s, const Reference& ref, const FilterBounds& b, double T) noexcept;

// ---- predicates -----------------------------------------------------------------

// Tracking tolerance: 1e-6 max(U+, -U-).
inline double tracking_tolerance(const ZBounds& zb) noexcept;

// |z1| <= tol and |z2| <= tol: the output tracks the reference.
inline bool is_tracking(const ZState& z, const ZBounds& zb) noexcept;

// Inside the boundary layer: the controller does not saturate (within the
// deadband), i.e. U- <= w_t - z2 <= U+.
bool in_boundary_layer(const ZState& z, const ZBounds& zb) noexcept;

// In the final approach: inside the BL with an unclamped target
// (z2- <= w* <= z2+), i.e. the curved part of the BL around the origin, where
// the remaining transient is m samples whatever the velocity bounds are as
// long as they do not cut the target (docs/motion/transient-sync.md, section 2, step 2).
// True at the origin too.
bool in_final_approach(const ZState& z, const ZBounds& zb) noexcept;

// ---- transient time (Table I) ------------------------------------------------------

// Samples until is_tracking() holds with the bounds held constant and the
// reference a ramp of slope rdot, with the region of Table I the state starts in.
// kNever when rdot is outside [xdot-, xdot+] (z2+ < 0 or z2- > 0) or the
// reference is out of reach (z2+ = 0 while behind, z2- = 0 while ahead).
TransientInfo transient_info(const ZState& z, const ZBounds& zb) noexcept;

// transient_info(z, zb).steps.
std::int64_t transient_steps(const ZState& z, const ZBounds& zb) noexcept;

// The bounds with the constants of the prediction that depend on them only
// (both halves: deadband, tracking tolerance, z1+ of eq. 9), for a caller that
// predicts many states under the same bounds (the blocks, while the bounds,
// rdot and T stay). transient_info(z, prepare_bounds(zb)) is transient_info(z, zb).
struct PreparedBounds {
  ZBounds zb;            // the bounds
  ZBounds zb_m;          // their mirror image (z1 > 0 half)
  double eps = 0, eps_m = 0;  // accel_deadband of zb, zb_m
  double tol = 0, tol_m = 0;  // tracking_tolerance of zb, zb_m
  double z1p = 0, z1p_m = 0;  // z1_plus of zb, zb_m
};
PreparedBounds prepare_bounds(const ZBounds& zb) noexcept;
TransientInfo transient_info(const ZState& z, const PreparedBounds& pb) noexcept;
std::int64_t transient_steps(const ZState& z, const PreparedBounds& pb) noexcept;

// Convenience: the same from the original coordinates.
std::int64_t transient_steps(const FilterState& s, const Reference& ref, const FilterBounds& b, double T) noexcept;

// ---- inline implementations ------------------------------------------------------
// The small functions above, and the pieces of controller C that the
// transient-time prediction and the synchronizer (transient_sync_math.hpp)
// evaluate many times per scan, inline.

namespace detail {

inline constexpr double kDeadbandRel = 1e-7;  // of max(U+, -U-)
inline constexpr double kTrackingRel = 1e-6;  // of max(U+, -U-)

// std::fmax as the x86-64 libm computes it (maxsd with NaN handling): the
// larger of x and y, y when they compare equal (+0/-0), the other one when one
// is a NaN. Inline: the library call is a noticeable part of a prediction.
inline double fmax_libm(double x, double y) noexcept { return (x > y || std::isnan(y)) ? x : y; }

inline double max_accel(const ZBounds& zb) noexcept { return fmax_libm(zb.u_max, -zb.u_min); }

// approach_steps, inline for the prediction's inner loops.
inline double approach_steps_inl(double a) noexcept {
  if (!(a > 0)) return 2;
  double n = std::ceil(0.5 + std::sqrt(0.25 + 2 * a));  // eq. (11)
  if (!(n < 9.0e15)) return n;                          // beyond exact integers: as computed
  if (n < 2) n = 2;
  // Correct a rounding of the square root by one either way.
  for (int i = 0; i < 2 && n > 2 && 0.5 * (n - 1) * (n - 2) >= a; ++i) n -= 1;
  for (int i = 0; i < 2 && 0.5 * n * (n - 1) < a; ++i) n += 1;
  return n;
}

// True when the target speed target_velocity computes for a state at distance
// d = |z1| > 0 with braking bound ub, ub (a/(m-1) + (m-2)/2) with a = d/ub and
// m = approach_steps(a), rounded, is certainly greater than v >= 0, decided
// without the square root. For every real m > 1, a/(m-1) + (m-2)/2 >=
// sqrt(2a) - 1/2 (AM-GM), so the exact value is >= sqrt(2 d ub) - ub/2 and it
// exceeds v when 2 d ub > (v + ub/2)^2. The test asks for a relative margin of
// 1e-9, far above the rounding of the test (5 ulps) and of target_velocity
// (a, the quotient, the sum, the product: 5 ulps), and for normal, finite
// operands, so that the rounded target is > v whenever the test holds. False
// means "not decided" (the caller computes the target).
inline bool target_surely_above(double d, double ub, double v) noexcept {
  if (!(v >= 0) || !(ub > 0)) return false;
  const double p = v + 0.5 * ub;
  const double pp = p * p;
  const double lhs = 2 * d * ub;
  return pp >= std::numeric_limits<double>::min() && lhs <= std::numeric_limits<double>::max() &&
         lhs >= pp * (1 + 1e-9);
}

// target_velocity (as declared) with the mirror image exact: the left half
// (z1 < 0) and the right half use the same arithmetic on |z1|.
inline double target_velocity_inl(double z1, const ZBounds& zb) noexcept {
  if (z1 == 0) return 0;
  const double ub = z1 < 0 ? -zb.u_min : zb.u_max;  // braking bound of the final approach
  const double a = std::fabs(z1) / ub;
  const double m = approach_steps_inl(a);
  const double w = ub * (a / (m - 1) + 0.5 * (m - 2));
  return z1 < 0 ? w : -w;
}

// clamped_target_velocity: the clamp of target_velocity to [z2-, z2+], with the
// far field (target certainly beyond the bound it is clamped to) decided
// without the square root. Exact: returns what the clamp of the rounded target
// returns.
inline double clamped_target_inl(double z1, const ZBounds& zb) noexcept {
  if (zb.z2_min <= zb.z2_max) {
    if (z1 < 0 && target_surely_above(-z1, -zb.u_min, zb.z2_max)) return zb.z2_max;    // w > z2+
    if (z1 > 0 && target_surely_above(z1, zb.u_max, -zb.z2_min)) return zb.z2_min;    // w < z2- <= z2+
  }
  const double w = target_velocity_inl(z1, zb);
  return w > zb.z2_max ? zb.z2_max : (w < zb.z2_min ? zb.z2_min : w);
}

}  // namespace detail

inline bool bounds_valid(const FilterBounds& b) noexcept {
  return std::isfinite(b.v_min) && std::isfinite(b.v_max) && std::isfinite(b.a_min) && std::isfinite(b.a_max) &&
         b.v_min < b.v_max && b.a_min < 0 && b.a_max > 0;
}

inline ZState to_z(const FilterState& s, const Reference& ref, double T) noexcept {
  const double y1 = s.x - ref.r;
  const double y2 = s.v - ref.v;
  return {y1 / (T * T) + y2 / (2 * T), y2 / T};
}

inline ZBounds z_bounds(const FilterBounds& b, double r_dot, double T) noexcept {
  return {(b.v_min - r_dot) / T, (b.v_max - r_dot) / T, b.a_min, b.a_max};
}

inline FilterState plant_step(const FilterState& s, double u, double T) noexcept {
  return {s.x + T * s.v + 0.5 * T * T * u, s.v + T * u};
}

inline ZState z_step(const ZState& z, double u) noexcept { return {z.z1 + z.z2 + u, z.z2 + u}; }

inline double accel_deadband(const ZBounds& zb) noexcept { return detail::kDeadbandRel * detail::max_accel(zb); }

inline double tracking_tolerance(const ZBounds& zb) noexcept { return detail::kTrackingRel * detail::max_accel(zb); }

inline bool is_tracking(const ZState& z, const ZBounds& zb) noexcept {
  const double tol = tracking_tolerance(zb);
  return std::fabs(z.z1) <= tol && std::fabs(z.z2) <= tol;
}

// Controller C's target at one abscissa z1 for several velocity bounds that
// share the acceleration bounds (the synchronizer's nominal, previous and
// reduced bounds): target_velocity(z1, zb) is computed (one square root) only
// when a clamp or a range test cannot be decided without it. Every answer is
// the one the full computation gives (see detail::target_surely_above).
class ControllerTarget {
 public:
  // zb supplies the acceleration bounds only.
  ControllerTarget(double z1, const ZBounds& zb) noexcept : z1_(z1), zb_(zb) {}

  // target_velocity(z1, zb).
  double value() noexcept {
    if (!have_) {
      w_ = detail::target_velocity_inl(z1_, zb_);
      have_ = true;
    }
    return w_;
  }
  // clamped_target_velocity(z1, zx), zx with the acceleration bounds of zb.
  double clamped(const ZBounds& zx) noexcept {
    if (zx.z2_min <= zx.z2_max) {
      if (z1_ < 0 && detail::target_surely_above(-z1_, -zx.u_min, zx.z2_max)) return zx.z2_max;
      if (z1_ > 0 && detail::target_surely_above(z1_, zx.u_max, -zx.z2_min)) return zx.z2_min;
    }
    const double w = value();
    return w > zx.z2_max ? zx.z2_max : (w < zx.z2_min ? zx.z2_min : w);
  }
  // z2- <= target <= z2+ of zx: the target is not cut by the velocity bounds.
  bool within(const ZBounds& zx) noexcept {
    if (z1_ < 0 && detail::target_surely_above(-z1_, -zx.u_min, zx.z2_max)) return false;
    if (z1_ > 0 && detail::target_surely_above(z1_, zx.u_max, -zx.z2_min)) return false;
    const double w = value();
    return w <= zx.z2_max && w >= zx.z2_min;
  }
  // control(z, zx) for z.z1 = z1.
  double control(const ZState& z, const ZBounds& zx) noexcept {
    const double u = clamped(zx) - z.z2;
    const double eps = accel_deadband(zx);
    if (u > zx.u_max + eps) return zx.u_max;
    if (u < zx.u_min - eps) return zx.u_min;
    return u;
  }
  // in_final_approach(z, zx) for z.z1 = z1.
  bool final_approach(const ZState& z, const ZBounds& zx) noexcept {
    if (!within(zx)) return false;
    const double u = clamped(zx) - z.z2;
    const double eps = accel_deadband(zx);
    return u <= zx.u_max + eps && u >= zx.u_min - eps;
  }

 private:
  double z1_;
  ZBounds zb_;
  double w_ = 0;
  bool have_ = false;
};

}  // namespace syncplc::motion
