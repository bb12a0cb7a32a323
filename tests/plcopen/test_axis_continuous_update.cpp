// ContinuousUpdate of the discrete moves and MC_MoveVelocity (AxisMachine::update,
// fblocks/plcopen/axis_update.cpp; PLCopen Part 1 v2.0 §2.4.1): a move
// re-targeted in flight, on the axis alone, scan by scan.
#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "tests/plcopen/axis_rig.hpp"

namespace syncplc::plcopen::test {
namespace {

TEST(AxisContinuousUpdate, RandomReTargetsArriveExactlyAndContinuously) {
  std::mt19937 rng(31);
  std::uniform_real_distribution<double> U(0, 1);
  for (int n = 0; n < 200; ++n) {
    const double T = 0.001;
    const double J = n % 2 ? 0 : 4000 + 20000 * U(rng);  // half jerk-limited
    AxisLimits l = default_limits();  // v 2, a 20
    // Acceleration = Deceleration: the remaining-scans figure is exact also
    // when the new goal lies behind (docs/motion/jerk-profile.md).
    l.d_max = 20;
    Rig r(l, T);
    r.power_up();
    Command c = move_absolute(-1 + 2 * U(rng), 0.5 + 1.5 * U(rng));
    c.jerk = J;
    const CommandId id = r.submit(c);
    const int first = 1 + static_cast<int>(600 * U(rng));
    double v_prev = r.m.set_velocity(), x_prev = r.m.set_position();
    double worst_dv = 0;
    for (int i = 0; i < first && r.status(id) == CommandStatus::Active; ++i) {
      r.scan();
      worst_dv = std::fmax(worst_dv, std::fabs(r.m.set_velocity() - v_prev));
      v_prev = r.m.set_velocity();
      x_prev = r.m.set_position();
    }
    if (r.status(id) != CommandStatus::Active) continue;  // arrived before the update
    c.position = -1 + 2 * U(rng);
    ASSERT_EQ(r.m.update(id, c), AxisError::None);
    const std::int64_t predicted = r.m.remaining_scans();
    std::int64_t scans = 0;
    while (r.status(id) == CommandStatus::Active && scans < 1000000) {
      r.scan();
      ++scans;
      worst_dv = std::fmax(worst_dv, std::fabs(r.m.set_velocity() - v_prev));
      ASSERT_NEAR(r.m.set_position() - x_prev, T * (v_prev + r.m.set_velocity()) / 2, 1e-12);
      v_prev = r.m.set_velocity();
      x_prev = r.m.set_position();
      ASSERT_LE(std::fabs(r.m.set_velocity()), c.velocity * (1 + 1e-12));
    }
    SCOPED_TRACE(::testing::Message() << "case " << n);
    ASSERT_EQ(r.status(id), CommandStatus::Done);
    EXPECT_EQ(r.m.set_position(), c.position);
    EXPECT_EQ(r.m.set_velocity(), 0);
    EXPECT_EQ(scans, predicted);
    EXPECT_LE(worst_dv, 20 * T * (1 + 1e-9));  // the velocity never jumps: at most d_max T a scan
  }
}

TEST(AxisContinuousUpdate, RelativeDistanceCountsFromWhereTheMoveStarted) {
  Rig r;
  r.power_up();
  ASSERT_EQ(r.m.set_position(1, false), AxisError::None);
  Command c = move_relative(2, 1);
  c.position = 0.5;  // from 1 to 1.5
  const CommandId id = r.submit(c);
  r.scans(100);
  c.position = -0.25;  // now to 0.75: from the start, not from where it is
  ASSERT_EQ(r.m.update(id, c), AxisError::None);
  r.run_until_end(id);
  EXPECT_EQ(r.status(id), CommandStatus::Done);
  EXPECT_EQ(r.m.set_position(), 0.75);
}

TEST(AxisContinuousUpdate, AdditiveDistanceCountsFromTheGoalItWasAddedTo) {
  Rig r;
  r.power_up();
  const CommandId a = r.submit(move_absolute(1, 1));
  r.scans(50);
  const CommandId b = r.submit(move_additive(0.5, 1));  // Aborting: 1 + 0.5
  EXPECT_EQ(r.status(a), CommandStatus::Aborted);
  r.scans(50);
  ASSERT_EQ(r.m.update(b, move_additive(-0.5, 1)), AxisError::None);  // now 1 - 0.5
  r.run_until_end(b);
  EXPECT_EQ(r.m.set_position(), 0.5);
}

TEST(AxisContinuousUpdate, ABufferedMoveTakesItsNewInputsWhenItStarts) {
  Rig r;
  r.power_up();
  const CommandId a = r.submit(move_absolute(1, 1));
  const CommandId b = r.submit(move_absolute(2, 1, BufferMode::Buffered));
  r.scans(10);
  ASSERT_EQ(r.m.update(b, move_absolute(-1, 1, BufferMode::Aborting)), AxisError::None);
  EXPECT_EQ(r.status(b), CommandStatus::Buffered);  // its BufferMode stays
  r.run_until_end(a);
  EXPECT_EQ(r.m.set_position(), 1);
  r.run_until_end(b);
  EXPECT_EQ(r.status(b), CommandStatus::Done);
  EXPECT_EQ(r.m.set_position(), -1);
}

TEST(AxisContinuousUpdate, AVelocityMoveRampsToItsNewVelocity) {
  for (double jerk : {0.0, 4000.0}) {
    const double T = 0.001;
    Rig r(default_limits(), T);  // v 2, a 20, d 40
    r.power_up();
    Command c = move_velocity(1);
    c.jerk = jerk;
    const CommandId id = r.submit(c);
    int guard = 0;
    while (!r.m.report(id).in_velocity && ++guard < 10000) r.scan();
    ASSERT_TRUE(r.m.report(id).in_velocity);
    c.velocity = -0.5;
    ASSERT_EQ(r.m.update(id, c), AxisError::None);
    EXPECT_FALSE(r.m.report(id).in_velocity);
    double v_prev = r.m.set_velocity(), a_prev = 0, worst_jerk = 0;
    guard = 0;
    while (!r.m.report(id).in_velocity && ++guard < 10000) {
      r.scan();
      const double a = (r.m.set_velocity() - v_prev) / T;
      ASSERT_GE(a, -40 * (1 + 1e-9));  // slowing down from +1 with d, then speeding up in - with a
      ASSERT_LE(std::fabs(a), 40 * (1 + 1e-9));
      worst_jerk = std::fmax(worst_jerk, std::fabs(a - a_prev) / T);
      a_prev = a;
      v_prev = r.m.set_velocity();
    }
    SCOPED_TRACE(::testing::Message() << "jerk " << jerk);
    ASSERT_TRUE(r.m.report(id).in_velocity);
    EXPECT_EQ(r.m.set_velocity(), -0.5);
    EXPECT_EQ(r.status(id), CommandStatus::Active);  // a velocity move is never Done
    if (jerk > 0) {
      EXPECT_LE(worst_jerk, jerk * (1 + 1e-6));
    }
  }
}

TEST(AxisContinuousUpdate, RefusedInputsLeaveTheMoveAsItWas) {
  AxisLimits l = default_limits();
  l.sw_limit_pos = 3;
  l.sw_limit_pos_on = true;
  Rig r(l);
  r.power_up();
  const CommandId id = r.submit(move_absolute(1, 1));
  r.scans(20);
  EXPECT_EQ(r.m.update(id, move_absolute(1, 5)), AxisError::BadVelocity);
  EXPECT_EQ(r.m.update(id, move_absolute(4, 1)), AxisError::BadPosition);
  EXPECT_EQ(r.m.update(id, move_velocity(1)), AxisError::BadParameter);  // another kind of command
  Command neg = move_absolute(2, 1);
  neg.jerk = -1;
  EXPECT_EQ(r.m.update(id, neg), AxisError::BadJerk);
  r.run_until_end(id);
  EXPECT_EQ(r.status(id), CommandStatus::Done);
  EXPECT_EQ(r.m.set_position(), 1);
  EXPECT_EQ(r.m.update(id, move_absolute(2, 1)), AxisError::None);  // ended: nothing to update
  r.scans(5);
  EXPECT_EQ(r.m.set_position(), 1);
}

}  // namespace
}  // namespace syncplc::plcopen::test
