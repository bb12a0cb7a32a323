// CIA402_DRIVE through BlockHarness against the drive model of
// cia402_drive_model.hpp, in virtual time: each arrow of the PDS FSA figure,
// fault -> reset -> enable, quick stop with both kinds of option code, mode
// switching and the targets, the transition timeout, the following error
// window, a lost link, and the load errors.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <set>
#include <string>

#include "fblocks/library.hpp"
#include "runtime/core/block_harness.hpp"
#include "runtime/project/loader.hpp"
#include "tests/drives/cia402_drive_model.hpp"

namespace syncplc::drives::test {
namespace {

std::string errors_of(const BlockHarness& h) {
  std::string s;
  for (const auto& e : h.errors()) s += e + "\n";
  return s;
}

// The block and a drive model wired as a bus would: every scan the block
// reads the drive's objects, then the drive runs one cycle on the block's
// controlword (a bus with one cycle of delay).
struct Rig {
  BlockHarness b;
  DriveModel d;
  std::int32_t position_counts = 0, velocity_counts = 0;

  explicit Rig(BlockHarness::Options o = {}, DriveModel::Options mo = {})
      : b(builtin_blocks(), "CIA402_DRIVE", std::move(o)), d(mo) {
    EXPECT_TRUE(b.ok()) << errors_of(b);
    b.set<bool>("link_ok", true);
  }
  void scan() {
    b.set<std::uint16_t>("statusword", d.statusword());
    b.set<std::int8_t>("modes_display", static_cast<std::int8_t>(d.mode_display()));
    b.set<std::uint16_t>("error_code", d.error_code());
    b.set<std::int32_t>("position_actual", position_counts);
    b.set<std::int32_t>("velocity_actual", velocity_counts);
    b.scan();
    d.cycle(b.get<std::uint16_t>("controlword"), b.get<std::int8_t>("modes_of_operation"));
  }
  // Scans until the block reports `s` (at most n scans; the drive may have
  // moved on in the cycle after); true if it did.
  bool until(State s, int n = 50) {
    for (int i = 0; i < n; ++i) {
      scan();
      if (static_cast<State>(b.get<std::int8_t>("state")) == s) return true;
    }
    return false;
  }
  void set_enable(bool v) { b.set<bool>("enable", v); }
  State state() { return static_cast<State>(b.get<std::int8_t>("state")); }
};

BlockHarness::Options opts(std::map<std::string, std::string> p = {}) {
  BlockHarness::Options o;
  o.params = std::move(p);
  return o;
}

TEST(Cia402Drive, Declaration) {
  const BlockTypeInfo* t = builtin_blocks().find("CIA402_DRIVE");
  ASSERT_NE(t, nullptr);
  EXPECT_EQ(t->category, "Drives");
  for (const char* p : {"enable", "quick_stop", "reset", "mode", "position_set", "velocity_set", "torque_set",
                        "link_ok", "statusword", "modes_display", "position_actual", "velocity_actual",
                        "error_code", "controlword", "modes_of_operation", "target_position", "target_velocity",
                        "velocity_offset", "target_torque", "state", "operation_enabled", "busy", "fault",
                        "fault_code", "warning", "timeout", "in_mode", "position", "velocity", "following_error",
                        "following_error_exceeded"})
    EXPECT_GE(t->pin_index(p), 0) << p;
  EXPECT_EQ(t->pins[static_cast<std::size_t>(t->pin_index("controlword"))].type, IecType::UINT);
  EXPECT_EQ(t->pins[static_cast<std::size_t>(t->pin_index("statusword"))].type, IecType::UINT);
  EXPECT_EQ(t->pins[static_cast<std::size_t>(t->pin_index("target_position"))].type, IecType::DINT);
  EXPECT_EQ(t->default_datatype, IecType::SINT);
}

TEST(Cia402Drive, InvalidParametersFailAtLoad) {
  for (const auto& [p, what] : std::vector<std::pair<std::map<std::string, std::string>, std::string>>{
           {{{"counts_per_unit", "0"}}, "counts_per_unit must be greater than 0"},
           {{{"transition_timeout", "0"}}, "transition_timeout must be greater than 0"},
           {{{"idle_state", "3"}}, "idle_state must be in"},
           {{{"following_error_window", "-1"}}, "following_error_window must be >="},
           {{{"disable_stop", "3"}}, "disable_stop must be in"},
           {{{"link_lost_stop", "2"}}, "link_lost_stop must be in"},
       }) {
    BlockHarness h(builtin_blocks(), "CIA402_DRIVE", opts(p));
    EXPECT_FALSE(h.ok()) << what;
    EXPECT_NE(errors_of(h).find(what), std::string::npos) << errors_of(h);
  }
}

// link_ok is required: an unwired one is a load error at the block (on main
// it defaulted to TRUE, failing open); a constant given on purpose loads.
TEST(Cia402Drive, AnUnwiredLinkOkIsALoadError) {
  const std::string head = R"(
tasks: [{name: servo, period: 1ms}]
tags: [{name: sw, type: UINT}]
blocks:
  - name: axis1
    type: CIA402_DRIVE
)";
  LoadOptions lo;
  lo.blocks = &builtin_blocks();
  auto r = load_project_text(head + "connections: [sw -> axis1.statusword]\n", "p.yaml", lo);
  std::string all;
  for (const auto& d : r.diagnostics.list()) all += d.text() + "\n";
  EXPECT_FALSE(r.program);
  EXPECT_NE(all.find("p.yaml:5:5"), std::string::npos) << all;
  EXPECT_NE(all.find("input axis1.link_ok must be connected or given a value in inputs:"), std::string::npos) << all;
  auto ok = load_project_text(head + "    inputs: {link_ok: TRUE}\nconnections: [sw -> axis1.statusword]\n", "p.yaml", lo);
  for (const auto& d : ok.diagnostics.list()) ADD_FAILURE() << d.text();
  EXPECT_TRUE(ok.program);
}

// The block walks the drive model through every arrow of the figure; the
// model logs the numbers of the transitions it made.
TEST(Cia402Drive, EveryTransitionOfThePdsFsa) {
  std::set<int> seen;
  // disable_stop 1 (Shutdown / Disable operation) and 2 (the direct
  // command) for 5, 8 and 9; the default (Quick stop) is tested below.
  auto run = [&](int idle, int qs_option, auto&& script, int disable_stop = 1) {
    DriveModel::Options mo;
    mo.quick_stop_option = qs_option;
    Rig r(opts({{"idle_state", std::to_string(idle)}, {"disable_stop", std::to_string(disable_stop)}}), mo);
    script(r);
    for (int n : r.d.transitions()) seen.insert(n);
  };
  // 0, 1 (power on), 2, 3, 4 (enable), 5 (disable to Switched on), 4 again.
  run(2, 2, [](Rig& r) {
    EXPECT_TRUE(r.until(State::kSwitchOnDisabled));
    r.set_enable(true);
    EXPECT_TRUE(r.until(State::kOperationEnabled));
    EXPECT_TRUE(r.b.get<bool>("operation_enabled"));
    EXPECT_EQ(r.b.get<std::uint16_t>("controlword"), 0x0F);
    r.set_enable(false);
    EXPECT_TRUE(r.until(State::kSwitchedOn));
    EXPECT_EQ(r.b.get<std::uint16_t>("controlword"), 0x07);
    EXPECT_EQ(r.d.transitions(), (std::vector<int>{0, 1, 2, 3, 4, 5}));
  });
  // 8 (Operation enabled -> Ready), 3, 6 (Switched on -> Ready).
  run(1, 2, [](Rig& r) {
    r.set_enable(true);
    EXPECT_TRUE(r.until(State::kOperationEnabled));
    r.set_enable(false);
    EXPECT_TRUE(r.until(State::kReadyToSwitchOn));
    EXPECT_EQ(r.d.transitions().back(), 8);
    // Another master's Switch on brings the drive to Switched on (3); the
    // block (idle_state 1) answers with Shutdown: 6.
    r.d.cycle(0x07, 8);
    r.scan();
    EXPECT_TRUE(r.until(State::kReadyToSwitchOn));
    EXPECT_EQ(r.d.transitions().back(), 6);
  });
  // 9 (Operation enabled -> Switch on disabled), 7 (Ready -> Switch on disabled), 10.
  run(0, 2, [](Rig& r) {
    r.set_enable(true);
    EXPECT_TRUE(r.until(State::kOperationEnabled));
    r.set_enable(false);
    EXPECT_TRUE(r.until(State::kSwitchOnDisabled));
    EXPECT_EQ(r.d.transitions().back(), 9);
    r.d.cycle(0x06, 8);  // the drive gets to Ready to switch on (2) by another command
    EXPECT_TRUE(r.until(State::kSwitchOnDisabled));
    EXPECT_EQ(r.d.transitions().back(), 7);
    r.d.cycle(0x06, 8);
    r.d.cycle(0x07, 8);  // Switched on
    EXPECT_TRUE(r.until(State::kSwitchOnDisabled));
    EXPECT_EQ(r.d.transitions().back(), 10);
  }, /*disable_stop=*/2);
  // 11, 12 (quick stop option code 2: the drive ends in Switch on disabled).
  run(0, 2, [](Rig& r) {
    r.set_enable(true);
    EXPECT_TRUE(r.until(State::kOperationEnabled));
    r.b.set<bool>("quick_stop", true);
    r.scan();
    EXPECT_EQ(r.b.get<std::uint16_t>("controlword"), 0x02);
    EXPECT_TRUE(r.until(State::kSwitchOnDisabled));
    const auto& t = r.d.transitions();
    EXPECT_EQ(std::vector<int>(t.end() - 2, t.end()), (std::vector<int>{11, 12}));
    EXPECT_FALSE(r.b.get<bool>("busy"));  // quick stop done: where the inputs ask
    r.b.set<bool>("quick_stop", false);   // enable is still TRUE: back up
    EXPECT_TRUE(r.until(State::kOperationEnabled));
  });
  // 11, 16 (option code 6: stays in Quick stop active, Enable operation returns).
  run(0, 6, [](Rig& r) {
    r.set_enable(true);
    EXPECT_TRUE(r.until(State::kOperationEnabled));
    r.b.set<bool>("quick_stop", true);
    EXPECT_TRUE(r.until(State::kQuickStopActive));
    for (int i = 0; i < 20; ++i) r.scan();
    EXPECT_EQ(r.d.state(), State::kQuickStopActive);
    EXPECT_FALSE(r.b.get<bool>("busy"));
    r.b.set<bool>("quick_stop", false);
    EXPECT_TRUE(r.until(State::kOperationEnabled));
    EXPECT_EQ(r.d.transitions().back(), 16);
  });
  // 12 by Disable voltage (option 6, enable dropped in Quick stop active).
  run(0, 6, [](Rig& r) {
    r.set_enable(true);
    EXPECT_TRUE(r.until(State::kOperationEnabled));
    r.b.set<bool>("quick_stop", true);
    EXPECT_TRUE(r.until(State::kQuickStopActive));
    r.b.set<bool>("quick_stop", false);
    r.set_enable(false);
    EXPECT_TRUE(r.until(State::kSwitchOnDisabled));
    EXPECT_EQ(r.d.transitions().back(), 12);
  });
  // 13, 14, 15.
  run(0, 2, [](Rig& r) {
    r.set_enable(true);
    EXPECT_TRUE(r.until(State::kOperationEnabled));
    r.d.inject_fault(0x7300);
    EXPECT_TRUE(r.until(State::kFault));
    r.b.set<bool>("reset", true);
    EXPECT_TRUE(r.until(State::kOperationEnabled));
    const auto& t = r.d.transitions();
    EXPECT_EQ(std::vector<int>(t.end() - 6, t.end()), (std::vector<int>{13, 14, 15, 2, 3, 4}));
  });
  std::set<int> all;
  for (int i = 0; i <= 16; ++i) all.insert(i);
  EXPECT_EQ(seen, all);
}

TEST(Cia402Drive, FaultResetEnableWithEventsAndFaultCode) {
  Rig r;
  r.set_enable(true);
  ASSERT_TRUE(r.until(State::kOperationEnabled));
  EXPECT_TRUE(r.b.events().empty());
  r.d.inject_fault(0x2310);  // continuous overcurrent
  r.scan();                  // the drive reacts in its cycle: seen at the next scan
  r.scan();
  EXPECT_EQ(r.state(), State::kFaultReactionActive);
  EXPECT_TRUE(r.b.get<bool>("fault"));
  EXPECT_FALSE(r.b.get<bool>("operation_enabled"));
  EXPECT_EQ(r.b.get<std::uint16_t>("fault_code"), 0x2310);
  ASSERT_EQ(r.b.events().size(), 1u);
  EXPECT_EQ(r.b.events()[0].kind, EventKind::DriverFault);
  EXPECT_EQ(r.b.events()[0].value, 0x2310);
  EXPECT_NE(std::string(r.b.events()[0].message).find("drive fault"), std::string::npos);
  ASSERT_TRUE(r.until(State::kFault));
  for (int i = 0; i < 10; ++i) {  // no reset asked: it stays, bit 7 low, no timeout
    r.scan();
    EXPECT_EQ(r.b.get<std::uint16_t>("controlword"), 0x00);
    EXPECT_FALSE(r.b.get<bool>("busy"));
  }
  r.b.set<bool>("reset", true);
  r.scan();
  EXPECT_EQ(r.b.get<std::uint16_t>("controlword"), 0x80);
  ASSERT_TRUE(r.until(State::kSwitchOnDisabled, 3));
  EXPECT_EQ(r.b.get<std::uint16_t>("fault_code"), 0);
  ASSERT_EQ(r.b.events().size(), 2u);
  EXPECT_EQ(r.b.events()[1].kind, EventKind::Info);
  ASSERT_TRUE(r.until(State::kOperationEnabled));  // enable still TRUE: back in operation
  EXPECT_FALSE(r.b.get<bool>("fault"));
  // reset held high is no new edge: a second fault is not reset by it.
  r.d.inject_fault(0x5530);
  ASSERT_TRUE(r.until(State::kFault));
  for (int i = 0; i < 10; ++i) r.scan();
  EXPECT_EQ(r.d.state(), State::kFault);
  r.b.set<bool>("reset", false);
  r.scan();
  r.b.set<bool>("reset", true);
  ASSERT_TRUE(r.until(State::kOperationEnabled));
}

TEST(Cia402Drive, AResetTheDriveRefusesEndsInATimeoutAndANewEdgeWorks) {
  Rig r(opts({{"transition_timeout", "0.02"}}));
  r.set_enable(true);
  ASSERT_TRUE(r.until(State::kOperationEnabled));
  r.d.inject_fault(0x4310, /*persistent=*/true);  // overtemperature: not resettable yet
  ASSERT_TRUE(r.until(State::kFault));
  r.b.set<bool>("reset", true);
  int high = 0;
  for (int i = 0; i < 40; ++i) {
    r.scan();
    high += (r.b.get<std::uint16_t>("controlword") & 0x80) != 0;
  }
  EXPECT_GE(high, 19);  // bit 7 held while waiting, for the timeout...
  EXPECT_LE(high, 21);
  EXPECT_EQ(r.b.get<std::uint16_t>("controlword"), 0x00);  // ...then low again
  EXPECT_TRUE(r.b.get<bool>("timeout"));
  EXPECT_EQ(r.d.state(), State::kFault);
  r.d.clear_persistent_fault();
  r.b.set<bool>("reset", false);
  r.scan();
  r.b.set<bool>("reset", true);
  ASSERT_TRUE(r.until(State::kOperationEnabled));
  EXPECT_FALSE(r.b.get<bool>("timeout"));
}

TEST(Cia402Drive, TransitionTimeoutInVirtualTime) {
  Rig r(opts({{"transition_timeout", "0.25"}}));
  ASSERT_TRUE(r.until(State::kSwitchOnDisabled));
  r.d.set_stuck(true);  // the drive stops following the controlword
  r.set_enable(true);
  const std::int64_t t0 = r.b.now_ns();
  int scans = 0;
  while (!r.b.get<bool>("timeout") && scans < 1000) {
    r.scan();
    ++scans;
    EXPECT_TRUE(r.b.get<bool>("busy"));
  }
  // The command changed at t0 (first scan with enable): timeout 250 ms later.
  EXPECT_EQ(scans, 251);
  EXPECT_EQ(r.b.now_ns() - t0, 251'000'000);
  ASSERT_EQ(r.b.events().size(), 1u);
  EXPECT_EQ(r.b.events()[0].kind, EventKind::DriverFault);
  EXPECT_NE(std::string(r.b.events()[0].message).find("transition_timeout"), std::string::npos);
  for (int i = 0; i < 100; ++i) r.scan();
  EXPECT_EQ(r.b.events().size(), 1u);  // once
  r.d.set_stuck(false);
  ASSERT_TRUE(r.until(State::kOperationEnabled));
  EXPECT_FALSE(r.b.get<bool>("timeout"));
  EXPECT_FALSE(r.b.get<bool>("busy"));
}

TEST(Cia402Drive, ModeSwitchingAndTheTargets) {
  // 1000 counts per unit.
  Rig r(opts({{"counts_per_unit", "1000"}}));
  r.b.set<std::int8_t>("mode", 8);
  r.position_counts = 12345;
  r.b.set<double>("position_set", 7.0);
  r.b.set<double>("velocity_set", 2.5);
  r.b.set<double>("torque_set", 0.3);
  r.scan();
  // Not enabled: the position target follows the actual position.
  EXPECT_EQ(r.b.get<std::int32_t>("target_position"), 12345);
  EXPECT_EQ(r.b.get<std::int32_t>("target_velocity"), 0);
  EXPECT_DOUBLE_EQ(r.b.get<double>("position"), 12.345);
  r.set_enable(true);
  ASSERT_TRUE(r.until(State::kOperationEnabled));
  EXPECT_TRUE(r.b.get<bool>("in_mode"));
  EXPECT_EQ(r.b.get<std::int8_t>("modes_of_operation"), 8);
  EXPECT_EQ(r.b.get<std::int32_t>("target_position"), 7000);
  EXPECT_EQ(r.b.get<std::int32_t>("velocity_offset"), 2500);
  EXPECT_EQ(r.b.get<std::int32_t>("target_velocity"), 0);
  EXPECT_EQ(r.b.get<std::int16_t>("target_torque"), 0);
  EXPECT_NEAR(r.b.get<double>("following_error"), 7.0 - 12.345, 1e-12);
  // Profile velocity: the display follows one drive cycle later.
  r.b.set<std::int8_t>("mode", 3);
  r.scan();
  EXPECT_FALSE(r.b.get<bool>("in_mode"));
  EXPECT_FALSE(r.b.get<bool>("operation_enabled"));
  EXPECT_TRUE(r.b.get<bool>("busy"));
  EXPECT_EQ(r.b.get<std::int32_t>("target_position"), 12345);  // not in a position mode: follows
  EXPECT_EQ(r.b.get<std::int32_t>("target_velocity"), 2500);
  r.scan();
  EXPECT_TRUE(r.b.get<bool>("in_mode"));
  EXPECT_TRUE(r.b.get<bool>("operation_enabled"));
  EXPECT_EQ(r.b.get<double>("following_error"), 0.0);
  // Cyclic synchronous velocity and torque.
  r.b.set<std::int8_t>("mode", 9);
  r.scan();
  r.scan();
  EXPECT_EQ(r.b.get<std::int8_t>("modes_of_operation"), 9);
  EXPECT_EQ(r.b.get<std::int32_t>("target_velocity"), 2500);
  r.b.set<std::int8_t>("mode", 10);
  r.scan();
  r.scan();
  EXPECT_EQ(r.b.get<std::int16_t>("target_torque"), 300);
  EXPECT_EQ(r.b.get<std::int32_t>("target_velocity"), 0);
  // A mode the drive does not take: in_mode stays FALSE, timeout after 1 s.
  r.b.set<std::int8_t>("mode", 2);
  for (int i = 0; i < 1001; ++i) r.scan();
  EXPECT_FALSE(r.b.get<bool>("in_mode"));
  EXPECT_TRUE(r.b.get<bool>("timeout"));
  // Back to CSP: no jump, the target is the set point again.
  r.b.set<std::int8_t>("mode", 8);
  r.scan();
  r.scan();
  EXPECT_TRUE(r.b.get<bool>("operation_enabled"));
  EXPECT_FALSE(r.b.get<bool>("timeout"));
  EXPECT_EQ(r.b.get<std::int32_t>("target_position"), 7000);
}

TEST(Cia402Drive, TargetsSaturateAtTheCountRange) {
  Rig r(opts({{"counts_per_unit", "1e6"}}));
  r.set_enable(true);
  ASSERT_TRUE(r.until(State::kOperationEnabled));
  r.b.set<double>("position_set", 1e6);
  r.b.set<double>("velocity_set", -1e6);
  r.scan();
  EXPECT_EQ(r.b.get<std::int32_t>("target_position"), 2147483647);
  EXPECT_EQ(r.b.get<std::int32_t>("velocity_offset"), -2147483647 - 1);
}

TEST(Cia402Drive, ModePinsTakeINTWhenTheInstanceIsINT) {
  BlockHarness::Options o;
  o.datatype = IecType::INT;
  BlockHarness b(builtin_blocks(), "CIA402_DRIVE", o);
  ASSERT_TRUE(b.ok()) << errors_of(b);
  b.set<bool>("link_ok", true);
  b.set<std::int16_t>("mode", 9);
  b.set<std::int16_t>("modes_display", 9);
  b.set<std::uint16_t>("statusword", 0x0627);
  b.set<bool>("enable", true);
  b.scan();
  EXPECT_EQ(b.get<std::int16_t>("modes_of_operation"), 9);
  EXPECT_TRUE(b.get<bool>("operation_enabled"));
  EXPECT_FALSE(b.get<bool>("warning"));
  b.set<std::uint16_t>("statusword", 0x06A7);
  b.scan();
  EXPECT_TRUE(b.get<bool>("warning"));
}

TEST(Cia402Drive, AModeBeyondAnyDrivesRangeIsClamped) {
  BlockHarness::Options o;
  o.datatype = IecType::LINT;
  BlockHarness b(builtin_blocks(), "CIA402_DRIVE", o);
  ASSERT_TRUE(b.ok()) << errors_of(b);
  b.set<bool>("link_ok", true);
  b.set<std::int64_t>("mode", 1'000'000'000'000LL);
  b.set<std::int64_t>("modes_display", -1'000'000'000'000LL);
  b.set<std::uint16_t>("statusword", 0x0240);
  b.scan();
  EXPECT_EQ(b.get<std::int64_t>("modes_of_operation"), 32767);
  EXPECT_FALSE(b.get<bool>("in_mode"));
}

TEST(Cia402Drive, FollowingErrorWindow) {
  Rig r(opts({{"following_error_window", "0.01"}, {"following_error_time", "0.005"}}));
  r.set_enable(true);
  ASSERT_TRUE(r.until(State::kOperationEnabled));
  r.position_counts = 0;  // counts_per_unit 1: units = counts
  r.b.set<double>("position_set", 0.005);
  for (int i = 0; i < 20; ++i) r.scan();
  EXPECT_FALSE(r.b.get<bool>("following_error_exceeded"));
  EXPECT_DOUBLE_EQ(r.b.get<double>("following_error"), 0.005);
  r.b.set<double>("position_set", -0.02);  // outside: flagged 5 ms later
  for (int i = 0; i < 5; ++i) {
    r.scan();
    EXPECT_FALSE(r.b.get<bool>("following_error_exceeded")) << i;
  }
  r.scan();
  EXPECT_TRUE(r.b.get<bool>("following_error_exceeded"));
  ASSERT_EQ(r.b.events().size(), 1u);
  EXPECT_EQ(r.b.events()[0].kind, EventKind::DriverFault);
  EXPECT_DOUBLE_EQ(r.b.events()[0].value, -0.02);
  for (int i = 0; i < 10; ++i) r.scan();
  EXPECT_EQ(r.b.events().size(), 1u);
  r.b.set<double>("position_set", 0.0);  // back inside: cleared at once
  r.scan();
  EXPECT_FALSE(r.b.get<bool>("following_error_exceeded"));
  // A short excursion (3 ms < 5 ms) is not flagged.
  r.b.set<double>("position_set", 0.5);
  for (int i = 0; i < 3; ++i) r.scan();
  r.b.set<double>("position_set", 0.0);
  r.scan();
  EXPECT_FALSE(r.b.get<bool>("following_error_exceeded"));
  EXPECT_EQ(r.b.events().size(), 1u);
  // Not supervised outside a position mode.
  r.b.set<std::int8_t>("mode", 3);
  r.b.set<double>("position_set", 5.0);
  for (int i = 0; i < 20; ++i) r.scan();
  EXPECT_FALSE(r.b.get<bool>("following_error_exceeded"));
}

// The link lost in Operation enabled (CSP, the axis at a set point away
// from 0): the block commands Quick stop at once, never Enable operation, and
// holds the target it last commanded although the actual position input now
// shows the read group's safe value 0; back, the drive (still in Operation
// enabled) is quick stopped and stays down until a new enable.
TEST(Cia402Drive, LinkLossQuickStopsHoldsTheTargetAndNeedsANewEnable) {
  Rig r(opts({{"counts_per_unit", "1000"}}));
  r.position_counts = 5000;
  r.b.set<double>("position_set", 5.0);
  r.set_enable(true);
  ASSERT_TRUE(r.until(State::kOperationEnabled));
  r.scan();
  ASSERT_EQ(r.b.get<std::int32_t>("target_position"), 5000);
  ASSERT_EQ(r.b.get<std::uint16_t>("controlword"), 0x0F);
  ASSERT_TRUE(r.b.events().empty());
  r.b.set<bool>("link_ok", false);
  for (int i = 0; i < 5; ++i) {
    r.b.set<std::uint16_t>("statusword", 0);     // the read group's safe values
    r.b.set<std::int32_t>("position_actual", 0);
    r.b.scan();  // the bus is down: the drive sees nothing
    EXPECT_EQ(r.state(), State::kUnknown);
    EXPECT_FALSE(r.b.get<bool>("operation_enabled"));
    EXPECT_EQ(r.b.get<std::uint16_t>("controlword"), 0x02) << i;  // Quick stop, not the held 000Fh
    EXPECT_EQ(r.b.get<std::int32_t>("target_position"), 5000) << i;  // held, not the stale 0
    EXPECT_TRUE(r.b.get<bool>("busy"));
  }
  ASSERT_EQ(r.b.events().size(), 1u);
  EXPECT_EQ(r.b.events()[0].kind, EventKind::DriverFault);
  EXPECT_NE(std::string(r.b.events()[0].message).find("link lost"), std::string::npos);
  // Back: the drive ran on (6007h = 0) in Operation enabled.
  r.b.set<bool>("link_ok", true);
  r.scan();
  EXPECT_EQ(r.b.get<std::uint16_t>("controlword"), 0x02);
  EXPECT_EQ(r.b.get<std::int32_t>("target_position"), 5000);  // the actual position, fresh
  ASSERT_TRUE(r.until(State::kSwitchOnDisabled));
  for (int i = 0; i < 50; ++i) {  // enable is still TRUE: no walk up without a new one
    r.scan();
    ASSERT_EQ(r.state(), State::kSwitchOnDisabled);
    ASSERT_NE(r.b.get<std::uint16_t>("controlword"), 0x06);
  }
  const auto t = r.d.transitions();
  EXPECT_EQ(std::vector<int>(t.end() - 2, t.end()), (std::vector<int>{11, 12}));
  r.set_enable(false);
  r.scan();
  r.set_enable(true);
  ASSERT_TRUE(r.until(State::kOperationEnabled));
}

// A drive that restarted during the outage reports Switch on disabled: it
// too waits for a new enable.
TEST(Cia402Drive, LinkLossThenARestartedDriveWaitsForANewEnable) {
  Rig r;
  r.set_enable(true);
  ASSERT_TRUE(r.until(State::kOperationEnabled));
  r.b.set<bool>("link_ok", false);
  r.b.scan();
  r.d = DriveModel();  // the drive restarted meanwhile
  r.b.set<bool>("link_ok", true);
  ASSERT_TRUE(r.until(State::kSwitchOnDisabled));
  for (int i = 0; i < 20; ++i) r.scan();
  EXPECT_EQ(r.d.state(), State::kSwitchOnDisabled);
  r.set_enable(false);
  r.scan();
  r.set_enable(true);
  ASSERT_TRUE(r.until(State::kOperationEnabled));
}

// enable FALSE in Operation enabled: by default Quick stop (11), held while
// the drive ramps, so its 605Ah ramp acts; never Disable voltage (9).
TEST(Cia402Drive, DisableFromOperationEnabledLetsTheDriveRamp) {
  Rig r;
  r.set_enable(true);
  ASSERT_TRUE(r.until(State::kOperationEnabled));
  r.set_enable(false);
  r.scan();
  EXPECT_EQ(r.b.get<std::uint16_t>("controlword"), 0x02);
  ASSERT_TRUE(r.until(State::kSwitchOnDisabled));
  const auto t = r.d.transitions();
  EXPECT_EQ(std::vector<int>(t.end() - 2, t.end()), (std::vector<int>{11, 12}));
  EXPECT_EQ(std::count(t.begin(), t.end(), 9), 0);
  // With quick stop option code 6 the drive stays in Quick stop active: the
  // block holds Quick stop until the ramp is done (bit 10), then 12.
  DriveModel::Options mo;
  mo.quick_stop_option = 6;
  Rig q(opts(), mo);
  q.set_enable(true);
  ASSERT_TRUE(q.until(State::kOperationEnabled));
  q.set_enable(false);
  ASSERT_TRUE(q.until(State::kQuickStopActive));
  int held = 0;  // scans in Quick stop active with the quick stop still commanded
  for (int i = 0; i < 20 && q.d.state() == State::kQuickStopActive; ++i) {
    q.scan();
    held += q.b.get<std::uint16_t>("controlword") == 0x02;
  }
  EXPECT_GE(held, 2);  // the model's ramp takes 3 cycles
  EXPECT_EQ(q.d.state(), State::kSwitchOnDisabled);
  EXPECT_EQ(q.d.transitions().back(), 12);
}

// The project may ask for coasting: disable_stop 2 with idle_state 0 is
// Disable voltage (9); link_lost_stop 1 is Disable voltage on a link loss.
TEST(Cia402Drive, CoastingOnlyWhenTheProjectAsks) {
  Rig r(opts({{"disable_stop", "2"}, {"link_lost_stop", "1"}}));
  r.set_enable(true);
  ASSERT_TRUE(r.until(State::kOperationEnabled));
  r.set_enable(false);
  ASSERT_TRUE(r.until(State::kSwitchOnDisabled));
  EXPECT_EQ(r.d.transitions().back(), 9);
  r.set_enable(true);
  ASSERT_TRUE(r.until(State::kOperationEnabled));
  r.b.set<bool>("link_ok", false);
  r.b.scan();
  EXPECT_EQ(r.b.get<std::uint16_t>("controlword"), 0x00);
}

}  // namespace
}  // namespace syncplc::drives::test
