// CiA 402 homing mode, the master's side: HomingMaster (cia402_homing.hpp)
// alone against scripted statuswords, and CIA402_DRIVE's home input through
// BlockHarness: mode 6, controlword bit 4 once the display shows it, the
// homing objects scaled, operation_enabled kept across the mode change, an
// earlier homing's status not believed, a homing error and its event.
#include <gtest/gtest.h>

#include <cstdint>
#include <string>

#include "fblocks/drives/cia402_homing.hpp"
#include "fblocks/drives/cia402_math.hpp"
#include "fblocks/library.hpp"
#include "runtime/core/block_harness.hpp"

namespace syncplc::drives::test {
namespace {

using namespace cia402;

constexpr std::uint16_t kOe = 0x0237;           // Operation enabled, voltage enabled, remote
constexpr std::uint16_t kNotStarted = kOe | 0x0400;   // 0 0 1
constexpr std::uint16_t kInProgress = kOe;            // 0 0 0
constexpr std::uint16_t kCompleted = kOe | 0x1400;    // 0 1 1
constexpr std::uint16_t kErrorStill = kOe | 0x2400;   // 1 0 1

HomingOutputs step(HomingMaster& m, bool request, std::uint16_t sw, int display, bool enabled = true) {
  HomingInputs in;
  in.request = request;
  in.enabled = enabled;
  in.statusword = sw;
  in.mode_display = display;
  return m.step(in);
}

TEST(Cia402Homing, StartsOnlyOnceTheDisplayShowsHomingMode) {
  HomingMaster m;
  HomingOutputs o = step(m, false, kOe, 8);
  EXPECT_FALSE(o.active);
  o = step(m, true, kOe, 8);
  EXPECT_TRUE(o.active);
  EXPECT_FALSE(o.start) << "bit 4 waits for the display";
  EXPECT_TRUE(o.busy);
  o = step(m, true, kNotStarted, 6);
  EXPECT_TRUE(o.start);
  o = step(m, true, kInProgress, 6);
  EXPECT_TRUE(o.start);
  EXPECT_FALSE(o.attained);
  o = step(m, true, kCompleted, 6);
  EXPECT_TRUE(o.attained);
  EXPECT_FALSE(o.busy);
  EXPECT_TRUE(o.start) << "bit 4 stays high until the request falls";
  o = step(m, false, kCompleted, 6);
  EXPECT_TRUE(o.active) << "one scan more in homing mode, bit 4 low";
  EXPECT_FALSE(o.attained);
  EXPECT_FALSE(o.start);
  o = step(m, false, kNotStarted, 6);
  EXPECT_FALSE(o.active);
  EXPECT_FALSE(o.start);
}

TEST(Cia402Homing, AnErrorAfterAnEarlierAttainedIsBelieved) {
  // The drive kept "completed" from an earlier homing and goes straight to
  // "error" at the new start: the bits changed, so it took the start.
  HomingMaster m;
  HomingOutputs o = step(m, true, kCompleted, 6);
  EXPECT_TRUE(o.start);
  o = step(m, true, kCompleted, 6);
  EXPECT_FALSE(o.attained) << "the same bits as at the start: not believed";
  o = step(m, true, kErrorStill, 6);
  EXPECT_TRUE(o.error);
}

TEST(Cia402Homing, AnEarlierHomingsStatusIsNotBelieved) {
  // The drive still shows "completed" (or "error") from before: it does not
  // count until the drive showed it took the start (bits 12 and 13 low, or
  // other bits than when bit 4 rose).
  HomingMaster m;
  HomingOutputs o = step(m, true, kCompleted, 6);
  EXPECT_TRUE(o.start);
  EXPECT_FALSE(o.attained);
  o = step(m, true, kCompleted, 6);
  EXPECT_FALSE(o.attained);
  HomingMaster m2;
  step(m2, true, kErrorStill, 6);
  o = step(m2, true, kErrorStill, 6);
  EXPECT_FALSE(o.error) << "an earlier error";
  o = step(m, true, kInProgress, 6);
  EXPECT_TRUE(o.busy);
  o = step(m, true, kCompleted, 6);
  EXPECT_TRUE(o.attained);
}

TEST(Cia402Homing, AttainedNeedsTargetReached) {
  HomingMaster m;
  step(m, true, kNotStarted, 6);
  HomingOutputs o = step(m, true, kOe | 0x1000, 6);  // 0 1 0: attained, still moving
  EXPECT_FALSE(o.attained);
  EXPECT_TRUE(o.busy);
  o = step(m, true, kCompleted, 6);
  EXPECT_TRUE(o.attained);
}

TEST(Cia402Homing, BitThirteenIsAnErrorThatHoldsUntilTheRequestFalls) {
  HomingMaster m;
  step(m, true, kNotStarted, 6);
  step(m, true, kInProgress, 6);
  HomingOutputs o = step(m, true, kOe | 0x2000, 6);  // 1 0 0: error, still moving
  EXPECT_TRUE(o.error);
  EXPECT_FALSE(o.start) << "bit 4 falls on an error";
  o = step(m, true, kNotStarted, 6);
  EXPECT_TRUE(o.error) << "latched while asked";
  o = step(m, false, kNotStarted, 6);
  EXPECT_FALSE(o.error);
}

TEST(Cia402Homing, LeavingOperationEnabledIsAnError) {
  HomingMaster m;
  step(m, true, kNotStarted, 6);
  HomingOutputs o = step(m, true, kInProgress, 6, /*enabled=*/false);
  EXPECT_TRUE(o.error);
}

TEST(Cia402Homing, NothingIsDecidedOnAStaleStatusword) {
  HomingMaster m;
  step(m, true, kNotStarted, 6);
  HomingInputs in;
  in.request = true;
  in.link_ok = false;
  in.enabled = false;
  in.statusword = kErrorStill;
  in.mode_display = 6;
  HomingOutputs o = m.step(in);
  EXPECT_FALSE(o.error);
  EXPECT_FALSE(o.attained);
  EXPECT_TRUE(o.busy);
}

// CIA402_DRIVE with a scripted drive: it takes each controlword's state and
// each modes of operation in one cycle (a bus with one cycle of delay), and
// its homing bits come from the test.
struct HomingRig {
  BlockHarness b;
  std::uint16_t sw = 0x0250;  // Switch on disabled
  int display = 8;
  std::uint16_t homing_bits = 0x0400;

  explicit HomingRig(BlockHarness::Options o = {}) : b(builtin_blocks(), "CIA402_DRIVE", std::move(o)) {
    EXPECT_TRUE(b.ok());
    b.set<bool>("link_ok", true);
    b.set<std::int8_t>("mode", 8);
  }
  void scan() {
    b.set<std::uint16_t>("statusword", sw == kOe ? static_cast<std::uint16_t>(kOe | homing_bits) : sw);
    b.set<std::int8_t>("modes_display", static_cast<std::int8_t>(display));
    b.scan();
    const std::uint16_t cw = b.get<std::uint16_t>("controlword");
    switch (cw & 0x8F) {
      case 0x06: sw = 0x0231; break;
      case 0x07: sw = 0x0233; break;
      case 0x0F: sw = kOe; break;
      default: break;
    }
    display = b.get<std::int8_t>("modes_of_operation");
  }
  void enable() {
    b.set<bool>("enable", true);
    for (int i = 0; i < 10; ++i) scan();
    ASSERT_TRUE(b.get<bool>("operation_enabled"));
  }
};

TEST(Cia402DriveHoming, HomeSwitchesToModeSixAndRaisesBitFour) {
  BlockHarness::Options o;
  o.params = {{"counts_per_unit", "1000"}, {"home_speed_switch", "2"}, {"home_speed_zero", "0.5"},
              {"home_acceleration", "40"}};
  HomingRig r(o);
  r.enable();
  r.b.set<std::int16_t>("home_method", 17);
  r.b.set<double>("home_position", -1.5);
  r.scan();
  EXPECT_EQ(r.b.get<std::int16_t>("homing_method"), 17);
  EXPECT_EQ(r.b.get<std::int32_t>("home_offset"), -1500);
  EXPECT_EQ(r.b.get<std::uint32_t>("homing_speed_switch"), 2000u);
  EXPECT_EQ(r.b.get<std::uint32_t>("homing_speed_zero"), 500u);
  EXPECT_EQ(r.b.get<std::uint32_t>("homing_acceleration"), 40000u);
  EXPECT_EQ(r.b.get<std::uint16_t>("controlword"), 0x000F);

  r.b.set<bool>("home", true);
  r.scan();  // asks for mode 6; the display still shows 8
  EXPECT_EQ(r.b.get<std::int8_t>("modes_of_operation"), 6);
  EXPECT_EQ(r.b.get<std::uint16_t>("controlword"), 0x000F) << "no start before the display shows 6";
  EXPECT_TRUE(r.b.get<bool>("operation_enabled")) << "the mode change does not drop operation_enabled";
  EXPECT_TRUE(r.b.get<bool>("homing"));
  r.scan();  // display 6, not started
  EXPECT_EQ(r.b.get<std::uint16_t>("controlword"), 0x001F);
  EXPECT_TRUE(r.b.get<bool>("operation_enabled"));
  r.homing_bits = 0;  // in progress
  for (int i = 0; i < 3; ++i) r.scan();
  EXPECT_FALSE(r.b.get<bool>("homing_attained"));
  r.homing_bits = 0x1400;
  r.scan();
  EXPECT_TRUE(r.b.get<bool>("homing_attained"));
  EXPECT_FALSE(r.b.get<bool>("homing"));
  EXPECT_FALSE(r.b.get<bool>("homing_error"));

  r.b.set<bool>("home", false);
  r.scan();  // bit 4 falls, one scan still in mode 6
  EXPECT_EQ(r.b.get<std::int8_t>("modes_of_operation"), 6);
  EXPECT_EQ(r.b.get<std::uint16_t>("controlword"), 0x000F);
  EXPECT_FALSE(r.b.get<bool>("homing_attained"));
  r.scan();  // back to mode 8; the display still shows 6
  EXPECT_EQ(r.b.get<std::int8_t>("modes_of_operation"), 8);
  EXPECT_TRUE(r.b.get<bool>("operation_enabled")) << "still enabled while the display returns";
  r.scan();
  EXPECT_TRUE(r.b.get<bool>("operation_enabled"));
  EXPECT_TRUE(r.b.get<bool>("in_mode"));
}

TEST(Cia402DriveHoming, ADisplayInAnotherModeIsNotEnabledAfterHoming) {
  // The exception is for 6 and the program's mode only.
  HomingRig r;
  r.enable();
  r.b.set<bool>("home", true);
  r.scan();
  r.scan();
  r.b.set<bool>("home", false);
  r.scan();
  r.scan();
  r.display = 3;  // a drive that shows neither
  r.b.set<std::uint16_t>("statusword", kOe);
  r.b.set<std::int8_t>("modes_display", 3);
  r.b.scan();
  EXPECT_FALSE(r.b.get<bool>("operation_enabled"));
}

TEST(Cia402DriveHoming, HomingErrorIsReportedWithAnEvent) {
  HomingRig r;
  r.enable();
  r.b.set<bool>("home", true);
  r.scan();
  r.scan();
  r.homing_bits = 0;
  r.scan();
  r.homing_bits = 0x2400;
  r.scan();
  EXPECT_TRUE(r.b.get<bool>("homing_error"));
  EXPECT_EQ(r.b.get<std::uint16_t>("controlword"), 0x000F) << "bit 4 falls";
  bool seen = false;
  for (const Event& e : r.b.events())
    if (e.kind == EventKind::DriverFault && std::string(e.message).find("homing error") != std::string::npos) seen = true;
  EXPECT_TRUE(seen);
  r.b.set<bool>("home", false);
  r.scan();
  EXPECT_FALSE(r.b.get<bool>("homing_error"));
}

TEST(Cia402DriveHoming, NegativeHomingSpeedIsRefused) {
  BlockHarness::Options o;
  o.params = {{"home_speed_switch", "-1"}};
  BlockHarness b(builtin_blocks(), "CIA402_DRIVE", o);
  EXPECT_FALSE(b.ok());
}

}  // namespace
}  // namespace syncplc::drives::test
