// MC_GearIn, MC_GearOut (and MC_CamOut's refusal) on two SIM_SERVO axes in
// virtual time: the slave ramps to the ratio, locks, and then follows the
// master's position exactly and without drift; leaving the gear keeps the
// velocity; what ends a gear (another command, the master's ErrorStop, the
// slave's limits) and the inputs refused.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <string>

#include "tests/plcopen/sync_rig.hpp"

namespace syncplc::sync_test {
namespace {

const std::string kGearTags =
    "  - {name: vx1, type: BOOL}\n  - {name: vx2, type: BOOL}\n  - {name: vx3, type: BOOL}\n"
    "  - {name: gear, type: BOOL}\n  - {name: gout, type: BOOL}\n  - {name: cout, type: BOOL}\n"
    "  - {name: mabs, type: BOOL}\n  - {name: fault, type: BOOL}\n  - {name: gact, type: BOOL}\n  - {name: mabs2, type: BOOL}\n"
    "  - {name: num, type: INT, init: 3}\n  - {name: den, type: UINT, init: 2}\n"
    "  - {name: acc, type: LREAL, init: 200}\n  - {name: jerk, type: LREAL}\n  - {name: bm, type: INT}\n";

const std::string kGearBlocks =
    "  - {name: mvx1, type: MC_MoveVelocity, params: {Axis: x}, inputs: {Velocity: 10, Acceleration: 100, Deceleration: 100}}\n"
    "  - {name: mvx2, type: MC_MoveVelocity, params: {Axis: x}, inputs: {Velocity: -20, Acceleration: 100, Deceleration: 100}}\n"
    "  - {name: mvx3, type: MC_MoveVelocity, params: {Axis: x}, inputs: {Velocity: 60, Acceleration: 1000}}\n"
    "  - {name: gi, type: MC_GearIn, params: {Master: x, Slave: y}}\n"
    "  - {name: ga, type: MC_GearIn, params: {Master: x, Slave: y}, inputs: {RatioNumerator: -1, "
    "RatioDenominator: 4, MasterValueSource: 1}}\n"
    "  - {name: go, type: MC_GearOut, params: {Slave: y}}\n"
    "  - {name: co, type: MC_CamOut, params: {Slave: y}}\n"
    "  - {name: ma, type: MC_MoveAbsolute, params: {Axis: y}, inputs: {Position: 0, Velocity: 10}}\n"
    "  - {name: ma2, type: MC_MoveAbsolute, params: {Axis: y}, inputs: {Position: 2, Velocity: 10}}\n";

const std::string kGearConnections =
    "  - vx1 -> mvx1.Execute\n  - vx2 -> mvx2.Execute\n  - vx3 -> mvx3.Execute\n  - gear -> gi.Execute\n"
    "  - gout -> go.Execute\n  - cout -> co.Execute\n  - mabs -> ma.Execute\n  - fault -> dx.inject_fault\n"
    "  - num -> gi.RatioNumerator\n  - den -> gi.RatioDenominator\n  - acc -> gi.Acceleration\n"
    "  - jerk -> gi.Jerk\n  - bm -> gi.BufferMode\n  - gact -> ga.Execute\n  - mabs2 -> ma2.Execute\n";

constexpr int kStandstill = 1, kDiscrete = 3, kContinuous = 4, kSynchronized = 5, kErrorStop = 7;

std::string gear_project() { return sync_project(kGearTags, kGearBlocks, kGearConnections); }

// The master runs at 10 u/s; the slave is geared in at 3/2 and scanned until InGear.
void gear_in_at_10(SyncRun& r) {
  r.scans(3);
  r.set("vx1", true);
  r.scans(150);
  r.set("gear", true);
  ASSERT_TRUE(r.until("gi.InGear", 2000));
}

TEST(McGear, RampsToTheRatioThenFollowsTheMasterExactlyWithoutDrift) {
  SyncRun r(gear_project());
  ASSERT_TRUE(r.ok());
  r.scans(3);
  r.set("vx1", true);
  r.scans(150);  // the master at 10 u/s
  r.set("gear", true);
  r.scan();  // the slave's state shows the command from the next scan on
  Cell& ys = r.cell("y.set_position");
  Cell& yv = r.cell("y.set_velocity");
  Cell& xs = r.cell("x.set_position");
  Cell& xv = r.cell("x.set_velocity");
  Cell& in_gear = r.cell("gi.InGear");
  // The ramp: within the GearIn's Acceleration (200), InGear only after it.
  double v_before = 0;
  int ramp = 0;
  for (; ramp < 2000 && !in_gear.get<bool>(); ++ramp) {
    r.scan();
    const double v = yv.get<double>();
    EXPECT_LE(std::fabs(v - v_before), 200 * kT * (1 + 1e-9)) << "scan " << ramp;
    v_before = v;
    EXPECT_EQ(r.state("y"), kSynchronized);
    EXPECT_TRUE(r.b("gi.Busy") && r.b("gi.Active"));
  }
  ASSERT_TRUE(in_gear.get<bool>());
  EXPECT_GT(ramp, 60);  // 15 u/s at 200 u/s^2: 75 scans
  EXPECT_DOUBLE_EQ(yv.get<double>(), 1.5 * xv.get<double>());
  // Locked: 200,000 scans (200 s), the master reversing to -20 u/s half way.
  const double x0 = xs.get<double>(), y0 = ys.get<double>();
  double worst = 0;
  for (int k = 0; k < 200000; ++k) {
    if (k == 100000) {
      r.set("vx1", false);
      r.set("vx2", true);
    }
    r.scan();
    const double dx = xs.get<double>() - x0, dy = ys.get<double>() - y0;
    worst = std::fmax(worst, std::fabs(dy - 1.5 * dx));
    if (std::fabs(yv.get<double>() - 1.5 * xv.get<double>()) > 1e-9) {
      ADD_FAILURE() << "velocity ratio off at scan " << k << ": " << yv.get<double>() << " vs " << xv.get<double>();
      break;
    }
    if (!in_gear.get<bool>() || r.state("y") != kSynchronized) {
      ADD_FAILURE() << "left the gear at scan " << k;
      break;
    }
  }
  EXPECT_LT(worst, 1e-9) << "position coupling error after 200 s";
  EXPECT_LT(xs.get<double>() - x0, -900);  // the master went back ~1000 u
}

// MasterValueSource 1: the master's actual position (SIM_SERVO with tau 0
// reports the set position it was given; the actual velocity is its backward
// difference), extrapolated by one scan: at a constant master velocity the
// slave's set position follows -1/4 of the master's actual one exactly.
TEST(McGear, ActualValueSourceFollowsTheMasterActualPosition) {
  SyncRun r(gear_project());
  ASSERT_TRUE(r.ok());
  r.scans(3);
  r.set("vx1", true);
  r.scans(150);
  r.set("gact", true);
  ASSERT_TRUE(r.until("ga.InGear", 2000));
  r.scans(5);
  Cell& ys = r.cell("y.set_position");
  Cell& xa = r.cell("x.position");
  const double x0 = xa.get<double>(), y0 = ys.get<double>();
  for (int k = 0; k < 5000; ++k) {
    r.scan();
    ASSERT_NEAR(ys.get<double>() - y0, -0.25 * (xa.get<double>() - x0), 1e-9) << "scan " << k;
  }
  EXPECT_NEAR(r.d("y.set_velocity"), -2.5, 1e-9);  // the actual velocity is a difference of positions
}

// BufferMode Buffered: the gear waits (Busy, not Active) behind the slave's
// move and starts in the scan the move is Done.
TEST(McGear, ABufferedGearStartsWhenTheMoveBeforeIsDone) {
  SyncRun r(gear_project());
  ASSERT_TRUE(r.ok());
  r.scans(3);
  r.set("vx1", true);
  r.scans(150);
  r.set("mabs2", true);
  r.scan();
  r.cell("bm").set<std::int16_t>(1);
  r.set("gear", true);
  r.scan();
  EXPECT_TRUE(r.b("gi.Busy"));
  EXPECT_FALSE(r.b("gi.Active"));
  int k = 0;
  for (; k < 5000 && !r.b("ma2.Done"); ++k) {
    EXPECT_FALSE(r.b("gi.Active")) << "scan " << k;
    r.scan();
  }
  ASSERT_TRUE(r.b("ma2.Done"));
  EXPECT_TRUE(r.b("gi.Active"));  // the same scan
  EXPECT_EQ(r.d("y.set_position"), 2.0);
  ASSERT_TRUE(r.until("gi.InGear", 2000));
  EXPECT_EQ(r.state("y"), kSynchronized);
}

TEST(McGear, GearOutKeepsTheSlaveVelocityInContinuousMotion) {
  SyncRun r(gear_project());
  ASSERT_TRUE(r.ok());
  gear_in_at_10(r);
  r.scans(10);
  r.set("gout", true);
  r.scan();
  EXPECT_TRUE(r.b("go.Done"));  // in the scan of the edge
  // The axis (and the GearIn, which runs before MC_GearOut here) show it from the next scan.
  r.scan();
  EXPECT_TRUE(r.b("go.Done"));
  EXPECT_FALSE(r.b("go.Error"));
  EXPECT_TRUE(r.b("gi.CommandAborted"));
  EXPECT_FALSE(r.b("gi.Busy") || r.b("gi.InGear"));
  EXPECT_EQ(r.state("y"), kContinuous);
  for (int k = 0; k < 100; ++k) {
    r.scan();
    EXPECT_DOUBLE_EQ(r.d("y.set_velocity"), 15.0);
  }
  EXPECT_EQ(r.state("y"), kContinuous);
}

TEST(McGear, GearOutAndCamOutOutsideSynchronizedMotionAre0x0105) {
  SyncRun r(gear_project());
  ASSERT_TRUE(r.ok());
  r.scans(5);
  ASSERT_EQ(r.state("y"), kStandstill);
  r.set("gout", true);
  r.set("cout", true);
  r.scan();
  EXPECT_TRUE(r.b("go.Error"));
  EXPECT_EQ(r.error_id("go"), 0x0105);
  EXPECT_TRUE(r.b("co.Error"));
  EXPECT_EQ(r.error_id("co"), 0x0105);
  EXPECT_EQ(r.state("y"), kStandstill);
}

TEST(McGear, AMoveOnTheSlaveAbortsTheGear) {
  SyncRun r(gear_project());
  ASSERT_TRUE(r.ok());
  gear_in_at_10(r);
  r.set("mabs", true);
  r.scans(2);  // the axis shows its state from the scan after the command
  EXPECT_TRUE(r.b("gi.CommandAborted"));
  EXPECT_FALSE(r.b("gi.Busy") || r.b("gi.InGear") || r.b("gi.Error"));
  EXPECT_EQ(r.state("y"), kDiscrete);
  ASSERT_TRUE(r.until("ma.Done", 5000));
  EXPECT_EQ(r.d("y.set_position"), 0.0);
}

TEST(McGear, MasterInErrorStopEndsTheGearWithErrorAndTheSlaveBrakes) {
  SyncRun r(gear_project());
  ASSERT_TRUE(r.ok());
  gear_in_at_10(r);
  r.set("fault", true);  // the master's drive faults
  r.scans(3);
  EXPECT_EQ(r.state("x"), kErrorStop);
  EXPECT_TRUE(r.b("gi.Error"));
  EXPECT_EQ(r.error_id("gi"), 0x0107);
  // The slave, let go, brakes with its MaxDecelerationAppl (800) to standstill;
  // it has no error of its own.
  double v_before = r.d("y.set_velocity");
  int k = 0;
  for (; k < 1000 && r.state("y") != kStandstill; ++k) {
    r.scan();
    const double v = r.d("y.set_velocity");
    EXPECT_LE(std::fabs(v), std::fabs(v_before));
    EXPECT_LE(std::fabs(v - v_before), 800 * kT * (1 + 1e-9));
    EXPECT_NE(r.state("y"), kErrorStop);
    v_before = v;
  }
  EXPECT_EQ(r.state("y"), kStandstill);
  // A new GearIn with the master in ErrorStop is refused.
  r.set("gear", false);
  r.scan();
  r.set("gear", true);
  r.scan();
  EXPECT_TRUE(r.b("gi.Error"));
  EXPECT_EQ(r.error_id("gi"), 0x0107);
}

TEST(McGear, AMasterFasterThanTheSlaveMayFollowIsSyncLimit) {
  SyncRun r(gear_project());
  ASSERT_TRUE(r.ok());
  r.cell("num").set<std::int16_t>(4);
  r.cell("den").set<std::uint16_t>(1);
  r.scans(3);
  r.set("vx1", true);
  r.scans(5);
  r.set("gear", true);  // 4 x 10 = 40 u/s: within the slave's 50
  ASSERT_TRUE(r.until("gi.InGear", 2000));
  r.set("vx1", false);
  r.set("vx2", true);  // -20 u/s: the slave should run -80
  int k = 0;
  for (; k < 2000 && r.state("y") != kErrorStop; ++k) {
    r.scan();
    EXPECT_LE(std::fabs(r.d("y.set_velocity")), 50 * (1 + 1e-9));
  }
  EXPECT_EQ(r.state("y"), kErrorStop);
  EXPECT_EQ(r.cell("y.error_id").get<std::uint16_t>(), 0x0309);
  EXPECT_TRUE(r.b("gi.Error"));
  EXPECT_EQ(r.error_id("gi"), 0x0309);
}

TEST(McGear, AMasterAcceleratingBeyondTheSlaveIsSyncLimit) {
  SyncRun r(gear_project());
  ASSERT_TRUE(r.ok());
  r.cell("num").set<std::int16_t>(1);
  r.cell("den").set<std::uint16_t>(1);
  gear_in_at_10(r);
  r.set("vx3", true);  // the master accelerates with 1000, the slave may 500
  r.scans(3);
  EXPECT_EQ(r.state("y"), kErrorStop);
  EXPECT_EQ(r.error_id("gi"), 0x0309);
}

TEST(McGear, InputErrors) {
  struct Case {
    const char* tag;
    double value;
    int error_id;
  };
  const Case cases[] = {{"den", 0, 0x020A}, {"jerk", 1, 0x0204}, {"bm", 2, 0x0206}, {"bm", 9, 0x0206}, {"acc", 600, 0x0202}, {"acc", -1, 0x0202}};
  for (const Case& c : cases) {
    SCOPED_TRACE(std::string(c.tag) + " = " + std::to_string(c.value));
    SyncRun r(gear_project());
    ASSERT_TRUE(r.ok());
    r.scans(5);
    const std::string t = c.tag;
    if (t == "den") r.cell(t).set<std::uint16_t>(static_cast<std::uint16_t>(c.value));
    else if (t == "bm") r.cell(t).set<std::int16_t>(static_cast<std::int16_t>(c.value));
    else r.cell(t).set<double>(c.value);
    r.set("gear", true);
    r.scan();
    EXPECT_TRUE(r.b("gi.Error"));
    EXPECT_EQ(r.error_id("gi"), c.error_id);
    EXPECT_EQ(r.state("y"), kStandstill);
  }
}

}  // namespace
}  // namespace syncplc::sync_test
