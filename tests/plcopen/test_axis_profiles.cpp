// The set values of the PLCopen axis (fblocks/plcopen/axis_profile.cpp through
// axis_machine): discrete moves within their bounds, exact arrival, exact
// remaining time; velocity ramps; software-limit braking; modulo goals.
#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "fblocks/plcopen/axis_profile.hpp"
#include "tests/plcopen/axis_rig.hpp"

namespace syncplc::plcopen::test {
namespace {

// Hundreds of random moves from rest: |v| <= V, |dv|/T <= max(acc, dec), no
// overshoot (monotone towards the goal), x == goal bit for bit at Done, and
// remaining_scans() at the start is the number of cycles until Done.
TEST(AxisProfiles, RandomMovesFromRest) {
  std::mt19937_64 rng(20261129);
  std::uniform_real_distribution<double> U(0, 1);
  AxisLimits l;
  l.v_max = 3;
  l.a_max = 50;
  l.d_max = 50;
  for (int k = 0; k < 400; ++k) {
    const double T = std::vector<double>{0.001, 0.002, 0.004, 0.0005}[k % 4];
    Rig r(l, T);
    r.power_up();
    const double x0 = -2 + 4 * U(rng);
    ASSERT_EQ(r.m.set_position(x0, false), AxisError::None);
    const double goal = x0 + (U(rng) < 0.5 ? -1 : 1) * std::pow(10, -4 + 4 * U(rng));
    const double V = 0.01 + 2.99 * U(rng);
    const double acc = 0.5 + 49.5 * U(rng), dec = U(rng) < 0.2 ? 0 : 0.5 + 49.5 * U(rng);
    const double dec_eff = dec == 0 ? l.d_max : dec;
    SCOPED_TRACE(testing::Message() << "k=" << k << " x0=" << x0 << " goal=" << goal << " V=" << V << " acc=" << acc
                                    << " dec=" << dec << " T=" << T);
    const CommandId id = r.submit(move_absolute(goal, V, BufferMode::Aborting, acc, dec));
    const std::int64_t predicted = r.m.remaining_scans();
    const double dir = goal > x0 ? 1 : -1;
    const double amax = std::max(acc, dec_eff);
    double x = x0, v = 0;
    std::int64_t n = 0;
    bool ok = true;
    while (r.status(id) == CommandStatus::Active && n < 10000000) {
      r.scan();
      ++n;
      const double xn = r.m.set_position(), vn = r.m.set_velocity();
      ok &= std::fabs(vn) <= V * (1 + 1e-12);
      ok &= std::fabs(vn - v) <= amax * T * (1 + 1e-9);
      ok &= dir * (xn - x) >= 0;     // monotone
      ok &= dir * (xn - goal) <= 0;  // never past the goal
      ok &= dir * vn >= 0;
      if (!ok) {
        ADD_FAILURE() << "n=" << n << " x=" << xn << " v=" << vn;
        break;
      }
      x = xn;
      v = vn;
    }
    ASSERT_EQ(r.status(id), CommandStatus::Done);
    EXPECT_EQ(r.m.set_position(), goal);
    EXPECT_EQ(r.m.set_velocity(), 0);
    EXPECT_EQ(n, predicted);
    EXPECT_EQ(r.m.state(), AxisState::Standstill);
  }
}

// Random pairs of moves in one direction, each blending mode: the set values
// stay within the bounds of the two moves and continuous through the
// hand-over, the first is Done once where it passes its goal, the second
// arrives exactly.
TEST(AxisProfiles, RandomBlendedPairs) {
  std::mt19937_64 rng(424242);
  std::uniform_real_distribution<double> U(0, 1);
  AxisLimits l;
  l.v_max = 3;
  l.a_max = 50;
  l.d_max = 50;
  const double T = 0.001;
  for (int k = 0; k < 200; ++k) {
    Rig r(l, T);
    r.power_up();
    const double dir = k % 2 == 0 ? 1 : -1;
    const double g1 = dir * std::pow(10, -3 + 3 * U(rng)), g2 = g1 + dir * std::pow(10, -3 + 3 * U(rng));
    const double va = 0.05 + 2.95 * U(rng), vb = 0.05 + 2.95 * U(rng);
    const double acc = 1 + 49 * U(rng), dec = 1 + 49 * U(rng);
    const auto mode = static_cast<BufferMode>(2 + k % 4);
    SCOPED_TRACE(testing::Message() << "k=" << k << " g1=" << g1 << " g2=" << g2 << " va=" << va << " vb=" << vb);
    const CommandId a = r.submit(move_absolute(g1, va, BufferMode::Aborting, acc, dec));
    const CommandId b = r.submit(move_absolute(g2, vb, mode, acc, dec));
    double v = 0;
    int dones = 0;
    bool ok = true;
    for (int i = 0; i < 10000000 && r.status(b) != CommandStatus::Done && ok; ++i) {
      const bool a_active = r.status(a) == CommandStatus::Active;
      r.scan();
      const double xn = r.m.set_position(), vn = r.m.set_velocity();
      ok &= std::fabs(vn - v) <= std::max(acc, dec) * T * (1 + 1e-9);
      ok &= std::fabs(vn) <= std::max(va, vb) * (1 + 1e-12);
      ok &= dir * vn >= 0 && dir * (xn - g2) <= 0;
      if (a_active && r.status(a) == CommandStatus::Done) {
        ++dones;
        ok &= dir * (xn - g1) >= 0 && r.status(b) == CommandStatus::Active;
      }
      if (!ok) ADD_FAILURE() << "i=" << i << " x=" << xn << " v=" << vn;
      v = vn;
    }
    EXPECT_EQ(dones, 1);
    EXPECT_EQ(r.status(b), CommandStatus::Done);
    EXPECT_EQ(r.m.set_position(), g2);
  }
}

TEST(AxisProfiles, RemainingScansCountsDownByOne) {
  Rig r;
  r.power_up();
  const CommandId id = r.submit(move_absolute(0.3, 1, BufferMode::Aborting, 7, 13));
  std::int64_t rem = r.m.remaining_scans();
  ASSERT_GT(rem, 2);
  while (r.status(id) == CommandStatus::Active) {
    r.scan();
    if (r.status(id) == CommandStatus::Active) { EXPECT_EQ(r.m.remaining_scans(), rem - 1); }
    --rem;
  }
  EXPECT_EQ(rem, 0);
  EXPECT_EQ(r.m.remaining_scans(), 0);
}

TEST(AxisProfiles, MoveVelocityRampsWithAccThenDec) {
  Rig r;
  r.power_up();
  const CommandId id = r.submit(move_velocity(1, BufferMode::Aborting, 10, 20));
  for (int i = 1; i <= 100; ++i) {
    EXPECT_FALSE(r.m.report(id).in_velocity);
    const double x = r.m.set_position(), v = r.m.set_velocity();
    r.scan();
    EXPECT_NEAR(r.m.set_velocity(), 0.01 * i, 1e-12);
    EXPECT_NEAR(r.m.set_position(), x + 0.001 * (v + r.m.set_velocity()) / 2, 1e-15);
  }
  EXPECT_EQ(r.m.set_velocity(), 1);
  EXPECT_TRUE(r.m.report(id).in_velocity);
  EXPECT_EQ(r.m.set_acceleration(), 0);
  // Reverse: dec (20) down to zero, then acc (10) up.
  const CommandId back = r.submit(move_velocity(-0.5, BufferMode::Aborting, 10, 20));
  r.scan();
  EXPECT_NEAR(r.m.set_velocity(), 1 - 0.02, 1e-12);
  r.scans(49);
  EXPECT_NEAR(r.m.set_velocity(), 0, 1e-12);
  r.scans(10);
  EXPECT_NEAR(r.m.set_velocity(), -0.1, 1e-9);
  for (int i = 0; i < 100 && !r.m.report(back).in_velocity; ++i) r.scan();
  EXPECT_EQ(r.m.set_velocity(), -0.5);
  EXPECT_TRUE(r.m.report(back).in_velocity);
  // Zero is a valid target.
  const CommandId zero = r.submit(move_velocity(0));
  for (int i = 0; i < 100 && !r.m.report(zero).in_velocity; ++i) r.scan();
  EXPECT_EQ(r.m.set_velocity(), 0);
  EXPECT_EQ(r.m.state(), AxisState::ContinuousMotion);
}

TEST(AxisProfiles, HaltAndStopRampWithTheirDeceleration) {
  for (bool is_stop : {false, true}) {
    Rig r;
    r.power_up();
    r.submit(move_velocity(2));
    r.scans(200);
    const CommandId id = r.submit(is_stop ? stop(8) : halt(8));
    EXPECT_EQ(r.m.remaining_scans(), 250);
    const int n = r.run_until_end(id);
    EXPECT_EQ(n, 250);
    EXPECT_EQ(r.status(id), CommandStatus::Done);
    EXPECT_EQ(r.m.set_velocity(), 0);
    EXPECT_EQ(r.m.state(), is_stop ? AxisState::Stopping : AxisState::Standstill);
  }
}

// A velocity move towards an enabled limit: ErrorStop(SoftLimit), braked with
// the system deceleration so that the set position never passes the limit.
TEST(AxisProfiles, SoftLimitBrakingNeverPassesTheLimit) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> U(0, 1);
  for (int k = 0; k < 200; ++k) {
    AxisLimits l = default_limits();
    l.d_max = 1 + 59 * U(rng);
    l.a_max = 1 + 59 * U(rng);
    const bool positive = k % 2 == 0;
    l.sw_limit_pos = 0.01 + U(rng);
    l.sw_limit_neg = -0.01 - U(rng);
    l.sw_limit_pos_on = l.sw_limit_neg_on = true;
    const double T = k % 3 == 0 ? 0.004 : 0.001;
    Rig r(l, T);
    r.power_up();
    const double v = (positive ? 1 : -1) * (0.05 + 1.95 * U(rng));
    SCOPED_TRACE(testing::Message() << "k=" << k << " v=" << v << " d=" << l.d_max);
    const CommandId id = r.submit(move_velocity(v));
    double vp = 0;
    for (int i = 0; i < 100000 && !(r.m.state() == AxisState::ErrorStop && r.m.set_velocity() == 0); ++i) {
      r.scan();
      ASSERT_LE(r.m.set_position(), l.sw_limit_pos);
      ASSERT_GE(r.m.set_position(), l.sw_limit_neg);
      ASSERT_LE(std::fabs(r.m.set_velocity() - vp), std::max(l.a_max, l.d_max) * T * (1 + 1e-9));
      vp = r.m.set_velocity();
    }
    EXPECT_EQ(r.m.state(), AxisState::ErrorStop);
    EXPECT_EQ(r.m.axis_error(), AxisError::SoftLimit);
    EXPECT_EQ(r.m.report(id).error, AxisError::SoftLimit);
    EXPECT_EQ(r.m.set_velocity(), 0);
    // It stops close to the limit, not far before it: within what one
    // accelerating sample adds to the reach x + v^2/(2d) (plus the discrete
    // ramp's rounding dT^2/8 on either side).
    const double lim = positive ? l.sw_limit_pos : l.sw_limit_neg;
    const double s = std::fabs(v), a = l.a_max, d = l.d_max;
    EXPECT_LE(std::fabs(r.m.set_position() - lim),
              s * T + a * T * T / 2 + s * a * T / d + a * a * T * T / (2 * d) + d * T * T / 4);
    // Reset, then a move away from the limit is fine.
    ASSERT_EQ(r.m.reset(), AxisError::None);
    EXPECT_EQ(r.m.state(), AxisState::Standstill);
    const CommandId back = r.submit(move_absolute(0, 1));
    ASSERT_GT(r.run_until_end(back), 0);
    EXPECT_EQ(r.status(back), CommandStatus::Done);
  }
}

TEST(AxisProfiles, LimitWrittenBehindADiscreteMoveStopsIt) {
  Rig r;
  r.power_up();
  r.submit(move_absolute(1, 1));
  r.scans(100);
  ASSERT_EQ(r.m.write_parameter(static_cast<std::int16_t>(AxisParameter::SWLimitPos), 0.5), AxisError::None);
  ASSERT_EQ(r.m.write_parameter(static_cast<std::int16_t>(AxisParameter::EnableLimitPos), 1), AxisError::None);
  for (int i = 0; i < 2000; ++i) {
    r.scan();
    ASSERT_LE(r.m.set_position(), 0.5);
  }
  EXPECT_EQ(r.m.axis_error(), AxisError::SoftLimit);
}

// MC_MoveAbsolute on a modulo axis (360): the goal by Direction.
TEST(AxisProfiles, ModuloGoalsByDirection) {
  AxisLimits l = default_limits();
  l.modulo = 360;
  l.v_max = 1000;
  l.a_max = l.d_max = 10000;
  struct Case {
    double from, target;
    Direction dir;
    double velocity_before;  // a MoveVelocity first, for Current
    double goal;             // continuous
  };
  const Case cases[] = {
      {350, 10, Direction::Positive, 0, 370},  {350, 10, Direction::Negative, 0, 10},
      {350, 10, Direction::Shortest, 0, 370},  {10, 350, Direction::Shortest, 0, -10},
      {0, 180, Direction::Shortest, 0, 180},   {350, 350, Direction::Positive, 0, 350},
      {350, 350, Direction::Negative, 0, 350}, {10, 20, Direction::Negative, 0, -340},
      {100, 90, Direction::Positive, 0, 450},  {100, 200, Direction::Current, 0, 200},
      {100, 90, Direction::Current, 0, 90},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(testing::Message() << c.from << " -> " << c.target << " dir " << static_cast<int>(c.dir));
    Rig r(l);
    r.power_up();
    ASSERT_EQ(r.m.set_position(c.from, false), AxisError::None);
    Command cmd = move_absolute(c.target, 500);
    cmd.direction = c.dir;
    const CommandId id = r.submit(cmd);
    ASSERT_GT(r.run_until_end(id), 0);
    EXPECT_EQ(r.m.set_position(), c.goal);
    EXPECT_EQ(r.m.user_position(r.m.set_position()), c.target);
  }
  // Current while moving: the direction of the set velocity.
  for (double v : {100.0, -100.0}) {
    Rig r(l);
    r.power_up();
    ASSERT_EQ(r.m.set_position(100, false), AxisError::None);
    r.submit(move_velocity(v));
    r.scans(1);
    Command cmd = move_absolute(100, 500);
    cmd.direction = Direction::Current;
    const double x = r.m.set_position();
    const CommandId id = r.submit(cmd);
    ASSERT_GT(r.run_until_end(id), 0);
    EXPECT_EQ(r.m.set_position(), v > 0 ? 460 : -260) << x;
  }
  Rig r(l);
  r.power_up();
  EXPECT_EQ(r.reject(move_absolute(360, 1)), AxisError::BadPosition);
  EXPECT_EQ(r.reject(move_absolute(-1, 1)), AxisError::BadPosition);
}

TEST(AxisProfiles, ModuloAxisShowsWrappedPositions) {
  AxisLimits l = default_limits();
  l.modulo = 360;
  Rig r(l);
  r.d.position = 725;
  r.scan();
  EXPECT_EQ(r.m.actual_position(), 5);
  EXPECT_EQ(r.m.set_position(), 725);  // continuous inside
  EXPECT_EQ(r.m.user_position(-1), 359);
  double v = 0;
  ASSERT_EQ(r.m.read_parameter(static_cast<std::int16_t>(AxisParameter::CommandedPosition), &v), AxisError::None);
  EXPECT_EQ(v, 5);
}

TEST(AxisProfiles, BrakingDistanceIsTheRampsSum) {
  for (double v : {0.0, 0.001, 0.0105, 1.0, 2.3456, -0.77}) {
    for (double d : {1.0, 7.5, 40.0}) {
      const double T = 0.001;
      motion::FilterState s{0, v};
      int n = 0;
      while (s.v != 0 && n < 100000) {
        s = ramp_step(s, 0, d, d, T).next;
        ++n;
      }
      EXPECT_NEAR(braking_distance(v, d, T), s.x, 1e-12 * (1 + std::fabs(s.x))) << v << " " << d;
      EXPECT_GE(std::fabs(braking_distance(v, d, T)), std::fabs(s.x));
      EXPECT_EQ(ramp_remaining(v, d, T), n) << v << " " << d;
    }
  }
}

}  // namespace
}  // namespace syncplc::plcopen::test
