// TON, TOF, TP: IEC semantics driven by the scan's planned release time.
#include "tests/iec/iec_test_util.hpp"

namespace syncplc::iectest {
namespace {

struct Timer {
  BlockHarness h;
  explicit Timer(const char* type, std::int64_t pt) : h(registry(), type, opts()) {
    h.set<std::int64_t>("PT", pt);
  }
  // One scan at absolute time t (ns) with the given IN.
  void at(std::int64_t t, bool in) {
    h.set_now_ns(t);
    h.set<bool>("IN", in);
    h.scan();
  }
  bool q() { return h.get<bool>("Q"); }
  std::int64_t et() { return h.get<std::int64_t>("ET"); }
  void pt(std::int64_t v) { h.set<std::int64_t>("PT", v); }
};

// ---- TON -------------------------------------------------------------------

TEST(Ton, DelaysRisingEdgeByPt) {
  Timer t("TON", ms(5));
  ASSERT_HARNESS_OK(t.h);
  t.at(ms(0), false);
  EXPECT_FALSE(t.q());
  EXPECT_EQ(t.et(), 0);
  t.at(ms(1), true);  // timing starts at 1 ms
  EXPECT_FALSE(t.q());
  EXPECT_EQ(t.et(), 0);
  for (int k = 2; k <= 5; ++k) {
    t.at(ms(k), true);
    EXPECT_FALSE(t.q()) << k;
    EXPECT_EQ(t.et(), ms(k - 1)) << k;
  }
  t.at(ms(6), true);  // elapsed = 5 ms = PT
  EXPECT_TRUE(t.q());
  EXPECT_EQ(t.et(), ms(5));
  t.at(ms(50), true);  // ET stays clamped at PT
  EXPECT_TRUE(t.q());
  EXPECT_EQ(t.et(), ms(5));
  t.at(ms(51), false);  // IN FALSE resets
  EXPECT_FALSE(t.q());
  EXPECT_EQ(t.et(), 0);
}

TEST(Ton, InTrueOnFirstScanStartsTiming) {
  Timer t("TON", ms(3));
  t.at(0, true);
  EXPECT_FALSE(t.q());
  t.at(ms(2), true);
  EXPECT_FALSE(t.q());
  EXPECT_EQ(t.et(), ms(2));
  t.at(ms(3), true);
  EXPECT_TRUE(t.q());
}

TEST(Ton, InDroppingMidTimingRestartsFromZero) {
  Timer t("TON", ms(5));
  t.at(ms(0), true);
  t.at(ms(4), true);
  EXPECT_EQ(t.et(), ms(4));
  t.at(ms(5), false);  // dropped one scan before it would have expired
  EXPECT_FALSE(t.q());
  EXPECT_EQ(t.et(), 0);
  t.at(ms(6), true);  // restart at 6 ms
  EXPECT_EQ(t.et(), 0);
  t.at(ms(10), true);
  EXPECT_FALSE(t.q());
  EXPECT_EQ(t.et(), ms(4));
  t.at(ms(11), true);
  EXPECT_TRUE(t.q());
}

TEST(Ton, LoweringPtBelowElapsedSetsQAtOnce) {
  Timer t("TON", ms(10));
  t.at(ms(0), true);
  t.at(ms(6), true);
  EXPECT_FALSE(t.q());
  EXPECT_EQ(t.et(), ms(6));
  t.pt(ms(4));
  t.at(ms(7), true);
  EXPECT_TRUE(t.q());
  EXPECT_EQ(t.et(), ms(4));  // clamped to the new PT
}

TEST(Ton, RaisingPtWhileQTrueDropsQAndEtContinues) {
  Timer t("TON", ms(5));
  t.at(ms(0), true);
  t.at(ms(7), true);
  EXPECT_TRUE(t.q());
  EXPECT_EQ(t.et(), ms(5));
  t.pt(ms(10));
  t.at(ms(8), true);
  EXPECT_FALSE(t.q());  // CODESYS behaviour: Q falls back
  EXPECT_EQ(t.et(), ms(8));  // the true elapsed time since the start
  t.at(ms(9), true);
  EXPECT_FALSE(t.q());
  EXPECT_EQ(t.et(), ms(9));
  t.at(ms(10), true);
  EXPECT_TRUE(t.q());
  EXPECT_EQ(t.et(), ms(10));
}

TEST(Ton, ZeroPtGivesQOnTheRisingScan) {
  Timer t("TON", 0);
  t.at(ms(0), false);
  EXPECT_FALSE(t.q());
  t.at(ms(1), true);
  EXPECT_TRUE(t.q());
  EXPECT_EQ(t.et(), 0);
  t.at(ms(2), false);
  EXPECT_FALSE(t.q());
}

TEST(Ton, NegativePtActsAsZero) {
  Timer t("TON", -ms(5));
  t.at(ms(0), true);
  EXPECT_TRUE(t.q());
  EXPECT_EQ(t.et(), 0);
}

TEST(Ton, FollowsTimeNotScanCount) {
  // Only three scans: skipped scans (dt of several periods) do not stretch it.
  Timer t("TON", ms(10));
  t.at(ms(0), true);
  t.at(ms(7), true);
  EXPECT_FALSE(t.q());
  EXPECT_EQ(t.et(), ms(7));
  t.at(ms(25), true);
  EXPECT_TRUE(t.q());
  EXPECT_EQ(t.et(), ms(10));
}

TEST(Ton, IrregularScanTimesWithFinePeriod) {
  Timer t("TON", 1500 * kUs);
  t.at(0, true);
  t.at(700 * kUs, true);
  EXPECT_EQ(t.et(), 700 * kUs);
  t.at(1499 * kUs, true);
  EXPECT_FALSE(t.q());
  t.at(1500 * kUs, true);
  EXPECT_TRUE(t.q());
  EXPECT_EQ(t.et(), 1500 * kUs);
}

TEST(Ton, WorksWithLargeAbsoluteTimes) {
  Timer t("TON", ms(2));
  const std::int64_t base = 9'000'000'000'000'000'000;  // ~285 years in ns
  t.at(base, true);
  t.at(base + ms(1), true);
  EXPECT_FALSE(t.q());
  t.at(base + ms(2), true);
  EXPECT_TRUE(t.q());
}

TEST(Ton, PeriodicHarnessScans) {
  BlockHarness h(registry(), "TON", opts(std::nullopt, std::nullopt, ms(1)));
  h.set<std::int64_t>("PT", ms(3));
  h.set<bool>("IN", true);
  h.scans(3);  // t = 0, 1, 2 ms
  EXPECT_FALSE(h.get<bool>("Q"));
  h.scan();  // t = 3 ms
  EXPECT_TRUE(h.get<bool>("Q"));
}

// ---- TOF -------------------------------------------------------------------

TEST(Tof, StartsOffAndWithoutDelay) {
  Timer t("TOF", ms(5));
  ASSERT_HARNESS_OK(t.h);
  t.at(ms(0), false);
  EXPECT_FALSE(t.q());
  EXPECT_EQ(t.et(), 0);
  t.at(ms(10), false);
  EXPECT_FALSE(t.q());
}

TEST(Tof, HoldsQForPtAfterFallingEdge) {
  Timer t("TOF", ms(5));
  t.at(ms(0), true);
  EXPECT_TRUE(t.q());
  EXPECT_EQ(t.et(), 0);
  t.at(ms(1), true);
  t.at(ms(2), false);  // falling edge at 2 ms
  EXPECT_TRUE(t.q());
  EXPECT_EQ(t.et(), 0);
  t.at(ms(6), false);
  EXPECT_TRUE(t.q());
  EXPECT_EQ(t.et(), ms(4));
  t.at(ms(7), false);
  EXPECT_FALSE(t.q());
  EXPECT_EQ(t.et(), ms(5));
  t.at(ms(20), false);  // ET holds PT
  EXPECT_FALSE(t.q());
  EXPECT_EQ(t.et(), ms(5));
  t.at(ms(21), true);  // rising IN resets ET
  EXPECT_TRUE(t.q());
  EXPECT_EQ(t.et(), 0);
}

TEST(Tof, RisingInDuringDelayResetsEt) {
  Timer t("TOF", ms(5));
  t.at(ms(0), true);
  t.at(ms(1), false);
  t.at(ms(4), false);
  EXPECT_EQ(t.et(), ms(3));
  t.at(ms(5), true);
  EXPECT_TRUE(t.q());
  EXPECT_EQ(t.et(), 0);
  t.at(ms(6), false);  // full delay again from 6 ms
  t.at(ms(10), false);
  EXPECT_TRUE(t.q());
  t.at(ms(11), false);
  EXPECT_FALSE(t.q());
}

TEST(Tof, ZeroPtDropsQOnTheFallingScan) {
  Timer t("TOF", 0);
  t.at(ms(0), true);
  EXPECT_TRUE(t.q());
  t.at(ms(1), false);
  EXPECT_FALSE(t.q());
  EXPECT_EQ(t.et(), 0);
}

TEST(Tof, PtChangedWhileTiming) {
  Timer t("TOF", ms(5));
  t.at(ms(0), true);
  t.at(ms(1), false);
  t.at(ms(4), false);
  t.pt(ms(10));  // raise: delay extended
  t.at(ms(8), false);
  EXPECT_TRUE(t.q());
  EXPECT_EQ(t.et(), ms(7));
  t.pt(ms(6));  // lower below elapsed: ends at once
  t.at(ms(9), false);
  EXPECT_FALSE(t.q());
  EXPECT_EQ(t.et(), ms(6));
  t.pt(ms(100));  // after expiry: no effect until IN rises again
  t.at(ms(10), false);
  EXPECT_FALSE(t.q());
}

TEST(Tof, FollowsTimeNotScanCount) {
  Timer t("TOF", ms(10));
  t.at(ms(0), true);
  t.at(ms(1), false);
  t.at(ms(30), false);  // a single late scan ends the delay
  EXPECT_FALSE(t.q());
  EXPECT_EQ(t.et(), ms(10));
}

// ---- TP --------------------------------------------------------------------

TEST(Tp, PulseOfLengthPt) {
  Timer t("TP", ms(5));
  ASSERT_HARNESS_OK(t.h);
  t.at(ms(0), false);
  EXPECT_FALSE(t.q());
  t.at(ms(1), true);  // pulse from 1 ms to 6 ms
  EXPECT_TRUE(t.q());
  EXPECT_EQ(t.et(), 0);
  t.at(ms(5), true);
  EXPECT_TRUE(t.q());
  EXPECT_EQ(t.et(), ms(4));
  t.at(ms(6), true);
  EXPECT_FALSE(t.q());
  EXPECT_EQ(t.et(), ms(5));
  t.at(ms(9), true);  // ET holds PT while IN is still TRUE; no new pulse
  EXPECT_FALSE(t.q());
  EXPECT_EQ(t.et(), ms(5));
  t.at(ms(10), false);  // pulse over and IN FALSE: ET resets
  EXPECT_FALSE(t.q());
  EXPECT_EQ(t.et(), 0);
  t.at(ms(11), true);  // a new rising edge: a new pulse
  EXPECT_TRUE(t.q());
  EXPECT_EQ(t.et(), 0);
}

TEST(Tp, InTrueOnFirstScanStartsPulse) {
  Timer t("TP", ms(2));
  t.at(0, true);
  EXPECT_TRUE(t.q());
  t.at(ms(2), true);
  EXPECT_FALSE(t.q());
}

TEST(Tp, RetriggerDuringPulseIsIgnored) {
  Timer t("TP", ms(5));
  t.at(ms(0), true);
  t.at(ms(1), false);
  EXPECT_TRUE(t.q());  // IN dropping does not end the pulse
  t.at(ms(2), true);   // new edge during the pulse: ignored
  EXPECT_TRUE(t.q());
  EXPECT_EQ(t.et(), ms(2));
  t.at(ms(4), true);
  EXPECT_EQ(t.et(), ms(4));
  t.at(ms(5), true);  // ends at 5 ms, measured from the first edge
  EXPECT_FALSE(t.q());
  EXPECT_EQ(t.et(), ms(5));
  t.at(ms(6), true);  // the edge was during the pulse: no second pulse
  EXPECT_FALSE(t.q());
}

TEST(Tp, InDroppingMidPulseResetsEtAtPulseEnd) {
  Timer t("TP", ms(3));
  t.at(ms(0), true);
  t.at(ms(1), false);
  EXPECT_TRUE(t.q());
  EXPECT_EQ(t.et(), ms(1));
  t.at(ms(2), false);
  EXPECT_TRUE(t.q());
  EXPECT_EQ(t.et(), ms(2));
  t.at(ms(3), false);  // pulse over with IN FALSE
  EXPECT_FALSE(t.q());
  EXPECT_EQ(t.et(), 0);
}

TEST(Tp, ZeroPtGivesNoPulse) {
  Timer t("TP", 0);
  t.at(ms(0), true);
  EXPECT_FALSE(t.q());
  EXPECT_EQ(t.et(), 0);
  t.at(ms(1), true);
  EXPECT_FALSE(t.q());
}

TEST(Tp, PtChangedDuringPulse) {
  Timer t("TP", ms(10));
  t.at(ms(0), true);
  t.at(ms(3), true);
  t.pt(ms(5));  // lowered but still above elapsed: pulse now ends at 5 ms
  t.at(ms(4), true);
  EXPECT_TRUE(t.q());
  t.at(ms(5), true);
  EXPECT_FALSE(t.q());
  EXPECT_EQ(t.et(), ms(5));
}

TEST(Tp, PtLoweredBelowElapsedEndsPulse) {
  Timer t("TP", ms(10));
  t.at(ms(0), true);
  t.at(ms(6), true);
  EXPECT_TRUE(t.q());
  t.pt(ms(2));
  t.at(ms(7), true);
  EXPECT_FALSE(t.q());
  EXPECT_EQ(t.et(), ms(2));
}

TEST(Tp, FollowsTimeNotScanCount) {
  Timer t("TP", ms(10));
  t.at(ms(0), true);
  EXPECT_TRUE(t.q());
  t.at(ms(9), true);
  EXPECT_TRUE(t.q());
  EXPECT_EQ(t.et(), ms(9));
  t.at(ms(40), false);  // many periods skipped: pulse over, IN FALSE
  EXPECT_FALSE(t.q());
  EXPECT_EQ(t.et(), 0);
}

}  // namespace
}  // namespace syncplc::iectest
