// Minimum time, checked independently of the filter's formulas.
//
// For the discrete double integrator z1' = z1 + z2 + u, z2' = z2 + u with
// U- <= u <= U+ and the velocity bounds z2- <= z2 <= z2+ on every state, the
// set R_N of states from which the origin can be reached in N samples is a
// convex polygon, built backwards from R_0 = {0}:
//   R_{k+1} = { (p - v, v - u) : (p, v) in R_k, U- <= u <= U+ }  with z2 in [z2-, z2+],
// i.e. a shear of R_k, a Minkowski sum with a vertical segment, and a clip to
// the velocity slab. A state whose filter transient takes N samples must lie in
// R_N and outside R_{N-1}: no admissible control reaches the origin earlier.
// Nothing here uses the controller or Table I (only the simulation of the
// filter, through control(), to get N).
#include <array>
#include <cmath>
#include <cstdio>
#include <algorithm>
#include <vector>

#include "tests/motion/nonlinear_filter_test_util.hpp"

namespace syncplc::motion::test {
namespace {

struct Pt {
  double x, y;  // z1, z2
};
using Poly = std::vector<Pt>;  // convex, counter-clockwise; 1 or 2 points when degenerate

double cross(Pt o, Pt a, Pt b) { return (a.x - o.x) * (b.y - o.y) - (a.y - o.y) * (b.x - o.x); }

// Appends p unless it repeats the previous point.
void push(Poly& out, Pt p, double eps) {
  if (!out.empty() && std::fabs(out.back().x - p.x) <= eps && std::fabs(out.back().y - p.y) <= eps) return;
  out.push_back(p);
}

void close_dedup(Poly& p, double eps) {
  while (p.size() > 1 && std::fabs(p.back().x - p.front().x) <= eps && std::fabs(p.back().y - p.front().y) <= eps)
    p.pop_back();
}

// Keeps the part of p with sign * (y - level) >= 0 (Sutherland-Hodgman on one
// half-plane; works for points and segments as closed loops).
Poly clip(const Poly& p, double level, double sign, double eps) {
  Poly out;
  const std::size_t n = p.size();
  for (std::size_t i = 0; i < n; ++i) {
    const Pt a = p[i], b = p[(i + 1) % n];
    const double da = sign * (a.y - level), db = sign * (b.y - level);
    if (da >= 0) push(out, a, eps);
    if ((da >= 0) != (db >= 0)) {
      const double t = da / (da - db);
      push(out, {a.x + t * (b.x - a.x), level}, eps);
    }
  }
  close_dedup(out, eps);
  return out;
}

// R_{k+1} from R_k; `slab` false leaves out the velocity bounds of the new
// state (an initial state beyond them, after a bound reduction).
Poly backward(const Poly& r, const ZBounds& zb, double eps, bool slab = true) {
  Poly s;
  s.reserve(r.size());
  for (const Pt& q : r) s.push_back({q.x - q.y, q.y});  // shear: z1 = p - v
  // Minkowski sum with {(0, t) : -U+ <= t <= -U-}: the lower chain (leftmost
  // to rightmost, counter-clockwise) moves down by U+, the upper chain up by -U-.
  const std::size_t n = s.size();
  std::size_t lb = 0, rb = 0, rt = 0, lt = 0;
  for (std::size_t i = 1; i < n; ++i) {
    const Pt& q = s[i];
    if (q.x < s[lb].x || (q.x == s[lb].x && q.y < s[lb].y)) lb = i;
    if (q.x > s[rb].x || (q.x == s[rb].x && q.y < s[rb].y)) rb = i;
    if (q.x > s[rt].x || (q.x == s[rt].x && q.y > s[rt].y)) rt = i;
    if (q.x < s[lt].x || (q.x == s[lt].x && q.y > s[lt].y)) lt = i;
  }
  Poly m;
  m.reserve(n + 4);
  for (std::size_t i = lb;; i = (i + 1) % n) {
    push(m, {s[i].x, s[i].y - zb.u_max}, eps);
    if (i == rb) break;
  }
  for (std::size_t i = rt;; i = (i + 1) % n) {
    push(m, {s[i].x, s[i].y - zb.u_min}, eps);
    if (i == lt) break;
  }
  close_dedup(m, eps);
  if (!slab) return m;
  return clip(clip(m, zb.z2_min, 1, eps), zb.z2_max, -1, eps);
}

double dist_to_segment(Pt p, Pt a, Pt b) {
  const double dx = b.x - a.x, dy = b.y - a.y;
  const double l2 = dx * dx + dy * dy;
  double t = l2 > 0 ? ((p.x - a.x) * dx + (p.y - a.y) * dy) / l2 : 0;
  t = t < 0 ? 0 : (t > 1 ? 1 : t);
  return std::hypot(p.x - a.x - t * dx, p.y - a.y - t * dy);
}

// > 0 inside (distance to the nearest edge line), < 0 outside.
double signed_depth(const Poly& r, Pt p) {
  if (r.empty()) return -1e300;
  if (r.size() == 1) return -std::hypot(p.x - r[0].x, p.y - r[0].y);
  if (r.size() == 2) return -dist_to_segment(p, r[0], r[1]);
  double d = 1e300;
  for (std::size_t i = 0; i < r.size(); ++i) {
    const Pt a = r[i], b = r[(i + 1) % r.size()];
    const double len = std::hypot(b.x - a.x, b.y - a.y);
    if (len > 0) d = std::fmin(d, cross(a, b, p) / len);
  }
  return d;
}

TEST(NonlinearFilterMinimumTime, NoAdmissibleControlIsFaster) {
  Rng rng(3001);
  long cases = 0, ambiguous = 0, failures = 0, scans = 0;
  std::array<long, kRegionSlots> regions{};
  Poly r, prev;
  while (cases < 10000) {
    ZBounds zb;
    zb.u_max = rng.logu(0.5, 5);
    zb.u_min = -rng.logu(0.5, 5);
    zb.z2_max = rng.logu(0.2, 30);
    zb.z2_min = -rng.logu(0.2, 30);
    // A state within the velocity bounds.
    ZState z0{(rng.chance(0.5) ? -1 : 1) * rng.logu(0.01, 1500), rng.uni(zb.z2_min, zb.z2_max)};
    if (rng.chance(0.1)) z0.z2 = rng.chance(0.5) ? zb.z2_max : zb.z2_min;  // on a bound (cruise)
    const TransientInfo info = transient_info(z0, zb);
    if (info.steps < 1 || info.steps > 200) continue;  // keep the polygons small
    // The filter's own count, by simulation.
    ZState z = z0;
    std::int64_t n = 0;
    while (!is_tracking(z, zb) && n < 1000) {
      z = z_step(z, control(z, zb));
      ++n;
    }
    ASSERT_EQ(n, info.steps);
    // Ended inside the tolerance before the exact origin (probability ~1e-6): skip.
    if (std::fabs(z.z2) > 1e-3 * tracking_tolerance(zb)) continue;
    ++cases;
    scans += n;
    ++regions[static_cast<std::size_t>(region_slot(info))];
    const double scale = 1 + std::fabs(z0.z1) + std::fabs(z0.z2) + (zb.u_max - zb.u_min) * static_cast<double>(n * n);
    const double eps = 1e-14 * scale;
    const double margin = 1e-9 * scale;
    r.assign(1, Pt{0, 0});
    for (std::int64_t k = 0; k < n - 1; ++k) r = backward(r, zb, eps);
    prev = r;                   // R_{n-1}
    r = backward(r, zb, eps);  // R_n
    const Pt p{z0.z1, z0.z2};
    const double outside_prev = -signed_depth(prev, p);
    const double inside_now = signed_depth(r, p);
    if (std::fabs(outside_prev) <= margin) ++ambiguous;
    // Strictly: z0 is in R_n (the filter gets there) and not in R_{n-1}.
    const bool ok = outside_prev >= -margin && inside_now >= -margin;
    if (!ok && ++failures <= 5) {
      ADD_FAILURE() << "z0=(" << z0.z1 << ", " << z0.z2 << ") bounds z2 [" << zb.z2_min << ", " << zb.z2_max
                    << "] u [" << zb.u_min << ", " << zb.u_max << "] filter " << n << " samples; depth in R_n-1 "
                    << -outside_prev << ", in R_n " << inside_now;
    }
  }
  std::printf("  %ld minimum-time cases (%ld samples), %ld on the boundary of R_n-1 within the margin; regions:", cases,
              scans, ambiguous);
  for (int s = 0; s < kRegionSlots; ++s)
    if (regions[static_cast<std::size_t>(s)]) std::printf(" %s=%ld", region_name(s).c_str(), regions[static_cast<std::size_t>(s)]);
  std::printf("\n");
  EXPECT_EQ(failures, 0);
  EXPECT_LE(ambiguous, cases / 100);
}

// Beyond a velocity bound (after a run-time reduction) the filter brakes at
// the full acceleration bound until the velocity is back within the bound.
// Taking that as the rule for every admissible control (a velocity beyond a
// bound must fall by -U- per sample until one more sample can bring it
// within), the braking prefix is forced, the next state is free of the
// velocity bounds and all later ones are within them: compare the filter with
// the fastest such control.
TEST(NonlinearFilterMinimumTime, BeyondAReducedBound) {
  Rng rng(3002);
  long cases = 0, longer = 0, extra_max = 0;
  std::array<long, kRegionSlots> regions{};
  Poly r;
  while (cases < 3000) {
    ZBounds zb;
    zb.u_max = rng.logu(0.5, 5);
    zb.u_min = -rng.logu(0.5, 5);
    zb.z2_max = rng.logu(0.2, 30);
    zb.z2_min = -rng.logu(0.2, 30);
    // Faster than z2+ (the mirror case is the same by symmetry).
    const ZState z0{(rng.chance(0.5) ? -1 : 1) * rng.logu(0.01, 1500), zb.z2_max + rng.logu(0.01, 10) * -zb.u_min};
    const TransientInfo info = transient_info(z0, zb);
    const std::int64_t n = info.steps;
    if (n < 1 || n > 200) continue;
    ++cases;
    ++regions[static_cast<std::size_t>(region_slot(info))];
    // The forced braking prefix.
    ZState z = z0;
    std::int64_t j = 0;
    while (z.z2 + zb.u_min > zb.z2_max) {
      z = z_step(z, zb.u_min);
      ++j;
    }
    const double scale = 1 + std::fabs(z0.z1) + std::fabs(z0.z2) + (zb.u_max - zb.u_min) * static_cast<double>(n * n);
    const double eps = 1e-14 * scale, margin = 1e-9 * scale;
    std::int64_t best = -1;
    r.assign(1, Pt{0, 0});
    for (std::int64_t k = 0; j + k < n && best < 0; ++k) {
      if (signed_depth(backward(r, zb, eps, false), {z.z1, z.z2}) >= -margin) best = j + k + 1;
      r = backward(r, zb, eps);
    }
    if (best < 0 || best < n) {
      ++longer;
      extra_max = std::max<long>(extra_max, best < 0 ? -1 : n - best);
      ADD_FAILURE() << "z0=(" << z0.z1 << ", " << z0.z2 << ") filter " << n << " fastest " << best;
    }
  }
  std::printf("  %ld states beyond z2+, %ld not minimum time; regions:", cases, longer);
  for (int s = 0; s < kRegionSlots; ++s)
    if (regions[static_cast<std::size_t>(s)]) std::printf(" %s=%ld", region_name(s).c_str(), regions[static_cast<std::size_t>(s)]);
  std::printf("\n");
  EXPECT_EQ(longer, 0);
}

// The polygon method itself: for a pure acceleration-bounded problem with
// symmetric bounds the minimum time from rest at distance d is known in closed
// form: the smallest N with d <= U * floor(N^2/4) (bang-bang over N samples).
TEST(NonlinearFilterMinimumTime, PolygonMethodMatchesBangBang) {
  const ZBounds zb{-1e9, 1e9, -1, 1};
  for (int n = 1; n <= 40; ++n) {
    Poly r(1, Pt{0, 0});
    for (int k = 0; k < n; ++k) r = backward(r, zb, 1e-12);
    // From rest at z1 = -d (z2 = 0): reachable in n samples iff d <= floor(n^2/4).
    const double reach = std::floor(n * n / 4.0);
    EXPECT_GE(signed_depth(r, {-reach, 0}), -1e-9) << n;
    EXPECT_LT(signed_depth(r, {-reach - 1e-3, 0}), 0) << n;
  }
}

}  // namespace
}  // namespace syncplc::motion::test
