// MC_CamIn and MC_CamOut on two SIM_SERVO axes in virtual time: a periodic
// rising cam wraps continuously in position period after period with one
// EndOfProfile each; a single shot ends once and holds; a buffered cam takes
// over at the end of the profile; MC_CamOut keeps the velocity; a table that
// is not increasing is refused; a linear table's knee beyond the slave's
// acceleration is SyncLimit.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <numbers>
#include <string>

#include "tests/plcopen/sync_rig.hpp"

namespace syncplc::sync_test {
namespace {

constexpr int kContinuous = 4, kSynchronized = 5, kErrorStop = 7;

// A rising cam: 10 master units per period, the slave 2 u per u plus a
// sine of 0.5 u: s(u) = 2 u + 0.5 sin(2 pi u / 10), 11 points.
std::string rising_table() {
  std::string m = "[", s = "[";
  for (int i = 0; i <= 10; ++i) {
    m += (i ? ", " : "") + std::to_string(i);
    char buf[64];
    std::snprintf(buf, sizeof buf, "%.17g", 2.0 * i + 0.5 * std::sin(2 * std::numbers::pi * i / 10));
    s += (i ? ", " : "") + std::string(buf);
  }
  return "MasterPositions: " + m + "], SlavePositions: " + s + "]";
}

// A single shot: 10 master units, the slave 0 -> 10 along a smoothstep.
std::string smoothstep_table() {
  std::string m = "[", s = "[";
  for (int i = 0; i <= 10; ++i) {
    const double t = i / 10.0;
    m += (i ? ", " : "") + std::to_string(i);
    char buf[64];
    std::snprintf(buf, sizeof buf, "%.17g", 10 * (3 * t * t - 2 * t * t * t));
    s += (i ? ", " : "") + std::string(buf);
  }
  return "MasterPositions: " + m + "], SlavePositions: " + s + "]";
}

std::string cam_project() {
  const std::string tags =
      "  - {name: vx, type: BOOL}\n  - {name: vslow, type: BOOL}\n  - {name: cam, type: BOOL}\n"
      "  - {name: cam2, type: BOOL}\n  - {name: shot, type: BOOL}\n  - {name: lin, type: BOOL}\n"
      "  - {name: bad, type: BOOL}\n  - {name: cout, type: BOOL}\n"
      "  - {name: scaled, type: BOOL}\n  - {name: vhalf, type: BOOL}\n";
  const std::string blocks =
      "  - {name: mvx, type: MC_MoveVelocity, params: {Axis: x}, inputs: {Velocity: 10, Acceleration: 100}}\n"
      "  - {name: mvs, type: MC_MoveVelocity, params: {Axis: x}, inputs: {Velocity: 2, Acceleration: 100}}\n"
      "  - {name: ci, type: MC_CamIn, params: {n: 11, Master: x, Slave: y}, inputs: {Interpolation: 1, " +
      rising_table() +
      "}}\n"
      "  - {name: ci2, type: MC_CamIn, params: {n: 11, Master: x, Slave: y}, inputs: {Interpolation: 1, "
      "StartMode: 1, BufferMode: 1, " +
      rising_table() +
      "}}\n"
      "  - {name: cs, type: MC_CamIn, params: {n: 11, Master: x, Slave: y}, inputs: {Interpolation: 1, "
      "StartMode: 1, Periodic: FALSE, " +
      smoothstep_table() +
      "}}\n"
      "  - {name: cl, type: MC_CamIn, params: {n: 3, Master: x, Slave: y}, inputs: {StartMode: 1, "
      "MasterPositions: [0, 1, 2], SlavePositions: [0, 0, 2]}}\n"
      "  - {name: cb, type: MC_CamIn, params: {n: 3, Master: x, Slave: y}, inputs: {"
      "MasterPositions: [0, 2, 1], SlavePositions: [0, 0, 2]}}\n"
      "  - {name: co, type: MC_CamOut, params: {Slave: y}}\n"
      "  - {name: mslow, type: MC_MoveVelocity, params: {Axis: x}, inputs: {Velocity: 0.5, Acceleration: 100}}\n"
      "  - {name: cz, type: MC_CamIn, params: {n: 2, Master: x, Slave: y}, inputs: {Periodic: FALSE, "
      "MasterOffset: 2, MasterScaling: 2, SlaveScaling: 3, SlaveOffset: -3, MasterPositions: [0, 4], "
      "SlavePositions: [1, 3]}}\n";
  const std::string connections =
      "  - vx -> mvx.Execute\n  - vslow -> mvs.Execute\n  - cam -> ci.Execute\n  - cam2 -> ci2.Execute\n"
      "  - shot -> cs.Execute\n  - lin -> cl.Execute\n  - bad -> cb.Execute\n  - cout -> co.Execute\n"
      "  - scaled -> cz.Execute\n  - vhalf -> mslow.Execute\n";
  return sync_project(tags, blocks, connections);
}

TEST(McCam, APeriodicCamWrapsContinuouslyWithOneEndOfProfilePerPeriod) {
  SyncRun r(cam_project());
  ASSERT_TRUE(r.ok());
  r.scans(5);
  r.set("cam", true);  // absolute: master and slave at 0, on the profile
  r.scan();
  EXPECT_TRUE(r.b("ci.Busy") && r.b("ci.Active"));
  r.set("vx", true);
  Cell& ys = r.cell("y.set_position");
  Cell& yv = r.cell("y.set_velocity");
  Cell& xs = r.cell("x.set_position");
  Cell& eop = r.cell("ci.EndOfProfile");
  double y_before = ys.get<double>(), v_before = yv.get<double>();
  int ends = 0;
  for (int k = 0; k < 6000; ++k) {  // ~5.5 periods
    r.scan();
    const double y = ys.get<double>(), v = yv.get<double>(), x = xs.get<double>();
    ASSERT_EQ(r.state("y"), kSynchronized) << "scan " << k;
    ASSERT_TRUE(r.b("ci.InSync"));
    // On the profile: s(u) = 2 u + 0.5 sin(...) is within the spline's error of it.
    EXPECT_NEAR(y, 2 * x + 0.5 * std::sin(2 * std::numbers::pi * x / 10), 2e-3) << "scan " << k;
    // Continuous: no step beyond the slave's velocity and acceleration.
    EXPECT_LE(std::fabs(y - y_before), 50 * kT);
    EXPECT_LE(std::fabs(v - v_before), 500 * kT * (1 + 1e-9)) << "scan " << k;
    if (eop.get<bool>()) {
      ++ends;
      // The wrap: the sample given to the slave (the master's next scan) is
      // past a multiple of the period, the master now within a scan before it.
      const double f = std::fmod(x, 10.0);
      EXPECT_TRUE(f > 10 - 10 * kT - 1e-9 || f < 1e-9) << x;
    }
    y_before = y;
    v_before = v;
  }
  const double x = xs.get<double>();
  EXPECT_EQ(ends, static_cast<int>(std::floor(x / 10))) << x;
  EXPECT_GE(ends, 5);
}

TEST(McCam, ASingleShotCamEndsOnceAndHoldsItsLastValue) {
  SyncRun r(cam_project());
  ASSERT_TRUE(r.ok());
  r.scans(5);
  r.set("shot", true);  // relative: starts where master and slave are
  r.scan();
  r.set("vslow", true);  // 2 u/s: the table's 10 u in ~5 s
  int ends = 0, end_scan = -1;
  for (int k = 0; k < 8000; ++k) {
    r.scan();
    if (r.b("cs.EndOfProfile")) {
      ++ends;
      end_scan = k;
    }
    ASSERT_EQ(r.state("y"), kSynchronized) << "scan " << k;
  }
  EXPECT_EQ(ends, 1);
  EXPECT_GT(end_scan, 4900);
  EXPECT_LT(end_scan, 5200);
  EXPECT_DOUBLE_EQ(r.d("y.set_position"), 10.0);
  EXPECT_EQ(r.d("y.set_velocity"), 0.0);
  EXPECT_TRUE(r.b("cs.InSync") && r.b("cs.Busy"));
}

TEST(McCam, ABufferedCamTakesOverAtTheEndOfTheProfile) {
  SyncRun r(cam_project());
  ASSERT_TRUE(r.ok());
  r.scans(5);
  r.set("cam", true);
  r.scan();
  r.set("vx", true);
  r.scans(300);
  r.set("cam2", true);
  r.scan();
  EXPECT_TRUE(r.b("ci2.Busy"));
  EXPECT_FALSE(r.b("ci2.Active"));
  double y_before = r.d("y.set_position");
  int switched_at = -1;
  for (int k = 0; k < 2000 && switched_at < 0; ++k) {
    const bool end = r.b("ci.EndOfProfile");
    r.scan();
    const double y = r.d("y.set_position");
    EXPECT_LE(std::fabs(y - y_before), 50 * kT);
    y_before = y;
    if (r.b("ci.CommandAborted")) {
      switched_at = k;
      EXPECT_TRUE(end);  // the scan before showed the end of the profile
    }
  }
  ASSERT_GE(switched_at, 0);
  EXPECT_TRUE(r.b("ci2.Active"));
  EXPECT_EQ(r.state("y"), kSynchronized);
  r.scan();
  EXPECT_TRUE(r.b("ci2.InSync"));
  // The second cam, relative, from where the first ended: one period of the
  // master (10 u) is the rise of the table (20 u).
  const double y0 = r.d("y.set_position");
  r.scans(1000);
  EXPECT_NEAR(r.d("y.set_position") - y0, 20, 1e-6);
}

TEST(McCam, CamOutKeepsTheSlaveVelocity) {
  SyncRun r(cam_project());
  ASSERT_TRUE(r.ok());
  r.scans(5);
  r.set("cam", true);
  r.scan();
  r.set("vx", true);
  r.scans(500);
  r.set("cout", true);
  r.scan();
  EXPECT_TRUE(r.b("co.Done"));
  const double v = r.d("y.set_velocity");  // the velocity of the last cam sample, kept
  r.scan();
  EXPECT_TRUE(r.b("ci.CommandAborted"));
  EXPECT_EQ(r.state("y"), kContinuous);
  r.scans(50);
  EXPECT_EQ(r.d("y.set_velocity"), v);
}

// Absolute: u = (x - 2) / 2, y = 3 f(u) - 3 with f(u) = 1 + u / 2 on the
// table [0, 4]: y = 0.75 (x - 2) for x in [2, 10], 0 before (f holds 1), 6
// after (f holds 3). The master starts at 0, so the slave starts where it is.
TEST(McCam, OffsetsAndScalingsPlaceTheProfile) {
  SyncRun r(cam_project());
  ASSERT_TRUE(r.ok());
  r.scans(5);
  r.set("scaled", true);
  r.scan();
  r.set("vhalf", true);
  Cell& ys = r.cell("y.set_position");
  Cell& xs = r.cell("x.set_position");
  int on_profile = 0;
  for (int k = 0; k < 25000; ++k) {
    r.scan();
    const double x = xs.get<double>(), y = ys.get<double>();
    const double want = x <= 2 ? 0 : (x >= 10 ? 6 : 0.75 * (x - 2));
    ASSERT_NEAR(y, want, 1e-9) << "scan " << k << " x " << x;
    if (x > 2 && x < 10) ++on_profile;
  }
  EXPECT_GT(on_profile, 15000);
  EXPECT_EQ(ys.get<double>(), 6.0);
  EXPECT_EQ(r.state("y"), kSynchronized);
}

TEST(McCam, ATableNotIncreasingIsRefused) {
  SyncRun r(cam_project());
  ASSERT_TRUE(r.ok());
  r.scans(5);
  r.set("bad", true);
  r.scan();
  EXPECT_TRUE(r.b("cb.Error"));
  EXPECT_EQ(r.error_id("cb"), 0x020A);
}

// Linear interpolation steps the slope at a knee: slope 0 to 2 at the master's
// 10 u/s asks the slave for 20 u/s in one scan, 20,000 u/s^2 > its 500.
TEST(McCam, ALinearKneeBeyondTheSlaveAccelerationIsSyncLimit) {
  SyncRun r(cam_project());
  ASSERT_TRUE(r.ok());
  r.scans(5);
  r.set("vx", true);
  r.scans(200);  // the master at 10 u/s
  r.set("lin", true);
  int k = 0;
  for (; k < 500 && r.state("y") != kErrorStop; ++k) r.scan();
  EXPECT_EQ(r.state("y"), kErrorStop);
  EXPECT_TRUE(r.b("cl.Error"));
  EXPECT_EQ(r.error_id("cl"), 0x0309);
  EXPECT_GT(k, 90);  // the knee is 1 master unit (~100 scans) after the start
}

}  // namespace
}  // namespace syncplc::sync_test
