// The PLCopen axis machine (fblocks/plcopen/axis_machine.hpp): the state
// diagram of PLCopen Part 1 §2.1, its errors (§2.2), BufferMode (§2.4.2),
// reports, MC_SetPosition and the parameters, on an ideal drive in virtual time.
#include <cmath>

#include <gtest/gtest.h>

#include "tests/plcopen/axis_rig.hpp"

namespace syncplc::plcopen::test {
namespace {

constexpr double kT = 0.001;

TEST(AxisStates, StartsDisabledAndPowersUpToStandstill) {
  Rig r;
  EXPECT_EQ(r.m.state(), AxisState::Disabled);
  EXPECT_FALSE(r.m.drive_command().enable);
  r.power = true;
  r.scan();  // the drive sees enable now, reports power_on next scan
  EXPECT_TRUE(r.m.drive_command().enable);
  EXPECT_EQ(r.m.state(), AxisState::Disabled);
  r.scan();
  EXPECT_EQ(r.m.state(), AxisState::Standstill);
  EXPECT_TRUE(r.m.power_on());
  EXPECT_TRUE(r.m.powered_request());
  EXPECT_STREQ(axis_state_name(r.m.state()), "Standstill");
}

TEST(AxisStates, DisabledSetValuesFollowTheActualOnes) {
  Rig r;
  r.d.position = 3.5;
  r.scan();
  EXPECT_EQ(r.m.set_position(), 3.5);
  r.power_up();
  EXPECT_EQ(r.m.set_position(), 3.5);
  EXPECT_EQ(r.m.drive_command().position, 3.5);
}

TEST(AxisStates, DiscreteMoveGoesToDiscreteMotionThenStandstill) {
  Rig r;
  r.power_up();
  const CommandId id = r.submit(move_absolute(0.1, 1));
  EXPECT_EQ(r.m.state(), AxisState::DiscreteMotion);
  EXPECT_EQ(r.status(id), CommandStatus::Active);
  EXPECT_EQ(r.m.active_command(), id);
  EXPECT_EQ(r.m.active_kind(), CommandKind::MoveAbsolute);
  ASSERT_GT(r.run_until_end(id), 0);
  EXPECT_EQ(r.status(id), CommandStatus::Done);
  EXPECT_EQ(r.m.state(), AxisState::Standstill);
  EXPECT_EQ(r.m.set_position(), 0.1);
  EXPECT_EQ(r.m.active_command(), 0u);
}

TEST(AxisStates, VelocityMoveStaysContinuousAndIsNeverDone) {
  Rig r;
  r.power_up();
  const CommandId id = r.submit(move_velocity(1));
  EXPECT_EQ(r.m.state(), AxisState::ContinuousMotion);
  EXPECT_EQ(r.m.remaining_scans(), -1);
  r.scans(500);
  EXPECT_EQ(r.status(id), CommandStatus::Active);
  EXPECT_TRUE(r.m.report(id).in_velocity);
  EXPECT_EQ(r.m.state(), AxisState::ContinuousMotion);
}

TEST(AxisStates, HomeOnlyFromStandstillAndHomingForOneCycle) {
  Rig r;
  EXPECT_EQ(r.reject(home(5)), AxisError::Disabled);
  r.power_up();
  r.submit(move_velocity(1));
  EXPECT_EQ(r.reject(home(5)), AxisError::NotStandstill);
  r.submit(halt());
  r.scans(100);
  ASSERT_EQ(r.m.state(), AxisState::Standstill);
  EXPECT_FALSE(r.m.homed());
  const CommandId id = r.submit(home(5));
  EXPECT_EQ(r.m.state(), AxisState::Homing);
  EXPECT_EQ(r.reject(move_absolute(1, 1)), AxisError::NotStandstill);
  EXPECT_EQ(r.m.remaining_scans(), 1);
  r.scan();
  EXPECT_EQ(r.status(id), CommandStatus::Done);
  EXPECT_TRUE(r.m.homed());
  EXPECT_EQ(r.m.state(), AxisState::Homing);
  EXPECT_EQ(r.m.set_position(), 5);
  r.scan();
  EXPECT_EQ(r.m.state(), AxisState::Standstill);
  EXPECT_EQ(r.m.actual_position(), 5);  // the offset moved the actual position too
  EXPECT_EQ(r.m.following_error(), 0);
}

TEST(AxisStates, MoveChainedOnHomeDoneIsAccepted) {
  Rig r;
  r.power_up();
  const CommandId h = r.submit(home(0));
  r.scan();
  ASSERT_EQ(r.status(h), CommandStatus::Done);
  const CommandId id = r.submit(move_absolute(0.01, 1));
  EXPECT_EQ(r.m.state(), AxisState::DiscreteMotion);
  ASSERT_GT(r.run_until_end(id), 0);
  EXPECT_EQ(r.m.state(), AxisState::Standstill);
}

TEST(AxisStates, StopHoldsUntilReleasedAfterDone) {
  Rig r;
  r.power_up();
  const CommandId mv = r.submit(move_velocity(1));
  r.scans(100);
  const CommandId st = r.submit(stop());
  EXPECT_EQ(r.status(mv), CommandStatus::Aborted);
  EXPECT_EQ(r.m.state(), AxisState::Stopping);
  EXPECT_EQ(r.reject(move_absolute(0, 1)), AxisError::Stopping);
  EXPECT_EQ(r.reject(halt()), AxisError::Stopping);
  const std::int64_t rem = r.m.remaining_scans();
  EXPECT_EQ(r.run_until_end(st), rem);
  EXPECT_EQ(r.status(st), CommandStatus::Done);
  EXPECT_EQ(r.m.set_velocity(), 0);
  r.scans(10);
  EXPECT_EQ(r.m.state(), AxisState::Stopping);  // Execute still TRUE
  EXPECT_EQ(r.reject(move_velocity(1)), AxisError::Stopping);
  r.m.release_stop(st);
  EXPECT_EQ(r.m.state(), AxisState::Standstill);
  r.submit(move_velocity(1));
}

TEST(AxisStates, StopReleasedBeforeDoneEndsInStandstill) {
  Rig r;
  r.power_up();
  r.submit(move_velocity(2));
  r.scans(200);
  const CommandId st = r.submit(stop());
  r.scans(3);
  r.m.release_stop(st);
  EXPECT_EQ(r.m.state(), AxisState::Stopping);
  ASSERT_GT(r.run_until_end(st), 0);
  EXPECT_EQ(r.status(st), CommandStatus::Done);
  EXPECT_EQ(r.m.state(), AxisState::Standstill);
}

TEST(AxisStates, SecondStopIsAcceptedAndAbortsTheFirst) {
  Rig r;
  r.power_up();
  r.submit(move_velocity(2));
  r.scans(200);
  const CommandId s1 = r.submit(stop(1));
  r.scan();
  const CommandId s2 = r.submit(stop());
  EXPECT_EQ(r.status(s1), CommandStatus::Aborted);
  EXPECT_EQ(r.status(s2), CommandStatus::Active);
  ASSERT_GT(r.run_until_end(s2), 0);
  r.m.release_stop(s1);  // the aborted one's Execute falls: no effect
  EXPECT_EQ(r.m.state(), AxisState::Stopping);
  r.m.release_stop(s2);
  EXPECT_EQ(r.m.state(), AxisState::Standstill);
}

TEST(AxisStates, HaltIsDiscreteMotionAndMayBeAborted) {
  Rig r;
  r.power_up();
  r.submit(move_velocity(2));
  r.scans(200);
  const CommandId h = r.submit(halt(5));
  EXPECT_EQ(r.m.state(), AxisState::DiscreteMotion);
  r.scans(10);
  const CommandId mv = r.submit(move_velocity(-1));
  EXPECT_EQ(r.status(h), CommandStatus::Aborted);
  r.scans(10);
  const CommandId h2 = r.submit(halt());
  ASSERT_GT(r.run_until_end(h2), 0);
  EXPECT_EQ(r.status(mv), CommandStatus::Aborted);
  EXPECT_EQ(r.status(h2), CommandStatus::Done);
  EXPECT_EQ(r.m.state(), AxisState::Standstill);
}

// MC_Power's Enable falls in each motion state: Disabled, the drive's enable
// off, the active and buffered commands Aborted.
TEST(AxisStates, PowerOffFromEachStateAbortsEverything) {
  enum Case { Discrete, Continuous, Stopping, Homing, Standing };
  for (int k = Discrete; k <= Standing; ++k) {
    SCOPED_TRACE(k);
    Rig r;
    r.power_up();
    CommandId a = 0, b = 0;
    switch (k) {
      case Discrete:
        a = r.submit(move_absolute(1, 1));
        b = r.submit(move_absolute(0, 1, BufferMode::Buffered));
        r.scans(5);
        break;
      case Continuous: a = r.submit(move_velocity(1)); r.scans(5); break;
      case Stopping: r.submit(move_velocity(1)); r.scans(50); a = r.submit(stop()); r.scan(); break;
      case Homing: a = r.submit(home(1)); break;
      case Standing: break;
    }
    r.m.request_power(false);  // MC_Power's Enable falls in this scan
    EXPECT_EQ(r.m.state(), AxisState::Disabled);
    EXPECT_FALSE(r.m.drive_command().enable);
    r.power = false;
    r.scan();
    if (a) { EXPECT_EQ(r.status(a), CommandStatus::Aborted); }
    if (b) { EXPECT_EQ(r.status(b), CommandStatus::Aborted); }
    r.scan();
    EXPECT_FALSE(r.m.power_on());
    EXPECT_EQ(r.reject(move_velocity(1)), AxisError::Disabled);
    EXPECT_EQ(r.reject(stop()), AxisError::Disabled);
  }
}

TEST(AxisStates, PowerOffWhileStopHeldLeavesStopDone) {
  Rig r;
  r.power_up();
  const CommandId st = r.submit(stop());
  r.scan();
  ASSERT_EQ(r.status(st), CommandStatus::Done);
  r.power = false;
  r.scan();
  EXPECT_EQ(r.m.state(), AxisState::Disabled);
  EXPECT_EQ(r.status(st), CommandStatus::Done);
  r.power_up();  // the old stop's hold is gone
  r.submit(move_velocity(1));
}

// ---- ErrorStop -------------------------------------------------------------------

// Every cause of ErrorStop, with an active and a buffered command: both end
// with Error and the axis's error (§2.2.2).
TEST(AxisErrors, EachCauseGoesToErrorStopAndErrorsTheCommands) {
  enum Cause { Fault, PowerLost, Lag, Feedback, Limit };
  const AxisError expected[] = {AxisError::DriveFault, AxisError::PowerLost, AxisError::FollowingError,
                                AxisError::FeedbackLost, AxisError::SoftLimit};
  for (int k = Fault; k <= Limit; ++k) {
    SCOPED_TRACE(k);
    AxisLimits l = default_limits();
    l.max_position_lag = 0.01;
    l.sw_limit_pos = 0.2;
    l.sw_limit_pos_on = k == Limit;
    Rig r(l);
    r.power_up();
    const CommandId a = r.submit(k == Limit ? move_velocity(1) : move_absolute(-1, 1));
    const CommandId b = k == Limit ? 0 : r.submit(move_absolute(0, 1, BufferMode::Buffered));
    r.scans(10);
    switch (k) {
      case Fault: r.d.fault = true; r.d.fault_code = 0x7305; break;
      case PowerLost: r.d.lose_power = true; break;
      case Lag: r.d.position += 0.02; break;
      case Feedback: r.d.valid = false; break;
      case Limit: break;
    }
    for (int i = 0; i < 2000 && r.m.state() != AxisState::ErrorStop; ++i) r.scan();
    EXPECT_EQ(r.m.state(), AxisState::ErrorStop);
    EXPECT_EQ(r.m.axis_error(), expected[k]);
    EXPECT_EQ(r.m.report(a).status, CommandStatus::Error);
    EXPECT_EQ(r.m.report(a).error, expected[k]);
    if (b) { EXPECT_EQ(r.m.report(b).error, expected[k]); }
    EXPECT_EQ(r.m.active_command(), 0u);
    if (k == Fault) {
      EXPECT_EQ(r.m.drive_fault_code(), 0x7305);
      EXPECT_FALSE(r.m.drive_command().enable);
    } else {
      EXPECT_TRUE(r.m.drive_command().enable);  // the power stage brakes the axis
    }
    EXPECT_EQ(r.reject(move_velocity(1)), AxisError::InErrorStop);
    EXPECT_EQ(r.reject(stop()), AxisError::InErrorStop);
    EXPECT_EQ(r.reject(home(0)), AxisError::InErrorStop);
  }
}

TEST(AxisErrors, DriveFaultWhileDisabled) {
  Rig r;
  r.d.fault = true;
  r.d.fault_code = 42;
  r.scan();
  EXPECT_EQ(r.m.state(), AxisState::ErrorStop);
  EXPECT_EQ(r.m.axis_error(), AxisError::DriveFault);
  EXPECT_EQ(r.m.drive_fault_code(), 42);
}

TEST(AxisErrors, StaleFeedbackWhileDisabledIsNoError) {
  Rig r;
  r.d.valid = false;
  r.scans(3);
  EXPECT_EQ(r.m.state(), AxisState::Disabled);
  EXPECT_FALSE(r.m.feedback_valid());
}

TEST(AxisErrors, LagMonitoringOffIgnoresLag) {
  Rig r;  // max_position_lag 0
  r.power_up();
  r.d.position += 5;
  r.scan();
  EXPECT_EQ(r.m.state(), AxisState::Standstill);
  EXPECT_EQ(r.m.following_error(), -5);
}

TEST(AxisErrors, ErrorStopBrakesWithSystemDecelerationWhilePowered) {
  AxisLimits l = default_limits();
  l.max_position_lag = 0.01;
  Rig r(l);
  r.power_up();
  ASSERT_EQ(r.m.write_parameter(static_cast<std::int16_t>(AxisParameter::MaxDecelerationAppl), 10), AxisError::None);
  r.submit(move_velocity(2));
  r.scans(200);
  ASSERT_EQ(r.m.set_velocity(), 2);
  r.m.cycle([&] { auto f = r.d.feedback(); f.position += 0.05; return f; }());  // following error
  ASSERT_EQ(r.m.state(), AxisState::ErrorStop);
  EXPECT_DOUBLE_EQ(r.m.set_velocity(), 2 - 40 * kT);  // system d_max 40, not the appl 10
  EXPECT_EQ(r.m.reset(), AxisError::StillMoving);
  r.d.apply(r.m.drive_command());
  int n = 0;
  while (r.m.set_velocity() != 0 && n < 1000) {
    const double v = r.m.set_velocity();
    r.scan();
    EXPECT_NEAR(v - r.m.set_velocity(), 40 * kT, 1e-12);
    if (r.m.set_velocity() == 0) break;
    ++n;
  }
  EXPECT_EQ(r.m.set_velocity(), 0);
  EXPECT_EQ(r.m.reset(), AxisError::None);
  EXPECT_EQ(r.m.state(), AxisState::Standstill);
  EXPECT_EQ(r.m.axis_error(), AxisError::None);
}

TEST(AxisErrors, ErrorStopWithPowerOffFollowsTheActualValues) {
  Rig r;
  r.power_up();
  r.submit(move_velocity(1));
  r.scans(100);
  r.d.fault = true;
  r.scan();
  ASSERT_EQ(r.m.state(), AxisState::ErrorStop);
  r.d.position = 7;
  r.d.velocity = 0.5;
  r.scan();
  EXPECT_EQ(r.m.set_position(), 7);
  EXPECT_EQ(r.m.set_velocity(), 0.5);
  EXPECT_EQ(r.m.drive_command().position, 7);
}

// ---- MC_Reset -------------------------------------------------------------------

TEST(AxisReset, OutsideErrorStopDoesNothing) {
  Rig r;
  EXPECT_EQ(r.m.reset(), AxisError::None);
  EXPECT_EQ(r.m.state(), AxisState::Disabled);
  r.power_up();
  const CommandId id = r.submit(move_velocity(1));
  EXPECT_EQ(r.m.reset(), AxisError::None);
  EXPECT_EQ(r.status(id), CommandStatus::Active);
  EXPECT_FALSE(r.m.drive_command().reset);
}

TEST(AxisReset, DriveFaultResetIsHeldUntilTheFaultClears) {
  Rig r;
  r.power_up();
  r.d.fault = true;
  r.scan();
  ASSERT_EQ(r.m.state(), AxisState::ErrorStop);
  EXPECT_FALSE(r.m.drive_command().reset);
  EXPECT_EQ(r.m.reset(), AxisError::None);
  EXPECT_EQ(r.m.state(), AxisState::ErrorStop);
  EXPECT_TRUE(r.m.drive_command().reset);
  r.d.apply(r.m.drive_command());
  r.scans(3);  // the fault persists: reset held, still ErrorStop
  EXPECT_EQ(r.d.resets_seen, 4);
  EXPECT_EQ(r.m.state(), AxisState::ErrorStop);
  EXPECT_FALSE(r.m.drive_command().enable);
  r.d.fault = false;
  r.scan();
  EXPECT_FALSE(r.m.drive_command().reset);
  EXPECT_EQ(r.m.state(), AxisState::Disabled);  // the power stage is off after a fault
  EXPECT_EQ(r.m.axis_error(), AxisError::None);
  EXPECT_EQ(r.m.drive_fault_code(), 0);
  EXPECT_TRUE(r.m.drive_command().enable);  // MC_Power still asks
  r.scan();
  EXPECT_EQ(r.m.state(), AxisState::Standstill);
}

// The fault clears while the drive still coasts: the reset request drops with
// the fault, the reset completes once the axis stands.
TEST(AxisReset, PendingResetWaitsForStandstill) {
  Rig r;
  r.power_up();
  r.d.fault = true;
  r.scan();
  ASSERT_EQ(r.m.reset(), AxisError::None);
  EXPECT_TRUE(r.m.drive_command().reset);
  DriveFeedback f = r.d.feedback();
  f.fault = false;
  f.velocity = 0.3;  // coasting
  r.m.cycle(f);
  EXPECT_EQ(r.m.state(), AxisState::ErrorStop);
  EXPECT_FALSE(r.m.drive_command().reset);
  EXPECT_EQ(r.m.set_velocity(), 0.3);
  f.velocity = 0;
  r.m.cycle(f);
  EXPECT_EQ(r.m.state(), AxisState::Disabled);
  EXPECT_EQ(r.m.axis_error(), AxisError::None);
}

TEST(AxisReset, FaultClearedBeforeResetNeedsTheReset) {
  Rig r;
  r.power_up();
  r.d.fault = true;
  r.scan();
  r.d.fault = false;
  r.scans(5);
  EXPECT_EQ(r.m.state(), AxisState::ErrorStop);
  EXPECT_FALSE(r.m.drive_command().enable);  // no re-enable without MC_Reset
  EXPECT_EQ(r.m.reset(), AxisError::None);
  EXPECT_EQ(r.m.state(), AxisState::Disabled);
}

TEST(AxisReset, ToDisabledWhenPowerIsNotRequested) {
  AxisLimits l = default_limits();
  l.max_position_lag = 0.01;
  Rig r(l);
  r.power_up();
  r.d.position = 1;
  r.scan();
  ASSERT_EQ(r.m.state(), AxisState::ErrorStop);
  r.power = false;
  r.scans(3);
  EXPECT_EQ(r.m.state(), AxisState::ErrorStop);  // power off keeps ErrorStop
  EXPECT_FALSE(r.m.drive_command().enable);
  EXPECT_EQ(r.m.reset(), AxisError::None);
  EXPECT_EQ(r.m.state(), AxisState::Disabled);
}

// ---- submit's errors ---------------------------------------------------------------

TEST(AxisSubmit, InputErrors) {
  AxisLimits l = default_limits();
  l.sw_limit_pos = 5;
  l.sw_limit_neg = -5;
  l.sw_limit_pos_on = l.sw_limit_neg_on = true;
  Rig r(l);
  r.power_up();
  const double inf = INFINITY, nan = NAN;
  for (double v : {0.0, -1.0, 2.5, inf, nan}) EXPECT_EQ(r.reject(move_absolute(1, v)), AxisError::BadVelocity) << v;
  for (double v : {2.5, -2.5, inf, nan}) EXPECT_EQ(r.reject(move_velocity(v)), AxisError::BadVelocity) << v;
  for (double a : {-1.0, 21.0, inf, nan}) {
    EXPECT_EQ(r.reject(move_absolute(1, 1, BufferMode::Aborting, a)), AxisError::BadAcceleration) << a;
    EXPECT_EQ(r.reject(move_velocity(1, BufferMode::Aborting, a)), AxisError::BadAcceleration) << a;
  }
  for (double d : {-1.0, 41.0, inf, nan}) {
    EXPECT_EQ(r.reject(move_absolute(1, 1, BufferMode::Aborting, 0, d)), AxisError::BadDeceleration) << d;
    EXPECT_EQ(r.reject(halt(d)), AxisError::BadDeceleration) << d;
    EXPECT_EQ(r.reject(stop(d)), AxisError::BadDeceleration) << d;
  }
  for (double j : {1.0, -1.0, inf, nan}) {
    Command c = move_absolute(1, 1);
    c.jerk = j;
    EXPECT_EQ(r.reject(c), AxisError::BadJerk) << j;
  }
  for (double p : {5.5, -5.5, inf, nan}) EXPECT_EQ(r.reject(move_absolute(p, 1)), AxisError::BadPosition) << p;
  EXPECT_EQ(r.reject(move_relative(6, 1)), AxisError::BadPosition);
  EXPECT_EQ(r.reject(move_additive(-6, 1)), AxisError::BadPosition);
  EXPECT_EQ(r.reject(home(nan)), AxisError::BadPosition);
  for (int b : {6, 7, 255})
    EXPECT_EQ(r.reject(move_absolute(1, 1, static_cast<BufferMode>(b))), AxisError::BadBufferMode) << b;
  for (int d : {0, 5, 255}) {
    Command c = move_absolute(1, 1);
    c.direction = static_cast<Direction>(d);
    EXPECT_EQ(r.reject(c), AxisError::BadDirection) << d;
  }
  Command bad_kind = move_absolute(1, 1);
  bad_kind.kind = static_cast<CommandKind>(99);
  EXPECT_EQ(r.reject(bad_kind), AxisError::BadParameter);
  // Nothing changed.
  EXPECT_EQ(r.m.state(), AxisState::Standstill);
  EXPECT_EQ(r.m.active_command(), 0u);
  // The limits themselves are allowed.
  r.submit(move_absolute(5, 2, BufferMode::Aborting, 20, 40));
  r.submit(move_velocity(-2));
}

TEST(AxisSubmit, RejectedCommandChangesNothing) {
  Rig r;
  r.power_up();
  const CommandId a = r.submit(move_absolute(1, 1));
  const CommandId b = r.submit(move_absolute(0.5, 1, BufferMode::Buffered));
  r.scans(20);
  const double x = r.m.set_position(), v = r.m.set_velocity();
  EXPECT_EQ(r.reject(move_absolute(2, 5)), AxisError::BadVelocity);
  EXPECT_EQ(r.status(a), CommandStatus::Active);
  EXPECT_EQ(r.status(b), CommandStatus::Buffered);
  EXPECT_EQ(r.m.set_position(), x);
  EXPECT_EQ(r.m.set_velocity(), v);
  EXPECT_EQ(r.m.active_command(), a);
}

TEST(AxisSubmit, BufferFull) {
  Rig r;
  r.power_up();
  r.submit(move_absolute(1, 1));
  for (std::size_t i = 0; i < AxisMachine::kQueueCapacity; ++i) r.submit(move_relative(0.1, 1, BufferMode::Buffered));
  EXPECT_EQ(r.reject(move_relative(0.1, 1, BufferMode::Buffered)), AxisError::BufferFull);
  // Aborting still goes.
  r.submit(move_absolute(0, 1));
}

TEST(AxisSubmit, BufferedWithNothingActiveStartsAtOnce) {
  Rig r;
  r.power_up();
  const CommandId id = r.submit(move_absolute(0.1, 1, BufferMode::Buffered));
  EXPECT_EQ(r.status(id), CommandStatus::Active);
  EXPECT_EQ(r.m.state(), AxisState::DiscreteMotion);
}

// ---- reports -------------------------------------------------------------------

TEST(AxisReports, UnknownForNoneUnseenAndAgedOut) {
  Rig r;
  r.power_up();
  EXPECT_EQ(r.status(0), CommandStatus::Unknown);
  EXPECT_EQ(r.status(12345), CommandStatus::Unknown);
  const CommandId first = r.submit(move_velocity(0.1));
  for (std::size_t i = 0; i < AxisMachine::kReportCapacity; ++i) r.submit(move_velocity(0.1));
  EXPECT_EQ(r.status(first), CommandStatus::Aborted);  // 32 ended: still kept
  r.submit(move_velocity(0.1));
  EXPECT_EQ(r.status(first), CommandStatus::Unknown);  // 33 ended: left the table
}

TEST(AxisReports, IdsAreNeverReused) {
  Rig r;
  r.power_up();
  CommandId last = 0;
  for (int i = 0; i < 100; ++i) {
    const CommandId id = r.submit(move_velocity(0.1));
    EXPECT_GT(id, last);
    last = id;
  }
}

// ---- BufferMode ------------------------------------------------------------------

TEST(AxisBuffer, AbortingMidMoveIsContinuous) {
  Rig r;
  r.power_up();
  const CommandId a = r.submit(move_absolute(1, 1.5, BufferMode::Aborting, 5, 8));
  r.scans(300);
  ASSERT_EQ(r.status(a), CommandStatus::Active);
  const double x0 = r.m.set_position(), v0 = r.m.set_velocity();
  ASSERT_GT(v0, 0.5);
  const CommandId b = r.submit(move_absolute(-0.5, 1, BufferMode::Aborting, 10, 10));
  EXPECT_EQ(r.status(a), CommandStatus::Aborted);
  EXPECT_EQ(r.status(b), CommandStatus::Active);
  r.scan();
  // No jump: the new profile starts from the set values (first sample brakes).
  EXPECT_NEAR(r.m.set_velocity(), v0 - 10 * kT, 1e-9);
  EXPECT_LE(std::fabs(r.m.set_position() - (x0 + v0 * kT)), 10 * kT * kT);
  double v = r.m.set_velocity();
  int n = 0;
  while (r.status(b) == CommandStatus::Active && n++ < 100000) {
    r.scan();
    EXPECT_LE(std::fabs(r.m.set_velocity() - v), 10 * kT * (1 + 1e-9));
    EXPECT_LE(std::fabs(r.m.set_velocity()), std::max(v0, 1.0) + 1e-12);
    v = r.m.set_velocity();
  }
  EXPECT_EQ(r.status(b), CommandStatus::Done);
  EXPECT_EQ(r.m.set_position(), -0.5);
}

// Three buffered moves: each becomes Active in the cycle the one before is
// Done, each is Done once, the axis never stops in between in Standstill.
TEST(AxisBuffer, BufferedChainOfThree) {
  Rig r;
  r.power_up();
  const CommandId ids[3] = {r.submit(move_absolute(0.2, 1)), r.submit(move_relative(-0.1, 0.5, BufferMode::Buffered)),
                            r.submit(move_absolute(0.3, 2, BufferMode::Buffered))};
  EXPECT_EQ(r.status(ids[1]), CommandStatus::Buffered);
  EXPECT_EQ(r.status(ids[2]), CommandStatus::Buffered);
  int done_count[3] = {0, 0, 0};
  CommandStatus prev[3] = {CommandStatus::Active, CommandStatus::Buffered, CommandStatus::Buffered};
  for (int i = 0; i < 100000 && r.status(ids[2]) != CommandStatus::Done; ++i) {
    r.scan();
    for (int k = 0; k < 3; ++k) {
      const CommandStatus s = r.status(ids[k]);
      if (s == CommandStatus::Done && prev[k] != CommandStatus::Done) {
        ++done_count[k];
        if (k < 2) {
          EXPECT_EQ(r.status(ids[k + 1]), CommandStatus::Active) << k;  // the same cycle
          EXPECT_EQ(r.m.active_command(), ids[k + 1]);
          EXPECT_EQ(r.m.state(), AxisState::DiscreteMotion);
        }
      }
      if (prev[k] == CommandStatus::Done) { EXPECT_EQ(s, CommandStatus::Done); }
      prev[k] = s;
    }
  }
  EXPECT_EQ(done_count[0], 1);
  EXPECT_EQ(done_count[1], 1);
  EXPECT_EQ(done_count[2], 1);
  EXPECT_EQ(r.m.set_position(), 0.3);
  EXPECT_EQ(r.m.state(), AxisState::Standstill);
}

TEST(AxisBuffer, BufferedAfterVelocityStartsInVelocity) {
  Rig r;
  r.power_up();
  const CommandId mv = r.submit(move_velocity(1, BufferMode::Aborting, 10));
  const CommandId h = r.submit(halt(0, BufferMode::Buffered));
  int n = 0;
  while (r.status(mv) == CommandStatus::Active && n < 1000) {
    EXPECT_FALSE(r.m.report(mv).in_velocity);
    r.scan();
    ++n;
  }
  EXPECT_EQ(n, 100);  // 1 u/s at 10 u/s^2, 1 ms
  EXPECT_EQ(r.status(mv), CommandStatus::Aborted);
  EXPECT_EQ(r.status(h), CommandStatus::Active);
  EXPECT_EQ(r.m.set_velocity(), 1);
  ASSERT_GT(r.run_until_end(h), 0);
  EXPECT_EQ(r.m.state(), AxisState::Standstill);
}

// Blending (§2.4.2): the first move passes its goal with the blending
// velocity (capped by its own bound) and is Done there; the second takes over
// in the same cycle from the set values: position and velocity continuous.
TEST(AxisBuffer, BlendingPassesTheGoalContinuously) {
  struct Case {
    BufferMode mode;
    double v_blend;  // expected at the hand-over: A 1 u/s, B 0.5 u/s
  };
  for (const Case c : {Case{BufferMode::BlendingLow, 0.5}, Case{BufferMode::BlendingHigh, 1},
                       Case{BufferMode::BlendingPrevious, 1}, Case{BufferMode::BlendingNext, 0.5}}) {
    SCOPED_TRACE(static_cast<int>(c.mode));
    Rig r;
    r.power_up();
    const double acc = 10, dec = 10;
    const CommandId a = r.submit(move_absolute(1, 1, BufferMode::Aborting, acc, dec));
    Command rel = move_absolute(1, 0.5, c.mode, acc, dec);
    rel.kind = CommandKind::MoveRelative;
    const CommandId b = r.submit(rel);  // from A's goal: to 2
    EXPECT_EQ(r.status(b), CommandStatus::Buffered);
    double x = r.m.set_position(), v = r.m.set_velocity();
    int dones = 0;
    for (int i = 0; i < 100000 && r.status(b) != CommandStatus::Done; ++i) {
      const CommandStatus before = r.status(a);
      r.scan();
      const double xn = r.m.set_position(), vn = r.m.set_velocity();
      EXPECT_LE(std::fabs(vn - v), std::max(acc, dec) * kT * (1 + 1e-9));
      EXPECT_LE(std::fabs(xn - x), 1 * kT * (1 + 1e-12));
      EXPECT_GE(vn, 0);  // never stops and turns
      if (before == CommandStatus::Active && r.status(a) == CommandStatus::Done) {
        ++dones;
        EXPECT_GE(xn, 1);                // passed the goal
        EXPECT_LT(xn, 1 + 1 * kT);       // within the sample
        EXPECT_NEAR(vn, c.v_blend, 2 * dec * kT);
        EXPECT_EQ(r.status(b), CommandStatus::Active);
        EXPECT_EQ(r.m.state(), AxisState::DiscreteMotion);
      }
      x = xn;
      v = vn;
    }
    EXPECT_EQ(dones, 1);
    EXPECT_EQ(r.status(b), CommandStatus::Done);
    EXPECT_EQ(r.m.set_position(), 2);
    EXPECT_EQ(r.m.state(), AxisState::Standstill);
  }
}

TEST(AxisBuffer, BlendingIntoAReversalStopsAtTheGoal) {
  Rig r;
  r.power_up();
  const CommandId a = r.submit(move_absolute(1, 1));
  const CommandId b = r.submit(move_absolute(0.5, 1, BufferMode::BlendingHigh));
  for (int i = 0; i < 100000 && r.status(a) == CommandStatus::Active; ++i) r.scan();
  ASSERT_EQ(r.status(a), CommandStatus::Done);
  EXPECT_EQ(r.m.set_position(), 1);
  EXPECT_EQ(r.m.set_velocity(), 0);
  EXPECT_EQ(r.status(b), CommandStatus::Active);
  ASSERT_GT(r.run_until_end(b), 0);
  EXPECT_EQ(r.m.set_position(), 0.5);
}

TEST(AxisBuffer, BlendingAfterAVelocityMoveIsBuffered) {
  Rig r;
  r.power_up();
  const CommandId mv = r.submit(move_velocity(1, BufferMode::Aborting, 10));
  const CommandId b = r.submit(move_relative(0.5, 1, BufferMode::BlendingLow));
  EXPECT_EQ(r.run_until_end(mv), 100);
  EXPECT_EQ(r.status(b), CommandStatus::Active);
}

TEST(AxisBuffer, AdditiveAddsToThePreviousGoal) {
  Rig r;
  r.power_up();
  r.submit(move_absolute(0.5, 1));
  r.scans(50);
  const CommandId a = r.submit(move_additive(0.25, 1));  // aborting in DiscreteMotion: 0.5 + 0.25
  ASSERT_GT(r.run_until_end(a), 0);
  EXPECT_EQ(r.m.set_position(), 0.75);
  r.submit(move_absolute(1, 1));
  const CommandId b = r.submit(move_additive(-0.5, 1, BufferMode::Buffered));  // 1 - 0.5
  ASSERT_GT(r.run_until_end(b), 0);
  EXPECT_EQ(r.m.set_position(), 0.5);
  const CommandId c = r.submit(move_additive(0.125, 1));  // standing: set position + distance
  ASSERT_GT(r.run_until_end(c), 0);
  EXPECT_EQ(r.m.set_position(), 0.625);
  r.submit(move_velocity(0.5));
  r.scans(100);
  const double x = r.m.set_position();
  const CommandId d = r.submit(move_additive(0.5, 1));  // aborting a velocity move: set position + distance
  ASSERT_GT(r.run_until_end(d), 0);
  EXPECT_EQ(r.m.set_position(), x + 0.5);
}

TEST(AxisBuffer, RelativeStartsFromTheSetPosition) {
  Rig r;
  r.power_up();
  r.submit(move_absolute(1, 1));
  r.scans(100);
  const double x = r.m.set_position();
  const CommandId id = r.submit(move_relative(0.25, 1));
  ASSERT_GT(r.run_until_end(id), 0);
  EXPECT_EQ(r.m.set_position(), x + 0.25);
}

// ---- MC_SetPosition, parameters, drive command -------------------------------------

TEST(AxisSetPosition, StandstillOrDisabledOnly) {
  Rig r;
  EXPECT_EQ(r.m.set_position(2, false), AxisError::None);  // Disabled
  EXPECT_EQ(r.m.set_position(), 2);
  r.power_up();
  EXPECT_EQ(r.m.set_position(), 2);
  EXPECT_EQ(r.m.actual_position(), 2);
  EXPECT_EQ(r.m.set_position(1, true), AxisError::None);
  EXPECT_EQ(r.m.set_position(), 3);
  EXPECT_EQ(r.m.set_position(NAN, false), AxisError::BadPosition);
  r.scan();
  EXPECT_EQ(r.m.actual_position(), 3);
  EXPECT_EQ(r.m.following_error(), 0);
  EXPECT_EQ(r.m.drive_command().position, 0);  // the drive did not move
  EXPECT_EQ(r.m.state(), AxisState::Standstill);
  r.submit(move_velocity(1));
  EXPECT_EQ(r.m.set_position(0, false), AxisError::NotStandstill);
}

TEST(AxisParameters, ReadAndWrite) {
  AxisLimits l = default_limits();
  l.j_max = 100;
  l.max_position_lag = 0.5;
  Rig r(l);
  auto P = [](AxisParameter p) { return static_cast<std::int16_t>(p); };
  double v = 0;
  EXPECT_EQ(r.m.read_parameter(P(AxisParameter::MaxVelocitySystem), &v), AxisError::None);
  EXPECT_EQ(v, 2);
  EXPECT_EQ(r.m.read_parameter(P(AxisParameter::EnablePosLagMonitoring), &v), AxisError::None);
  EXPECT_EQ(v, 1);
  EXPECT_EQ(r.m.read_parameter(0, &v), AxisError::BadParameter);
  EXPECT_EQ(r.m.read_parameter(18, &v), AxisError::BadParameter);
  EXPECT_EQ(r.m.read_parameter(1, nullptr), AxisError::BadParameter);
  // Read only.
  for (AxisParameter p : {AxisParameter::CommandedPosition, AxisParameter::MaxVelocitySystem,
                          AxisParameter::ActualVelocity, AxisParameter::CommandedVelocity,
                          AxisParameter::MaxAccelerationSystem, AxisParameter::MaxDecelerationSystem,
                          AxisParameter::MaxJerkSystem})
    EXPECT_EQ(r.m.write_parameter(P(p), 1), AxisError::BadParameter) << static_cast<int>(p);
  // Ranges.
  EXPECT_EQ(r.m.write_parameter(P(AxisParameter::MaxVelocityAppl), 0), AxisError::BadParameter);
  EXPECT_EQ(r.m.write_parameter(P(AxisParameter::MaxVelocityAppl), 2.1), AxisError::BadParameter);
  EXPECT_EQ(r.m.write_parameter(P(AxisParameter::MaxVelocityAppl), NAN), AxisError::BadParameter);
  EXPECT_EQ(r.m.write_parameter(P(AxisParameter::MaxVelocityAppl), 1), AxisError::None);
  EXPECT_EQ(r.m.limits().v_max, 1);
  EXPECT_EQ(r.m.system_limits().v_max, 2);
  EXPECT_EQ(r.m.write_parameter(P(AxisParameter::MaxAccelerationAppl), 21), AxisError::BadParameter);
  EXPECT_EQ(r.m.write_parameter(P(AxisParameter::MaxAccelerationAppl), 5), AxisError::None);
  EXPECT_EQ(r.m.write_parameter(P(AxisParameter::MaxDecelerationAppl), -1), AxisError::BadParameter);
  EXPECT_EQ(r.m.write_parameter(P(AxisParameter::MaxDecelerationAppl), 6), AxisError::None);
  EXPECT_EQ(r.m.write_parameter(P(AxisParameter::MaxJerkAppl), 101), AxisError::BadParameter);
  EXPECT_EQ(r.m.write_parameter(P(AxisParameter::MaxJerkAppl), 0), AxisError::None);
  EXPECT_EQ(r.m.write_parameter(P(AxisParameter::MaxPositionLag), -1), AxisError::BadParameter);
  EXPECT_EQ(r.m.write_parameter(P(AxisParameter::EnableLimitPos), 0.5), AxisError::BadParameter);
  EXPECT_EQ(r.m.write_parameter(P(AxisParameter::SWLimitPos), -1), AxisError::None);
  EXPECT_EQ(r.m.write_parameter(P(AxisParameter::SWLimitNeg), 1), AxisError::None);
  EXPECT_EQ(r.m.write_parameter(P(AxisParameter::EnableLimitPos), 1), AxisError::None);
  EXPECT_EQ(r.m.write_parameter(P(AxisParameter::EnableLimitNeg), 1), AxisError::BadParameter);  // neg >= pos
  EXPECT_EQ(r.m.write_parameter(P(AxisParameter::SWLimitNeg), -2), AxisError::None);
  EXPECT_EQ(r.m.write_parameter(P(AxisParameter::EnableLimitNeg), 1), AxisError::None);
  EXPECT_EQ(r.m.write_parameter(P(AxisParameter::SWLimitNeg), 0), AxisError::BadParameter);
  EXPECT_EQ(r.m.write_parameter(99, 0), AxisError::BadParameter);
  // The appl limits bound new commands.
  r.power_up();
  EXPECT_EQ(r.reject(move_absolute(-1.5, 1.5)), AxisError::BadVelocity);
  EXPECT_EQ(r.reject(move_absolute(-1.5, 1, BufferMode::Aborting, 6)), AxisError::BadAcceleration);
  EXPECT_EQ(r.reject(move_absolute(-1.5, 1, BufferMode::Aborting, 0, 7)), AxisError::BadDeceleration);
  EXPECT_EQ(r.reject(move_absolute(-2.5, 1)), AxisError::BadPosition);
  // Lag monitoring off/on.
  EXPECT_EQ(r.m.write_parameter(P(AxisParameter::EnablePosLagMonitoring), 0), AxisError::None);
  EXPECT_EQ(r.m.limits().max_position_lag, 0);
  r.d.position += 1;
  r.scan();
  EXPECT_EQ(r.m.state(), AxisState::Standstill);
  EXPECT_EQ(r.m.write_parameter(P(AxisParameter::EnablePosLagMonitoring), 1), AxisError::None);
  EXPECT_EQ(r.m.limits().max_position_lag, 0.5);
  EXPECT_EQ(r.m.read_parameter(P(AxisParameter::MaxPositionLag), &v), AxisError::None);
  EXPECT_EQ(v, 0.5);
  r.d.position += 1;
  r.scan();
  EXPECT_EQ(r.m.axis_error(), AxisError::FollowingError);
}

TEST(AxisParameters, CommandedAndActualValues) {
  Rig r;
  r.power_up();
  r.submit(move_velocity(1));
  r.scans(50);
  auto P = [](AxisParameter p) { return static_cast<std::int16_t>(p); };
  double v = 0;
  ASSERT_EQ(r.m.read_parameter(P(AxisParameter::CommandedVelocity), &v), AxisError::None);
  EXPECT_EQ(v, r.m.set_velocity());
  ASSERT_EQ(r.m.read_parameter(P(AxisParameter::ActualVelocity), &v), AxisError::None);
  EXPECT_EQ(v, r.m.actual_velocity());
  ASSERT_EQ(r.m.read_parameter(P(AxisParameter::CommandedPosition), &v), AxisError::None);
  EXPECT_EQ(v, r.m.set_position());
}

TEST(AxisDriveCommand, SetValuesInDriveCoordinates) {
  Rig r;
  r.power_up();
  ASSERT_EQ(r.m.set_position(10, false), AxisError::None);
  r.submit(move_velocity(1));
  r.scans(20);
  const DriveCommand& c = r.m.drive_command();
  EXPECT_TRUE(c.enable);
  EXPECT_EQ(c.position, r.m.set_position() - 10);
  EXPECT_EQ(c.velocity, r.m.set_velocity());
  EXPECT_EQ(c.acceleration, r.m.set_acceleration());
  EXPECT_NEAR(c.acceleration, r.m.limits().a_max, 1e-9);  // still accelerating over the coming scan
}

}  // namespace
}  // namespace syncplc::plcopen::test
