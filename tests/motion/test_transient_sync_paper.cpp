// Paper 004, Section III, Tables II-IV: three references with the bounds of
// Table II and six transients at t = 0, 2, 4, 5, 7, 8 s whose unsynchronized
// transient times are those of Table III.
//
// The paper does not publish its reference sequence (Fig. 5 shows it only as a
// plot), nor its sampling time. This reproduction assumes T = 1 ms (Table III
// has millisecond resolution) and steps from rest: for every signal and
// transient the step amplitude is chosen (by bisection on the Table I
// prediction) so that the filter's own transient time is exactly the Table III
// value; the signs of the steps are ours. The energies therefore cannot match
// Table IV; they are printed next to it. What must hold is what the paper
// claims: all transients of an event end together at the slowest one's time,
// the event with a single moving signal (t = 7 s) is unchanged, and E drops
// wherever a faster signal was slowed down.
#include <algorithm>
#include <array>
#include <cstdio>

#include "fblocks/motion/nonlinear_filter_math.hpp"
#include "tests/motion/transient_sync_test_util.hpp"

namespace syncplc::motion::synctest {
namespace {

constexpr double kT = 0.001;

struct PaperEvent {
  double t;                          // s
  std::array<int, 3> steps_ms;       // Table III (0: the signal does not move)
  std::array<int, 3> sign;           // our choice
  double e_async, e_sync;            // Table IV, m^2/s
};

const std::array<PaperEvent, 6> kEvents = {{
    {0.0, {722, 1040, 922}, {+1, +1, -1}, 47.78, 42.12},
    {2.0, {456, 887, 790}, {-1, +1, +1}, 31.88, 28.04},
    {4.0, {349, 475, 775}, {+1, -1, -1}, 16.10, 12.25},
    {5.0, {488, 430, 845}, {-1, -1, +1}, 20.41, 14.85},
    {7.0, {0, 0, 389}, {0, 0, -1}, 2.13, 2.13},
    {8.0, {490, 452, 0}, {+1, -1, 0}, 11.36, 10.88},
}};

std::int64_t steps_for(double D, const AxisBounds& b) {
  return transient_steps(FilterState{0, 0}, Reference{D, 0}, FilterBounds{b.v_min, b.v_max, b.a_min, b.a_max}, kT);
}

// The middle of the interval of step amplitudes (of the given sign) whose
// transient time from rest is exactly `steps` samples.
double amplitude_for(int steps, int sign, const AxisBounds& b) {
  auto first_at_least = [&](std::int64_t n) {
    double lo = 0, hi = 100;
    for (int k = 0; k < 200; ++k) {
      const double mid = 0.5 * (lo + hi);
      (steps_for(sign * mid, b) >= n ? hi : lo) = mid;
    }
    return hi;
  };
  return sign * 0.5 * (first_at_least(steps) + first_at_least(steps + 1));
}

TEST(TransientSyncPaper, TablesThreeAndFourSetting) {
  const auto bounds = table2();
  // Amplitudes that reproduce Table III exactly.
  std::array<std::array<double, 3>, 6> amp{};
  for (std::size_t e = 0; e < kEvents.size(); ++e)
    for (std::size_t i = 0; i < 3; ++i) {
      if (kEvents[e].steps_ms[i] == 0) continue;
      amp[e][i] = amplitude_for(kEvents[e].steps_ms[i], kEvents[e].sign[i], bounds[i]);
      ASSERT_EQ(steps_for(amp[e][i], bounds[i]), kEvents[e].steps_ms[i]) << "event " << e << " signal " << i + 1;
    }

  LockstepRig rig(3, kUnified, kT, bounds, 1);
  ASSERT_TRUE(rig.ok()) << rig.errors();
  rig.scan();  // scan 0: every filter starts on its reference (start_at_r); t = 0 is scan 1
  std::array<double, 3> level{};
  std::size_t next = 0;
  for (std::int64_t k = 0; k < 9000; ++k) {
    if (next < kEvents.size() && k == std::llround(kEvents[next].t / kT)) {
      for (std::size_t i = 0; i < 3; ++i) {
        level[i] += amp[next][i];
        rig.set_segment(static_cast<int>(i), level[i], 0);
      }
      rig.scan();
      // At the event scan each moving signal's own time (unsynchronized) is
      // its Table III value; synchronized, every moving signal arrives with
      // the slowest.
      const int slowest = *std::max_element(kEvents[next].steps_ms.begin(), kEvents[next].steps_ms.end());
      for (std::size_t i = 0; i < 3; ++i)
        if (kEvents[next].steps_ms[i] != 0) {
          EXPECT_EQ(rig.off().steps_to_go(static_cast<int>(i)), kEvents[next].steps_ms[i]);
          EXPECT_EQ(rig.test().steps_to_go(static_cast<int>(i)), slowest);
        }
      ++next;
      continue;
    }
    rig.scan();
  }
  ASSERT_EQ(next, kEvents.size());
  const auto& ws = rig.windows_test();
  const auto& wo = rig.windows_off();
  ASSERT_EQ(ws.size(), kEvents.size());
  ASSERT_EQ(wo.size(), kEvents.size());
  double es = 0, eo = 0, ps = 0, po = 0;
  std::printf("[ table IV ]  t (s)   slowest (ms)   E async   E sync   change  | paper: async    sync   change\n");
  for (std::size_t e = 0; e < kEvents.size(); ++e) {
    const auto& ev = kEvents[e];
    const int slowest = *std::max_element(ev.steps_ms.begin(), ev.steps_ms.end());
    const int movers = static_cast<int>(std::count_if(ev.steps_ms.begin(), ev.steps_ms.end(), [](int s) { return s > 0; }));
    EXPECT_EQ(wo[e].start, 1 + std::llround(ev.t / kT));
    EXPECT_EQ(wo[e].length, slowest) << "event at " << ev.t;  // Table III: the starred time
    EXPECT_EQ(ws[e].length, slowest) << "event at " << ev.t;  // not delayed
    EXPECT_EQ(ws[e].spread, 0) << "event at " << ev.t;       // all end together
    if (movers == 1) {
      EXPECT_EQ(ws[e].energy, wo[e].energy) << "event at " << ev.t;  // unchanged, as in Table IV
    } else {
      EXPECT_GT(wo[e].spread, 0) << "event at " << ev.t;  // unsynchronized, they end apart
      EXPECT_LT(ws[e].energy, wo[e].energy) << "event at " << ev.t;
    }
    std::printf("[ table IV ] %5.1f   %12d   %7.2f   %6.2f   %5.1f%%  |       %6.2f  %6.2f   %5.1f%%\n", ev.t, slowest,
                wo[e].energy, ws[e].energy, 100 * (ws[e].energy / wo[e].energy - 1), ev.e_async, ev.e_sync,
                100 * (ev.e_sync / ev.e_async - 1));
    es += ws[e].energy;
    eo += wo[e].energy;
    ps += ev.e_sync;
    po += ev.e_async;
  }
  std::printf("[ table IV ] total                   %7.2f   %6.2f   %5.1f%%  |       %6.2f  %6.2f   %5.1f%%\n", eo, es,
              100 * (es / eo - 1), po, ps, 100 * (ps / po - 1));
  EXPECT_EQ(rig.bounds_test().violations, 0) << rig.bounds_test().first;
  EXPECT_EQ(rig.output_mismatches, 0) << rig.first_mismatch;
  EXPECT_LT(es, eo);
}

}  // namespace
}  // namespace syncplc::motion::synctest
