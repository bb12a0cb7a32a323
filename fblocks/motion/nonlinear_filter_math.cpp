// Nonlinear filter of paper 004, Section II: controller C and the transient
// time of Table I. See nonlinear_filter_math.hpp for the notation and
// docs/motion/nonlinear-filter.md for the derivations.
#include "fblocks/motion/nonlinear_filter_math.hpp"

#include <cmath>
#include <limits>

namespace syncplc::motion {
namespace {

using detail::approach_steps_inl;
using detail::clamped_target_inl;
using detail::fmax_libm;
using detail::target_surely_above;
using detail::target_velocity_inl;


// The mirror image: z -> -z with (U-, U+, z2-, z2+) -> (-U+, -U-, -z2+, -z2-).
ZState mirror(const ZState& z) noexcept { return {-z.z1, -z.z2}; }
ZBounds mirror(const ZBounds& b) noexcept { return {-b.z2_max, -b.z2_min, -b.u_max, -b.u_min}; }

// The controller's unclamped acceleration w_t - z2 (before saturation).
double raw_control(const ZState& z, const ZBounds& zb) noexcept { return clamped_target_inl(z.z1, zb) - z.z2; }

// State after k samples of constant acceleration u (eq. 12, as in eqs. 15/17):
// z1 + k z2 + k(k+1)/2 u, z2 + k u.
ZState after_constant(const ZState& z, double k, double u) noexcept {
  return {z.z1 + k * z.z2 + 0.5 * k * (k + 1) * u, z.z2 + k * u};
}

// ceil/floor of a double that may be huge, as a double; callers check the
// range against kMaxSteps before converting.
double ceil_nonneg(double v) noexcept { return v > 0 ? std::ceil(v) : 0.0; }

// ---- one prediction: its frame and its target velocities ----------------------

// The target velocities of one prediction, memoized: target_velocity(z1, zb)
// and its approach_steps m for the bounds zb of the original frame. The
// prediction evaluates controller C at the same abscissa several times (the
// region tests, the entry index and its predecessor, the final approach);
// each distinct z1 costs one square root. Exact: the same function of the same
// operands.
class Targets {
 public:
  struct Entry {
    double z1 = 0, m = 0, w = 0;
  };
  explicit Targets(const ZBounds& zb) noexcept : zb_(zb) {}
  // z1 != 0 (original frame).
  const Entry& at(double z1) noexcept {
    for (int i = 0; i < count_; ++i)
      if (e_[i].z1 == z1) return e_[i];
    Entry& e = e_[next_];
    next_ = (next_ + 1) % kSize;
    if (count_ < kSize) ++count_;
    const double ub = z1 < 0 ? -zb_.u_min : zb_.u_max;
    const double a = std::fabs(z1) / ub;
    const double m = approach_steps_inl(a);
    const double w = ub * (a / (m - 1) + 0.5 * (m - 2));
    e = Entry{z1, m, z1 < 0 ? w : -w};
    return e;
  }

 private:
  static constexpr int kSize = 6;
  const ZBounds& zb_;
  Entry e_[kSize];
  int count_ = 0, next_ = 0;
};

// A half of the state space as the prediction sees it: the bounds b of the
// frame (zb, or mirror(zb) when mirrored) and the shared memo of the original
// frame. The mirror image is exact: target_velocity(-z1, mirror(zb)) is
// -target_velocity(z1, zb) bit for bit (same |z1|, same braking bound).
struct Frame {
  Targets& t;
  const ZBounds& b;
  bool mirrored;
  double eps;  // accel_deadband(b)
  double tol;  // tracking_tolerance(b)
  double z1p;  // z1_plus(b)

  Frame(Targets& targets, const PreparedBounds& pb, bool mirror_frame) noexcept
      : t(targets),
        b(mirror_frame ? pb.zb_m : pb.zb),
        mirrored(mirror_frame),
        eps(mirror_frame ? pb.eps_m : pb.eps),
        tol(mirror_frame ? pb.tol_m : pb.tol),
        z1p(mirror_frame ? pb.z1p_m : pb.z1p) {}

  // target_velocity(z1, b).
  double target(double z1) const noexcept {
    if (z1 == 0) return 0;
    return mirrored ? -t.at(-z1).w : t.at(z1).w;
  }
  // approach_steps(-z1 / -b.u_min) for z1 < 0 (that target's m).
  double m_left(double z1) const noexcept { return mirrored ? t.at(-z1).m : t.at(z1).m; }
  // clamped_target_velocity(z1, b).
  double clamped(double z1) const noexcept {
    if (b.z2_min <= b.z2_max) {
      if (z1 < 0 && target_surely_above(-z1, -b.u_min, b.z2_max)) return b.z2_max;
      if (z1 > 0 && target_surely_above(z1, b.u_max, -b.z2_min)) return b.z2_min;
    }
    const double w = target(z1);
    return w > b.z2_max ? b.z2_max : (w < b.z2_min ? b.z2_min : w);
  }
  // Below the BL: the controller saturates at U+.
  bool below(const ZState& z) const noexcept { return clamped(z.z1) - z.z2 > b.u_max + eps; }
  // Above the BL: the controller saturates at U-.
  bool above(const ZState& z) const noexcept { return clamped(z.z1) - z.z2 < b.u_min - eps; }
  // In the curved part at abscissa z1: the target is not cut by z2+.
  bool curved_at(double z1) const noexcept {
    if (z1 < 0 && target_surely_above(-z1, -b.u_min, b.z2_max)) return false;
    return target(z1) <= b.z2_max;
  }
};

// ---- the final approach (eq. 11) ---------------------------------------------

// Samples from a left-half state (z1 <= 0) inside the curved part of the BL
// until is_tracking(): m = approach_steps(|z1|/Ub). The velocity profile of the
// approach is Ub (m-2+f), Ub (m-3+f), ..., Ub f, 0 with
// f = (a - (m-1)(m-2)/2)/(m-1) in (0, 1]; the state at sample m-1 is (0, Ub f),
// already tracking when Ub f <= tol.
struct Approach {
  double steps = 0;
  double m = 0;
};

Approach final_approach(double z1, const Frame& fr) noexcept {
  const ZBounds& zb = fr.b;
  const double ub = -zb.u_min;
  if (z1 >= 0) return {1, 1};  // z1 = 0 and z2 != 0: u = -z2 lands on the origin
  const double a = -z1 / ub;
  const double m = fr.m_left(z1);  // approach_steps(a)
  const double f = (a - 0.5 * (m - 1) * (m - 2)) / (m - 1);
  const double steps = f * ub <= fr.tol ? m - 1 : m;
  return {steps, m};
}

// ---- the flat part of the BL: cruise on z2 = z2+ (eqs. 13-14) ---------------

struct Layer {
  double steps = -1;  // < 0: never
  double k_cruise = 0;
  double m = 0;
  bool flat = false;
  bool on_bound = false;
  bool closed_form = true;
};

// Samples from a state inside the BL in the left half (z1 < 0) until tracking.
Layer layer_left(const ZState& z, const Frame& fr) noexcept {
  const ZBounds& zb = fr.b;
  Layer out;
  if (fr.curved_at(z.z1)) {  // z_a
    const Approach ap = final_approach(z.z1, fr);
    out.steps = ap.steps;
    out.m = ap.steps;
    return out;
  }
  out.flat = true;
  out.on_bound = std::fabs(z.z2 - zb.z2_max) <= fr.eps;  // z_b rather than z_c
  // First sample: w_t = z2+, the state lands on the bound. Then u = 0 until
  // the target drops to z2+, at z1 >= z1+ (eq. 14), j samples later.
  const double v = zb.z2_max;
  const double z1b = z.z1 + v;
  // With z2+ within the tracking tolerance the cruise itself may enter it.
  const double tol = fr.tol;
  double j_tol = -1;  // first cruise sample inside the tolerance, < 0: none
  if (v <= tol) {
    if (std::fabs(z1b) <= tol) {
      out.k_cruise = 1;
      out.steps = 1;
      return out;
    }
    if (!(v > 0)) return out;  // behind and not allowed to move closer: never
    j_tol = ceil_nonneg((-tol - z1b) / v);
    if (!(j_tol <= static_cast<double>(kMaxSteps))) return out;
    if (fr.z1p >= -tol) {  // the curved part starts inside the tolerance: j_tol comes first
      out.k_cruise = 1 + j_tol;
      out.steps = 1 + j_tol;
      return out;
    }
  }
  const double hi_est = ceil_nonneg((fr.z1p - z1b) / v);
  if (!(hi_est <= static_cast<double>(kMaxSteps))) return out;
  auto first = [&](double j) {
    return fr.curved_at(z1b + j * v) && (j == 0 || !fr.curved_at(z1b + (j - 1) * v));
  };
  double j = hi_est;
  if (!first(j)) {
    out.closed_form = false;
    // curved_at is monotone along the cruise (z1 grows, w* falls): bisect.
    double lo = 0, hi = fmax_libm(hi_est, 1.0);
    while (!fr.curved_at(z1b + hi * v)) {
      lo = hi;
      hi *= 2;
      if (hi > static_cast<double>(kMaxSteps)) return out;
    }
    if (fr.curved_at(z1b + lo * v)) hi = lo;
    while (hi - lo > 1) {
      const double mid = std::floor(0.5 * (lo + hi));
      (fr.curved_at(z1b + mid * v) ? hi : lo) = mid;
    }
    j = hi;
  }
  if (j_tol >= 0 && j_tol < j) {
    out.k_cruise = 1 + j_tol;
    out.steps = 1 + j_tol;
    return out;
  }
  const Approach ap = final_approach(z1b + j * v, fr);
  out.k_cruise = 1 + j;
  out.m = ap.steps;
  out.steps = 1 + j + ap.steps;
  return out;
}

// ---- full acceleration towards the BL (eqs. 15-22) -------------------------------

struct Entry {
  double k = -1;  // < 0: never (beyond kMaxSteps)
  bool closed_form = true;
};

// True when the rounded s + sqrt(rad)/den (in that order of operations) is
// certainly >= K (an integer below 2^53), decided without the square root.
// Rounding is monotone and K is representable, so s + q >= K exactly suffices,
// q the rounded quotient. With d = K - s > 0 that holds when
// sqrt(rad) (1-u)^2 / den >= d (u = 2^-53: the square root and the quotient
// are rounded), i.e. rad >= (d den)^2 (1+u)^4; the test asks for a relative
// margin of 1e-12 over the rounded (d den)^2, far above the 6 ulps of rounding
// in d, d den and its square, with normal, finite operands. d <= 0: q >= 0.
bool surely_at_least(double s, double rad, double den, double K) noexcept {
  if (!std::isfinite(s) || !(rad >= 0) || !(rad <= std::numeric_limits<double>::max()) || !(den > 0) ||
      !(den <= std::numeric_limits<double>::max()))
    return false;
  const double d = K - s;
  if (d <= 0) return true;
  const double p = d * den;
  const double pp = p * p;
  return pp >= std::numeric_limits<double>::min() && pp <= std::numeric_limits<double>::max() &&
         rad >= pp * (1 + 1e-12);
}

// From a state below the BL (u = U+), the first sample k >= 1 at which the
// state is no longer below it. Along a trajectory of constant U+ "below" holds
// on a prefix only (docs/motion/nonlinear-filter.md), so the closed-form
// candidates are verified at k and k-1 and, should all fail, a bisection
// between the bounds k_lo and k_hi finds the index.
Entry entry_from_below(const ZState& z, const Frame& fr) noexcept {
  const ZBounds& zb = fr.b;
  const double up = zb.u_max;
  const double ub = -zb.u_min;
  // Necessary: z2_k >= z2- - U+ (the BL's lower edge is >= z2- - U+).
  // (When the numerator is <= 0 and U+ > 0 the quotient is <= 0 or NaN, and
  // ceil_nonneg gives 0 without it.)
  const double lo_num = zb.z2_min - up - z.z2;
  const double k_lo = fmax_libm(1.0, lo_num <= 0 && up > 0 ? 0.0 : ceil_nonneg(lo_num / up));
  // Sufficient: z2_k >= z2+ - U+ (the edge is <= z2+ - U+): eq. (18) + 1.
  const double k_hi = fmax_libm(1.0, ceil_nonneg((zb.z2_max - up - z.z2) / up));
  if (!(k_hi <= static_cast<double>(kMaxSteps))) return {};
  auto below = [&](double k) { return fr.below(after_constant(z, k, up)); };
  auto first = [&](double k) { return k >= k_lo && k <= k_hi && !below(k) && (k == 1 || below(k - 1)); };
  // Candidates: the necessary bound (mirror of z_d), eq. (20) rounded up
  // (eq. 21) and down (eq. 22), the crossing of z1 = 0 when (20) has no real
  // root, and the flat-part entry (eq. 18).
  if (first(k_lo)) return {k_lo};
  const double disc = z.z2 * z.z2 + up * z.z2 - 2 * up * z.z1;
  if (disc >= 0) {
    // k20 = s + sqrt(rad)/den, the operations of eq. (20) in their order. When
    // it is certainly >= k_hi + 1, both of its candidates lie beyond k_hi and
    // fail: the square root is skipped.
    const double s = -1 - z.z2 / up;
    const double rad = (up + ub) * ub * disc;
    const double den = up * (up + ub);
    if (!surely_at_least(s, rad, den, k_hi + 1)) {
      const double k20 = s + std::sqrt(rad) / den;
      if (first(std::ceil(k20))) return {std::ceil(k20)};
      if (first(std::floor(k20))) return {std::floor(k20)};
    }
  } else {
    const double k0 = std::floor((-up - z.z2) / up) + 1;
    if (first(k0)) return {k0};
  }
  if (first(k_hi)) return {k_hi};
  // Fallback: bisection for the first k in [k_lo, k_hi] that is not below.
  double lo = k_lo - 1, hi = k_hi;  // below(lo) or lo = k_lo - 1; !below(hi)
  while (hi - lo > 1) {
    const double mid = std::floor(0.5 * (lo + hi));
    (below(mid) ? lo : hi) = mid;
  }
  return {hi, false};
}

}  // namespace

// ---- validation and coordinates ----------------------------------------------

FilterState from_z(const ZState& z, const Reference& ref, double T) noexcept {
  const double y2 = T * z.z2;
  const double y1 = T * T * (z.z1 - 0.5 * z.z2);
  return {ref.r + y1, ref.v + y2};
}

double z1_plus(const ZBounds& zb) noexcept {
  if (!(zb.z2_max > 0)) return 0;
  const double q = std::floor(-zb.z2_max / zb.u_min);
  return -(q + 1) * (zb.z2_max + q * zb.u_min / 2);
}

double z1_minus(const ZBounds& zb) noexcept { return -z1_plus(mirror(zb)); }

// ---- plant --------------------------------------------------------------------

// ---- controller C ---------------------------------------------------------------

double approach_steps(double a) noexcept { return approach_steps_inl(a); }

double target_velocity(double z1, const ZBounds& zb) noexcept { return target_velocity_inl(z1, zb); }

double clamped_target_velocity(double z1, const ZBounds& zb) noexcept { return clamped_target_inl(z1, zb); }

double control(const ZState& z, const ZBounds& zb) noexcept {
  const double u = raw_control(z, zb);
  const double eps = accel_deadband(zb);
  if (u > zb.u_max + eps) return zb.u_max;
  if (u < zb.u_min - eps) return zb.u_min;
  return u;
}

FilterStep filter_step(const FilterState& s, const Reference& ref, const FilterBounds& b, double T) noexcept {
  const double u = control(to_z(s, ref, T), z_bounds(b, ref.v, T));
  return {plant_step(s, u, T), u};
}

// ---- predicates -----------------------------------------------------------------

bool in_boundary_layer(const ZState& z, const ZBounds& zb) noexcept {
  const double u = raw_control(z, zb);
  const double eps = accel_deadband(zb);
  return u <= zb.u_max + eps && u >= zb.u_min - eps;
}

bool in_final_approach(const ZState& z, const ZBounds& zb) noexcept {
  const double w = target_velocity(z.z1, zb);
  return in_boundary_layer(z, zb) && w <= zb.z2_max && w >= zb.z2_min;
}

// ---- transient time (Table I) ------------------------------------------------------

PreparedBounds prepare_bounds(const ZBounds& zb) noexcept {
  PreparedBounds pb;
  pb.zb = zb;
  pb.zb_m = mirror(zb);
  pb.eps = accel_deadband(pb.zb);
  pb.eps_m = accel_deadband(pb.zb_m);
  pb.tol = tracking_tolerance(pb.zb);
  pb.tol_m = tracking_tolerance(pb.zb_m);
  pb.z1p = z1_plus(pb.zb);
  pb.z1p_m = z1_plus(pb.zb_m);
  return pb;
}

TransientInfo transient_info(const ZState& z0, const ZBounds& zb) noexcept {
  return transient_info(z0, prepare_bounds(zb));
}

TransientInfo transient_info(const ZState& z0, const PreparedBounds& pb) noexcept {
  const ZBounds& zb = pb.zb;
  TransientInfo info;
  if (!(zb.z2_max >= 0 && zb.z2_min <= 0) || !std::isfinite(z0.z1) || !std::isfinite(z0.z2)) return info;
  if (std::fabs(z0.z1) <= pb.tol && std::fabs(z0.z2) <= pb.tol) {  // is_tracking(z0, zb)
    info.steps = 0;
    info.region = TransientRegion::Tracking;
    return info;
  }
  Targets targets(zb);
  const Frame plain(targets, pb, false);
  // 1. Full acceleration until the BL (z_d, z_e, z_f and their mirrors). In
  //    exact arithmetic one saturated phase at most; the loop tolerates a
  //    second one from rounding.
  ZState z = z0;
  double k_entry = 0;
  int sat = 0;  // +1: came from below (U+), -1: from above (U-), in the original frame
  bool closed_form = true;
  for (int phase = 0; phase < 3; ++phase) {
    Entry e;
    if (plain.below(z)) {
      e = entry_from_below(z, plain);
      if (e.k < 0) return info;
      z = after_constant(z, e.k, zb.u_max);
      sat = +1;
    } else if (plain.above(z)) {
      e = entry_from_below(mirror(z), Frame(targets, pb, true));
      if (e.k < 0) return info;
      z = after_constant(z, e.k, zb.u_min);
      sat = -1;
    } else {
      break;
    }
    k_entry += e.k;
    closed_form = closed_form && e.closed_form;
  }
  // 2. Inside the BL: the half decides the frame (mirror for z1 > 0).
  const bool mirrored = z.z1 > 0;
  const ZState zc = mirrored ? mirror(z) : z;
  const int sat_c = mirrored ? -sat : sat;
  const Layer layer = mirrored ? layer_left(zc, Frame(targets, pb, true)) : layer_left(zc, plain);
  if (layer.steps < 0) return info;
  const double total = k_entry + layer.steps;
  if (!(total <= static_cast<double>(kMaxSteps))) return info;
  info.steps = static_cast<std::int64_t>(total);
  info.mirrored = mirrored;
  info.k_entry = static_cast<std::int64_t>(k_entry);
  info.k_cruise = static_cast<std::int64_t>(layer.k_cruise);
  info.m = static_cast<std::int64_t>(layer.m);
  info.closed_form = closed_form && layer.closed_form;
  if (sat_c == 0) info.region = layer.flat ? (layer.on_bound ? TransientRegion::B : TransientRegion::C) : TransientRegion::A;
  else if (sat_c > 0) info.region = layer.flat ? TransientRegion::E : TransientRegion::F;
  else info.region = layer.flat ? TransientRegion::D : TransientRegion::G;
  return info;
}

std::int64_t transient_steps(const ZState& z, const ZBounds& zb) noexcept { return transient_info(z, zb).steps; }

std::int64_t transient_steps(const ZState& z, const PreparedBounds& pb) noexcept { return transient_info(z, pb).steps; }

std::int64_t transient_steps(const FilterState& s, const Reference& ref, const FilterBounds& b, double T) noexcept {
  return transient_steps(to_z(s, ref, T), z_bounds(b, ref.v, T));
}

}  // namespace syncplc::motion
