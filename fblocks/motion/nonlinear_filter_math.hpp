// The velocity/acceleration-limited discrete-time nonlinear filter used by
// paper 004 (C. Guarino Lo Bianco, "An efficient algorithm for the real-time
// generation of synchronous reference signals", Section II; the filter of its
// reference [21]) and the prediction of its transient time (Table I).
//
// Pure functions, double precision, noexcept, no allocation. Each function does
// one job; the comments cite the paper's equations. The controller C is not
// printed in the paper: the law here is the one derived in
// ../shared/design/motion-math.md ("Paper 004") and in
// docs/motion/nonlinear-filter.md, which also lists the corrections of Table I.
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

#include <cstdint>

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
bool bounds_valid(const FilterBounds& b) noexcept;

// Eqs. (5)-(6): z from the state, the reference and the sampling time T > 0.
ZState to_z(const FilterState& s, const Reference& ref, double T) noexcept;

// Inverse of (5)-(6): y2 = T z2, y1 = T^2 (z1 - z2/2); x = r + y.
FilterState from_z(const ZState& z, const Reference& ref, double T) noexcept;

// The bounds in z-space for reference slope rdot (text after eq. 8).
ZBounds z_bounds(const FilterBounds& b, double r_dot, double T) noexcept;

// Eq. (9): abscissa where the curved part of the left BL meets z2 = z2+;
// 0 when z2+ <= 0.
double z1_plus(const ZBounds& zb) noexcept;

// Eq. (10): its mirror, where the right BL meets z2 = z2-; 0 when z2- >= 0.
double z1_minus(const ZBounds& zb) noexcept;

// ---- plant --------------------------------------------------------------------

// Eqs. (1)-(2): x' = x + T xdot + T^2/2 u, xdot' = xdot + T u.
FilterState plant_step(const FilterState& s, double u, double T) noexcept;

// Eqs. (7)-(8): z1' = z1 + z2 + u, z2' = z2 + u.
ZState z_step(const ZState& z, double u) noexcept;

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
double accel_deadband(const ZBounds& zb) noexcept;

// Controller C, one sample: u = clamp(w_t - z2, U-, U+) with the deadband,
// w_t = clamped_target_velocity(z1). Memoryless; the bounds may change at any
// sample.
double control(const ZState& z, const ZBounds& zb) noexcept;

// One complete filter sample in the original coordinates: z from (s, ref),
// u = control(z), next = plant_step(s, u). T > 0, bounds valid.
FilterStep filter_step(const FilterState& s, const Reference& ref, const FilterBounds& b, double T) noexcept;

// ---- predicates -----------------------------------------------------------------

// Tracking tolerance: 1e-6 max(U+, -U-).
double tracking_tolerance(const ZBounds& zb) noexcept;

// |z1| <= tol and |z2| <= tol: the output tracks the reference.
bool is_tracking(const ZState& z, const ZBounds& zb) noexcept;

// Inside the boundary layer: the controller does not saturate (within the
// deadband), i.e. U- <= w_t - z2 <= U+.
bool in_boundary_layer(const ZState& z, const ZBounds& zb) noexcept;

// In the final approach: inside the BL with an unclamped target
// (z2- <= w* <= z2+), i.e. the curved part of the BL around the origin, where
// the remaining transient is m samples whatever the velocity bounds are as
// long as they do not cut the target (motion-math.md, Synchronizer step 2).
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

// Convenience: the same from the original coordinates.
std::int64_t transient_steps(const FilterState& s, const Reference& ref, const FilterBounds& b, double T) noexcept;

}  // namespace syncplc::motion
