// Randomized properties of the nonlinear filter of paper 004 (Section II),
// simulated in the original coordinates exactly as NONLINEAR_FILTER runs it:
//   - the predicted transient time (Table I) equals the scans actually taken,
//     at every scan of every transient, in every region of Table I and its
//     mirror image;
//   - the velocity and acceleration bounds are never exceeded (a velocity
//     beyond a newly reduced bound is braked at the full acceleration bound);
//   - a step is reached without overshoot;
//   - a reference faster than the velocity bounds is never tracked and the
//     prediction says so.
// Seeded std::mt19937_64: every run checks the same cases.
#include <array>
#include <cstdio>
#include <vector>

#include "tests/motion/nonlinear_filter_test_util.hpp"

namespace syncplc::motion::test {
namespace {

// Per-scan checks of the bounds; counts violations, reports the first few.
struct BoundChecker {
  long violations = 0;
  long braking_scans = 0;  // scans that started beyond a velocity bound

  void check(const FilterState& before, const FilterStep& st, const FilterBounds& b, double T, double r_dot,
             const char* where, long id) {
    const double ta = accel_tolerance(b);
    const double tv = velocity_tolerance(b, r_dot);
    bool ok = st.u <= b.a_max + ta && st.u >= b.a_min - ta;
    // Within the bounds the velocity stays within them; beyond a bound it
    // moves back at the full acceleration bound (or lands on the bound).
    const double v = st.next.v;
    const double hi = before.v > b.v_max + tv ? std::fmax(b.v_max, before.v + T * b.a_min) : b.v_max;
    const double lo = before.v < b.v_min - tv ? std::fmin(b.v_min, before.v + T * b.a_max) : b.v_min;
    if (before.v > b.v_max + tv || before.v < b.v_min - tv) ++braking_scans;
    ok = ok && v <= hi + tv && v >= lo - tv;
    if (!ok && ++violations <= 5) {
      ADD_FAILURE() << where << " case " << id << ": v " << before.v << " -> " << v << " u " << st.u << " bounds ["
                    << b.v_min << ", " << b.v_max << "] [" << b.a_min << ", " << b.a_max << "]";
    }
  }
};

struct RegionTally {
  std::array<long, kRegionSlots> n{};
  void add(const TransientInfo& i) { ++n[static_cast<std::size_t>(region_slot(i))]; }
  void print(const char* what) const {
    std::printf("  %s:", what);
    for (int s = 0; s < kRegionSlots; ++s)
      if (n[static_cast<std::size_t>(s)]) std::printf(" %s=%ld", region_name(s).c_str(), n[static_cast<std::size_t>(s)]);
    std::printf("\n");
  }
  long at(TransientRegion r, bool mirrored) const { return n[static_cast<std::size_t>(2 * static_cast<int>(r) + mirrored)]; }
};

// ---------------------------------------------------------------------------
// The prediction equals the scans taken, from every scan of the transient.

TEST(NonlinearFilterRandom, PredictionEqualsScansTakenAtEveryScan) {
  Rng rng(2001);
  BoundChecker bc;
  RegionTally regions;
  long cases = 0, scans = 0, mismatches = 0, searched = 0, never_cases = 0;
  std::vector<std::int64_t> pred;
  pred.reserve(30000);
  for (int c = 0; c < 30000; ++c) {
    const double T = random_period(rng);
    const FilterBounds b = random_bounds(rng, T);
    double r_dot = random_slope(rng, b);
    if (rng.chance(0.03)) r_dot = rng.chance(0.5) ? b.v_max : b.v_min;  // on a bound: one side never tracks
    Reference ref{rng.uni(-1, 1), r_dot};
    // An offset that keeps the cruise to about 150 scans (x behind: dir = 1).
    const int dir = rng.chance(0.5) ? 1 : -1;
    const double reach = 150 * T * std::fmax(closing_speed(b, r_dot, dir), 0.01 * (b.v_max - b.v_min));
    FilterState s{ref.r - dir * rng.uni(0, 1) * reach, 0};
    const double vspan = std::fmax(b.v_max, -b.v_min);
    const double pick = rng.uni(0, 1);
    if (pick < 0.5) s.v = rng.uni(b.v_min, b.v_max);           // within the bounds
    else if (pick < 0.8) s.v = rng.uni(-1.5, 1.5) * vspan;     // often beyond one of them
    else s.v = r_dot;                                          // a step from tracking
    pred.clear();
    std::int64_t arrival = -1;
    const std::int64_t cap = 2500;
    for (std::int64_t k = 0; k <= cap; ++k) {
      const ZBounds zb = z_bounds(b, ref.v, T);
      const ZState z = to_z(s, ref, T);
      const TransientInfo info = transient_info(z, zb);
      if (!info.closed_form) ++searched;
      regions.add(info);
      pred.push_back(info.steps);
      if (is_tracking(z, zb)) {
        arrival = k;
        break;
      }
      const FilterStep st = filter_step(s, ref, b, T);
      bc.check(s, st, b, T, ref.v, "prediction", c);
      s = st.next;
      ref.r += T * ref.v;
    }
    ++cases;
    scans += static_cast<long>(pred.size());
    if (arrival < 0) {
      ++never_cases;
      // Not tracked within the cap: only a reference on a velocity bound may do that.
      for (std::size_t i = 0; i < pred.size(); ++i) {
        if (pred[i] != kNever && pred[i] <= cap - static_cast<std::int64_t>(i)) {
          if (++mismatches <= 5) ADD_FAILURE() << "case " << c << " scan " << i << ": predicted " << pred[i] << ", not tracking after " << cap;
          break;
        }
      }
      continue;
    }
    for (std::size_t i = 0; i < pred.size(); ++i) {
      const std::int64_t actual = arrival - static_cast<std::int64_t>(i);
      if (pred[i] != actual) {
        if (++mismatches <= 5) ADD_FAILURE() << "case " << c << " scan " << i << ": predicted " << pred[i] << ", took " << actual;
      }
    }
  }
  std::printf("  %ld cases, %ld scans predicted, %ld never tracking, %ld braking scans, %ld searched indices\n", cases,
              scans, never_cases, bc.braking_scans, searched);
  regions.print("regions at every scan");
  EXPECT_EQ(mismatches, 0);
  EXPECT_EQ(bc.violations, 0);
  EXPECT_EQ(searched, 0);  // the closed forms (with their k/k-1 check) always hit
  EXPECT_GT(never_cases, 100);
  EXPECT_GT(bc.braking_scans, 10000);
  for (auto r : {TransientRegion::A, TransientRegion::B, TransientRegion::C, TransientRegion::D, TransientRegion::E,
                 TransientRegion::F}) {
    for (bool m : {false, true}) {
      EXPECT_GE(regions.at(r, m), 1000) << region_name(2 * static_cast<int>(r) + m);
    }
  }
  EXPECT_GE(regions.at(TransientRegion::G, false) + regions.at(TransientRegion::G, true), 10);
  EXPECT_GE(regions.at(TransientRegion::Never, false), 1000);
}

// ---------------------------------------------------------------------------
// Steps, ramps and bound changes at random scans, mid-transient.

TEST(NonlinearFilterRandom, BoundsHoldAndPredictionsHoldThroughChanges) {
  Rng rng(2002);
  BoundChecker bc;
  RegionTally regions;
  long segments = 0, reached = 0, mismatches = 0, bound_changes = 0, reductions_below_v = 0, scans = 0, searched = 0;
  std::vector<std::int64_t> pred;
  pred.reserve(256);
  for (int c = 0; c < 10000; ++c) {
    const double T = random_period(rng);
    FilterBounds b = random_bounds(rng, T);
    Reference ref{rng.uni(-1, 1), random_slope(rng, b)};
    FilterState s{ref.r, ref.v};
    for (int seg = 0; seg < 6; ++seg) {
      // Change something at this scan.
      const double what = rng.uni(0, 1);
      const double reach = 60 * T * (b.v_max - b.v_min);
      if (what < 0.35) {
        ref.r += rng.uni(-1, 1) * reach;  // step
      } else if (what < 0.6) {
        ref.v = random_slope(rng, b);  // new ramp
        if (rng.chance(0.5)) ref.r += rng.uni(-1, 1) * reach;
      } else {
        b = random_bounds(rng, T);  // new bounds (the reference keeps going)
        ++bound_changes;
        if (s.v > b.v_max || s.v < b.v_min) ++reductions_below_v;
        if (ref.v > b.v_max || ref.v < b.v_min) ref.v = random_slope(rng, b);
        if (rng.chance(0.3)) ref.r += rng.uni(-1, 1) * reach;
      }
      const int len = rng.integer(1, 100);
      pred.clear();
      std::int64_t arrival = -1;
      for (int k = 0; k < len; ++k) {
        const ZBounds zb = z_bounds(b, ref.v, T);
        const ZState z = to_z(s, ref, T);
        const TransientInfo info = transient_info(z, zb);
        if (!info.closed_form) ++searched;
        regions.add(info);
        pred.push_back(info.steps);
        const bool tr = is_tracking(z, zb);
        if (tr && arrival < 0) arrival = k;
        if (!tr && arrival >= 0 && ++mismatches <= 5) ADD_FAILURE() << "case " << c << ": lost tracking";
        const FilterStep st = filter_step(s, ref, b, T);
        bc.check(s, st, b, T, ref.v, "changes", c);
        s = st.next;
        ref.r += T * ref.v;
      }
      ++segments;
      scans += len;
      const std::int64_t end = arrival >= 0 ? arrival : static_cast<std::int64_t>(pred.size());
      if (arrival >= 0) ++reached;
      for (std::int64_t i = 0; i < end; ++i) {
        const std::int64_t p = pred[static_cast<std::size_t>(i)];
        // Tracked in this segment: exactly the scans taken; not yet: more than remain.
        const bool ok = arrival >= 0 ? p == arrival - i : (p == kNever ? false : p > end - i - 1);
        if (!ok && ++mismatches <= 5) {
          ADD_FAILURE() << "case " << c << " segment " << seg << " scan " << i << ": predicted " << p
                        << (arrival >= 0 ? ", took " + std::to_string(arrival - i) : ", not reached in segment");
        }
      }
    }
  }
  std::printf("  %ld segments (%ld scans), %ld tracked within the segment, %ld bound changes (%ld below the velocity), "
              "%ld braking scans\n",
              segments, scans, reached, bound_changes, reductions_below_v, bc.braking_scans);
  regions.print("regions");
  EXPECT_EQ(mismatches, 0);
  EXPECT_EQ(bc.violations, 0);
  EXPECT_EQ(searched, 0);
  EXPECT_GT(reductions_below_v, 1000);
  EXPECT_GT(bc.braking_scans, 1000);
  EXPECT_GT(reached, 10000);
}

// ---------------------------------------------------------------------------
// A step from tracking (same slope before and after) is reached without
// overshoot: x - r keeps its sign and its size never grows.

TEST(NonlinearFilterRandom, StepFromTrackingHasNoOvershoot) {
  Rng rng(2003);
  long cases = 0, failures = 0, scans = 0;
  for (int c = 0; c < 30000; ++c) {
    const double T = random_period(rng);
    const FilterBounds b = random_bounds(rng, T);
    Reference ref{rng.uni(-1, 1), random_slope(rng, b)};
    FilterState s{ref.r, ref.v};
    const int dir = rng.chance(0.5) ? 1 : -1;  // the step puts r ahead of x (1) or behind
    const double step = dir * rng.uni(0, 1) * 100 * T * closing_speed(b, ref.v, dir);
    ref.r += step;
    const ZBounds zb0 = z_bounds(b, ref.v, T);
    // Position slack: the tracking tolerance in y1 plus the rounding of x and r.
    const double slack = 2 * T * T * tracking_tolerance(zb0) + 1e-13 * (1 + std::fabs(ref.r) + std::fabs(s.x));
    const double sign = step > 0 ? 1 : -1;  // x - r starts at -step
    const std::int64_t predicted = transient_steps(to_z(s, ref, T), zb0);
    double prev = std::fabs(s.x - ref.r);
    std::int64_t k = 0;
    double overshoot = 0, growth = 0;
    while (!tracking(s, ref, b, T) && k < 100000) {
      s = filter_step(s, ref, b, T).next;
      ref.r += T * ref.v;
      ++k;
      const double y = s.x - ref.r;
      overshoot = std::fmax(overshoot, sign * y);
      growth = std::fmax(growth, std::fabs(y) - prev);
      prev = std::fabs(y);
    }
    bool ok = k == predicted && overshoot <= slack && growth <= slack;
    // And it stays there.
    for (int j = 0; j < 3 && ok; ++j) {
      s = filter_step(s, ref, b, T).next;
      ref.r += T * ref.v;
      ok = tracking(s, ref, b, T);
    }
    ++cases;
    scans += k;
    if (!ok && ++failures <= 5) ADD_FAILURE() << "case " << c << ": step " << step << " scans " << k << " predicted " << predicted << " overshoot " << overshoot << " growth " << growth << " slack " << slack;
  }
  std::printf("  %ld steps, %ld scans\n", cases, scans);
  EXPECT_EQ(failures, 0);
}

// ---------------------------------------------------------------------------
// A reference faster than a velocity bound: "never", the output runs at that
// bound, the acceleration bound holds.

TEST(NonlinearFilterRandom, ReferenceBeyondTheVelocityBoundsIsNeverTracked) {
  Rng rng(2004);
  long failures = 0;
  for (int c = 0; c < 5000; ++c) {
    const double T = random_period(rng);
    const FilterBounds b = random_bounds(rng, T);
    const double excess = rng.uni(0.01, 1) * (b.v_max - b.v_min);
    Reference ref{rng.uni(-1, 1), rng.chance(0.5) ? b.v_max + excess : b.v_min - excess};
    const double bound = ref.v > b.v_max ? b.v_max : b.v_min;
    // Behind the reference (ahead of it, the reference first catches up).
    FilterState s{ref.r - (ref.v > b.v_max ? 1 : -1) * rng.uni(0, 0.5), rng.uni(b.v_min, b.v_max)};
    // Long enough to reach the bound from the other one.
    const int horizon = 20 + static_cast<int>((b.v_max - b.v_min) / std::fmin(b.a_max, -b.a_min) / T);
    BoundChecker bc;
    bool ok = true;
    for (int k = 0; k < horizon; ++k) {
      const ZState z = to_z(s, ref, T);
      const ZBounds zb = z_bounds(b, ref.v, T);
      ok = ok && transient_steps(z, zb) == kNever && !is_tracking(z, zb);
      const FilterStep st = filter_step(s, ref, b, T);
      bc.check(s, st, b, T, ref.v, "never", c);
      s = st.next;
      ref.r += T * ref.v;
    }
    // Then the output moves at the bound the reference exceeds.
    ok = ok && bc.violations == 0 && std::fabs(s.v - bound) <= velocity_tolerance(b, ref.v);
    if (!ok && ++failures <= 5) ADD_FAILURE() << "case " << c << ": v " << s.v << " bound " << bound;
  }
  EXPECT_EQ(failures, 0);
}

}  // namespace
}  // namespace syncplc::motion::test
