// A PLCopen axis on an ideal drive, scanned in virtual time: the drive's
// power stage follows its enable one scan later, its actual position and
// velocity are the last set values it received.
#pragma once

#include <functional>

#include <gtest/gtest.h>

#include "fblocks/plcopen/axis_machine.hpp"

namespace syncplc::plcopen::test {

struct IdealDrive {
  bool power_on = false;
  double position = 0;
  double velocity = 0;
  bool fault = false;
  std::uint16_t fault_code = 0;
  bool valid = true;
  bool lose_power = false;  // the power stage drops whatever the enable says
  int resets_seen = 0;      // scans in which DriveCommand::reset was TRUE

  DriveFeedback feedback() const {
    DriveFeedback f;
    f.position = position;
    f.velocity = velocity;
    f.valid = valid;
    f.power_on = power_on;
    f.fault = fault;
    f.fault_code = fault_code;
    return f;
  }
  void apply(const DriveCommand& c) {
    if (c.reset) ++resets_seen;
    power_on = c.enable && !fault && !lose_power;
    if (power_on) {
      position = c.position;
      velocity = c.velocity;
    } else {
      velocity = 0;
    }
  }
};

inline AxisLimits default_limits() {
  AxisLimits l;
  l.v_max = 2;
  l.a_max = 20;
  l.d_max = 40;
  return l;
}

struct Rig {
  explicit Rig(const AxisLimits& l = default_limits(), double T = 0.001) : m(l, T) {}
  AxisMachine m;
  IdealDrive d;
  bool power = false;  // MC_Power's Enable
  std::function<void()> blocks;  // what the blocks do after cycle() each scan

  void scan() {
    m.cycle(d.feedback());
    m.request_power(power);
    if (blocks) blocks();
    d.apply(m.drive_command());
  }
  void scans(int n) {
    for (int i = 0; i < n; ++i) scan();
  }
  // Powers the axis and scans until Standstill (two scans on the ideal drive).
  void power_up() {
    power = true;
    for (int i = 0; i < 3 && m.state() != AxisState::Standstill; ++i) scan();
    ASSERT_EQ(m.state(), AxisState::Standstill);
  }
  CommandId submit(const Command& c) {
    AxisError e = AxisError::None;
    const CommandId id = m.submit(c, &e);
    EXPECT_EQ(e, AxisError::None);
    EXPECT_NE(id, 0u);
    return id;
  }
  AxisError reject(const Command& c) {
    AxisError e = AxisError::None;
    const CommandId id = m.submit(c, &e);
    EXPECT_EQ(id, 0u);
    return e;
  }
  // Scans until the command's report leaves Active/Buffered (or n scans); the scans it took.
  int run_until_end(CommandId id, int n = 1000000) {
    for (int i = 1; i <= n; ++i) {
      scan();
      const CommandStatus s = m.report(id).status;
      if (s != CommandStatus::Active && s != CommandStatus::Buffered) return i;
    }
    return -1;
  }
  CommandStatus status(CommandId id) const { return m.report(id).status; }
};

inline Command move_absolute(double p, double v, BufferMode b = BufferMode::Aborting, double acc = 0, double dec = 0) {
  Command c;
  c.kind = CommandKind::MoveAbsolute;
  c.position = p;
  c.velocity = v;
  c.acceleration = acc;
  c.deceleration = dec;
  c.buffer = b;
  return c;
}
inline Command move_relative(double dist, double v, BufferMode b = BufferMode::Aborting) {
  Command c = move_absolute(dist, v, b);
  c.kind = CommandKind::MoveRelative;
  return c;
}
inline Command move_additive(double dist, double v, BufferMode b = BufferMode::Aborting) {
  Command c = move_absolute(dist, v, b);
  c.kind = CommandKind::MoveAdditive;
  return c;
}
inline Command move_velocity(double v, BufferMode b = BufferMode::Aborting, double acc = 0, double dec = 0) {
  Command c;
  c.kind = CommandKind::MoveVelocity;
  c.velocity = v;
  c.acceleration = acc;
  c.deceleration = dec;
  c.buffer = b;
  return c;
}
inline Command halt(double dec = 0, BufferMode b = BufferMode::Aborting) {
  Command c;
  c.kind = CommandKind::Halt;
  c.deceleration = dec;
  c.buffer = b;
  return c;
}
inline Command stop(double dec = 0) {
  Command c;
  c.kind = CommandKind::Stop;
  c.deceleration = dec;
  return c;
}
inline Command home(double p) {
  Command c;
  c.kind = CommandKind::Home;
  c.position = p;
  return c;
}

}  // namespace syncplc::plcopen::test
