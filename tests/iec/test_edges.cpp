// R_TRIG, F_TRIG: one-scan pulses, first-scan behaviour.
#include <vector>

#include "tests/iec/iec_test_util.hpp"

namespace syncplc::iectest {
namespace {

std::vector<bool> run(const char* type, const std::vector<bool>& clk) {
  BlockHarness h(registry(), type);
  EXPECT_TRUE(h.ok()) << errors_of(h);
  std::vector<bool> q;
  for (bool c : clk) {
    h.set<bool>("CLK", c);
    h.scan();
    q.push_back(h.get<bool>("Q"));
  }
  return q;
}

TEST(RTrig, OneScanPulsePerRisingEdge) {
  EXPECT_EQ(run("R_TRIG", {false, true, true, true, false, true, false, false, true}),
            (std::vector<bool>{false, true, false, false, false, true, false, false, true}));
}

TEST(RTrig, PulsesOnFirstScanWhenClkIsTrue) {
  EXPECT_EQ(run("R_TRIG", {true, true, false}), (std::vector<bool>{true, false, false}));
}

TEST(RTrig, NoPulseOnFirstScanWhenClkIsFalse) {
  EXPECT_EQ(run("R_TRIG", {false, false}), (std::vector<bool>{false, false}));
}

TEST(FTrig, OneScanPulsePerFallingEdge) {
  EXPECT_EQ(run("F_TRIG", {true, true, false, false, true, false, true, true, false}),
            (std::vector<bool>{false, false, true, false, false, true, false, false, true}));
}

TEST(FTrig, NoPulseOnFirstScanWhenClkIsFalse) {
  // The memory starts as "CLK was FALSE": no spurious first-scan pulse.
  EXPECT_EQ(run("F_TRIG", {false, false, false}), (std::vector<bool>{false, false, false}));
}

TEST(FTrig, NoPulseOnFirstScanWhenClkIsTrue) {
  EXPECT_EQ(run("F_TRIG", {true, false, false}), (std::vector<bool>{false, true, false}));
}

TEST(Edges, PulseLastsExactlyOneScanEvenIfScansAreSkipped) {
  BlockHarness h(registry(), "R_TRIG");
  h.set<bool>("CLK", true);
  h.scan();
  EXPECT_TRUE(h.get<bool>("Q"));
  h.set_now_ns(ms(100));  // a long gap does not matter: edges are per scan
  h.scan();
  EXPECT_FALSE(h.get<bool>("Q"));
}

}  // namespace
}  // namespace syncplc::iectest
