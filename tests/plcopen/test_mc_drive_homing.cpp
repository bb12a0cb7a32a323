// MC_Home on an axis whose drive homes itself (home_mode 3, the CiA 402
// homing mode through CIA402_DRIVE): the axis asks (DriveCommand::home),
// follows the drive meanwhile, and takes the drive's position at "homing
// attained"; a homing error, a timeout, stale feedback, an abort by MC_Stop.
// The drive here is a script: it moves on its own while asked, then jumps to
// the home offset and reports attained (or an error).
#include <gtest/gtest.h>

#include <cmath>

#include "fblocks/plcopen/axis_machine.hpp"

namespace syncplc::plcopen::test {
namespace mc_drive_homing {

constexpr double kT = 0.001;

struct HomingDrive {
  double position = 5;
  double velocity = 0;
  bool power_on = false;
  bool valid = true;
  int homing_scans = 0;     // scans asked so far
  int scans_to_home = 50;   // moving in - at 1 u/s, then at home
  bool fail = false;        // report a homing error instead
  bool attained = false, error = false;
  bool home_seen = false;
  double home_position_seen = NAN;

  DriveFeedback feedback() const {
    DriveFeedback f;
    f.position = position;
    f.velocity = velocity;
    f.valid = valid;
    f.power_on = power_on;
    f.homing_attained = attained;
    f.homing_error = error;
    return f;
  }
  void apply(const DriveCommand& c) {
    power_on = c.enable;
    if (c.home) {
      home_seen = true;
      home_position_seen = c.home_position;
      if (attained || error) return;
      if (++homing_scans < scans_to_home) {
        velocity = -1;
        position += velocity * kT;
      } else if (fail) {
        velocity = 0;
        error = true;
      } else {
        velocity = 0;
        position = c.home_position;  // the home point gets the home offset
        attained = true;
      }
      return;
    }
    homing_scans = 0;
    attained = error = false;
    if (power_on) {
      position = c.position;
      velocity = c.velocity;
    }
  }
};

AxisLimits limits() {
  AxisLimits l;
  l.v_max = 2;
  l.a_max = 20;
  l.d_max = 40;
  l.max_position_lag = 0.01;  // the drive's own motion and its jump must not trip it
  return l;
}

struct DriveHomingRig {
  AxisMachine m{limits(), kT};
  HomingDrive d;

  explicit DriveHomingRig(double timeout_s = 1) {
    HomingConfig h;
    h.mode = HomingConfig::Mode::Drive;
    h.method = 17;
    h.timeout_s = timeout_s;
    m.configure_homing(h);
  }
  void scan() {
    m.cycle(d.feedback());
    m.request_power(true);
    d.apply(m.drive_command());
  }
  void scans(int n) {
    for (int i = 0; i < n; ++i) scan();
  }
  void power_up() {
    for (int i = 0; i < 3 && m.state() != AxisState::Standstill; ++i) scan();
    ASSERT_EQ(m.state(), AxisState::Standstill);
  }
  CommandId home(double position) {
    Command c;
    c.kind = CommandKind::Home;
    c.position = position;
    AxisError e = AxisError::None;
    const CommandId id = m.submit(c, &e);
    EXPECT_EQ(e, AxisError::None);
    return id;
  }
};

TEST(McDriveHoming, TheDriveHomesAndTheAxisTakesItsPosition) {
  DriveHomingRig r;
  AxisLimits l = limits();
  l.sw_limit_neg = 1.99;  // the drive's homing passes it (user position 2 -> 1.951)
  l.sw_limit_neg_on = true;
  r.m.retune(l);
  r.power_up();
  ASSERT_EQ(r.m.set_position(2, false), AxisError::None);  // an offset of -3 before homing
  const CommandId id = r.home(10);
  EXPECT_TRUE(r.m.drive_command().home);
  EXPECT_DOUBLE_EQ(r.m.drive_command().home_position, 10);
  int scans = 0;
  while (r.m.report(id).status == CommandStatus::Active && scans < 200) {
    r.scan();
    ++scans;
    if (r.m.report(id).status == CommandStatus::Active && !r.d.attained) {
      EXPECT_EQ(r.m.state(), AxisState::Homing);
      // The set values follow the drive (one scan behind: the unit delay).
      EXPECT_LT(std::fabs(r.m.set_position() - (r.d.position - 3)), 1.5e-3);
    }
  }
  EXPECT_EQ(r.m.report(id).status, CommandStatus::Done);
  EXPECT_EQ(scans, 51) << "50 scans of the drive's homing, then the attained feedback a scan later";
  EXPECT_TRUE(r.m.homed());
  EXPECT_DOUBLE_EQ(r.m.set_position(), 10);
  EXPECT_DOUBLE_EQ(r.m.actual_position(), 10);
  EXPECT_DOUBLE_EQ(r.m.set_velocity(), 0);
  EXPECT_FALSE(r.m.drive_command().home);
  EXPECT_DOUBLE_EQ(r.m.drive_command().position, 10) << "the offset is 0: drive and axis positions agree";
  r.scan();
  EXPECT_EQ(r.m.state(), AxisState::Standstill);
  r.scans(5);
  EXPECT_EQ(r.m.state(), AxisState::Standstill);
  EXPECT_DOUBLE_EQ(r.d.position, 10) << "no jump after homing";
}

TEST(McDriveHoming, AHomingErrorIsErrorStopAndMcResetLeavesIt) {
  DriveHomingRig r;
  r.d.fail = true;
  r.power_up();
  const CommandId id = r.home(0);
  for (int i = 0; i < 60 && r.m.state() != AxisState::ErrorStop; ++i) r.scan();
  ASSERT_EQ(r.m.state(), AxisState::ErrorStop);
  EXPECT_EQ(r.m.axis_error(), AxisError::DriveHomingError);
  EXPECT_EQ(static_cast<int>(AxisError::DriveHomingError), 0x0307);
  EXPECT_EQ(r.m.report(id).status, CommandStatus::Error);
  EXPECT_EQ(r.m.report(id).error, AxisError::DriveHomingError);
  EXPECT_FALSE(r.m.drive_command().home) << "the request falls: the drive leaves homing mode";
  EXPECT_FALSE(r.m.homed());
  // The set values, which followed the drive at -1 u/s, brake with d_max
  // (40 u/s^2: 25 scans); MC_Reset before is StillMoving.
  EXPECT_EQ(r.m.reset(), AxisError::StillMoving);
  r.scans(30);
  EXPECT_EQ(r.m.reset(), AxisError::None);
  r.scan();
  EXPECT_EQ(r.m.state(), AxisState::Standstill);
  EXPECT_EQ(r.m.axis_error(), AxisError::None);
}

TEST(McDriveHoming, NoAttainedWithinTheTimeoutIsHomingTimeout) {
  DriveHomingRig r(0.02);
  r.d.scans_to_home = 1000;
  r.power_up();
  r.home(0);
  int scans = 0;
  while (r.m.state() == AxisState::Homing && scans < 100) {
    r.scan();
    ++scans;
  }
  EXPECT_EQ(r.m.state(), AxisState::ErrorStop);
  EXPECT_EQ(r.m.axis_error(), AxisError::HomingTimeout);
  EXPECT_NEAR(scans, 20, 1) << "0.02 s at 1 ms";
  EXPECT_FALSE(r.m.drive_command().home);
}

TEST(McDriveHoming, McStopAbortsTheHomingAndTheDriveIsReleased) {
  DriveHomingRig r;
  r.power_up();
  const CommandId home = r.home(0);
  r.scans(10);
  ASSERT_TRUE(r.m.drive_command().home);
  Command stop;
  stop.kind = CommandKind::Stop;
  AxisError e = AxisError::None;
  const CommandId sid = r.m.submit(stop, &e);
  ASSERT_EQ(e, AxisError::None);
  EXPECT_EQ(r.m.report(home).status, CommandStatus::Aborted);
  EXPECT_FALSE(r.m.drive_command().home) << "bit 4 falls: the drive interrupts its homing";
  for (int i = 0; i < 200 && r.m.report(sid).status != CommandStatus::Done; ++i) r.scan();
  EXPECT_EQ(r.m.report(sid).status, CommandStatus::Done);
  EXPECT_FALSE(r.m.homed());
  r.m.release_stop(sid);
  EXPECT_EQ(r.m.state(), AxisState::Standstill);
}

TEST(McDriveHoming, StaleFeedbackDuringHomingIsErrorStop) {
  DriveHomingRig r;
  r.power_up();
  r.home(0);
  r.scans(5);
  r.d.valid = false;
  r.scan();
  EXPECT_EQ(r.m.state(), AxisState::ErrorStop);
  EXPECT_EQ(r.m.axis_error(), AxisError::FeedbackLost);
  EXPECT_FALSE(r.m.drive_command().home);
}

TEST(McDriveHoming, HomingNeedsStandstill) {
  DriveHomingRig r;
  Command c;
  c.kind = CommandKind::Home;
  AxisError e = AxisError::None;
  EXPECT_EQ(r.m.submit(c, &e), 0u);
  EXPECT_EQ(e, AxisError::Disabled);
  EXPECT_FALSE(r.m.drive_command().home);
}

}  // namespace
}  // namespace syncplc::plcopen::test
