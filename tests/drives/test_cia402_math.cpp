// The pure CiA 402 state machine (fblocks/drives/cia402_math): the state
// coding of the statusword with every don't-care bit combination, the
// command coding of the controlword, the transition numbers of the PDS FSA
// figure, and the Master's reset edge and timeout in virtual time.
#include <gtest/gtest.h>

#include "fblocks/drives/cia402_math.hpp"

namespace syncplc::drives::cia402 {
namespace {

constexpr State kStates[] = {State::kNotReadyToSwitchOn, State::kSwitchOnDisabled, State::kReadyToSwitchOn,
                             State::kSwitchedOn,         State::kOperationEnabled, State::kQuickStopActive,
                             State::kFaultReactionActive, State::kFault};

// The bits the state coding table leaves as x for a state.
std::uint16_t dont_care(State s) {
  switch (s) {
    case State::kReadyToSwitchOn:
    case State::kSwitchedOn:
    case State::kOperationEnabled:
    case State::kQuickStopActive:
      return static_cast<std::uint16_t>(~0x6Fu);
    default:
      return static_cast<std::uint16_t>(~0x4Fu);
  }
}

TEST(Cia402Statusword, EveryStateDecodesWhateverTheDontCareBits) {
  EXPECT_EQ(statusword_of(State::kSwitchOnDisabled), 0x40);
  EXPECT_EQ(statusword_of(State::kReadyToSwitchOn), 0x21);
  EXPECT_EQ(statusword_of(State::kSwitchedOn), 0x23);
  EXPECT_EQ(statusword_of(State::kOperationEnabled), 0x27);
  EXPECT_EQ(statusword_of(State::kQuickStopActive), 0x07);
  EXPECT_EQ(statusword_of(State::kFaultReactionActive), 0x0F);
  EXPECT_EQ(statusword_of(State::kFault), 0x08);
  for (State s : kStates) {
    const std::uint16_t x = dont_care(s);
    for (std::uint32_t v = 0; v < 0x10000; ++v) {  // every value the x bits can take
      if ((v & ~x) != 0) continue;
      ASSERT_EQ(decode_statusword(static_cast<std::uint16_t>(statusword_of(s) | v)), s)
          << state_name(s) << " with 16#" << std::hex << v;
    }
  }
}

TEST(Cia402Statusword, CodingsThatAreNoStateDecodeAsUnknown) {
  // Every 7-bit pattern of bits 0-3, 5, 6 that is no row of the table.
  int unknown = 0;
  for (std::uint16_t v = 0; v < 0x80; ++v) {
    if (v & 0x10) continue;  // bit 4 (voltage enabled) is never part of the coding
    const State s = decode_statusword(v);
    bool is_row = false;
    for (State t : kStates) is_row = is_row || ((v & ~dont_care(t) & 0x7F) == statusword_of(t));
    EXPECT_EQ(s == State::kUnknown, !is_row) << std::hex << v;
    unknown += s == State::kUnknown;
  }
  EXPECT_GT(unknown, 0);
  EXPECT_EQ(decode_statusword(0x0041), State::kUnknown);  // switch on disabled + ready: contradictory
  EXPECT_EQ(decode_statusword(0x0003), State::kUnknown);
}

TEST(Cia402Controlword, CommandCodingTable) {
  EXPECT_EQ(cw::kShutdown, 0x06);
  EXPECT_EQ(cw::kSwitchOnCmd, 0x07);
  EXPECT_EQ(cw::kEnableOperationCmd, 0x0F);
  EXPECT_EQ(cw::kDisableVoltage, 0x00);
  EXPECT_EQ(cw::kQuickStopCmd, 0x02);
  EXPECT_EQ(cw::kDisableOperation, 0x07);
  EXPECT_EQ(cw::kFaultResetCmd, 0x80);
  using G = Goal;
  // The walk up: 2, 3, 4.
  EXPECT_EQ(command_for(State::kSwitchOnDisabled, G::kOperationEnabled, false), 0x06);
  EXPECT_EQ(command_for(State::kReadyToSwitchOn, G::kOperationEnabled, false), 0x07);
  EXPECT_EQ(command_for(State::kSwitchedOn, G::kOperationEnabled, false), 0x0F);
  EXPECT_EQ(command_for(State::kOperationEnabled, G::kOperationEnabled, false), 0x0F);
  // Down from Operation enabled: by default Quick stop (11) whatever the
  // goal, so the drive's 605Ah ramp acts; Stop::kShutdown gives 5 and 8
  // (605Ch, 605Bh ramps); only Stop::kDirect gives Disable voltage (9).
  for (G g : {G::kSwitchedOn, G::kReadyToSwitchOn, G::kSwitchOnDisabled})
    EXPECT_EQ(command_for(State::kOperationEnabled, g, false), 0x02);
  EXPECT_EQ(command_for(State::kOperationEnabled, G::kSwitchedOn, false, Stop::kShutdown), 0x07);
  EXPECT_EQ(command_for(State::kOperationEnabled, G::kReadyToSwitchOn, false, Stop::kShutdown), 0x06);
  EXPECT_EQ(command_for(State::kOperationEnabled, G::kSwitchOnDisabled, false, Stop::kShutdown), 0x06);
  EXPECT_EQ(command_for(State::kOperationEnabled, G::kSwitchedOn, false, Stop::kDirect), 0x07);
  EXPECT_EQ(command_for(State::kOperationEnabled, G::kReadyToSwitchOn, false, Stop::kDirect), 0x06);
  EXPECT_EQ(command_for(State::kOperationEnabled, G::kSwitchOnDisabled, false, Stop::kDirect), 0x00);
  // Quick stop active below Operation enabled: the quick stop is held while
  // the drive ramps (bit 10 low), Disable voltage (12) once it stopped.
  for (Stop st : {Stop::kQuickStop, Stop::kShutdown, Stop::kDirect}) {
    EXPECT_EQ(command_for(State::kQuickStopActive, G::kSwitchOnDisabled, false, st, false), 0x02);
    EXPECT_EQ(command_for(State::kQuickStopActive, G::kSwitchOnDisabled, false, st, true), 0x00);
  }
  // 6, 7, 10 and holding.
  EXPECT_EQ(command_for(State::kSwitchedOn, G::kReadyToSwitchOn, false), 0x06);
  EXPECT_EQ(command_for(State::kSwitchedOn, G::kSwitchOnDisabled, false), 0x00);
  EXPECT_EQ(command_for(State::kSwitchedOn, G::kSwitchedOn, false), 0x07);
  EXPECT_EQ(command_for(State::kReadyToSwitchOn, G::kSwitchOnDisabled, false), 0x00);
  EXPECT_EQ(command_for(State::kReadyToSwitchOn, G::kReadyToSwitchOn, false), 0x06);
  EXPECT_EQ(command_for(State::kReadyToSwitchOn, G::kSwitchedOn, false), 0x07);
  EXPECT_EQ(command_for(State::kSwitchOnDisabled, G::kSwitchOnDisabled, false), 0x00);
  EXPECT_EQ(command_for(State::kSwitchOnDisabled, G::kSwitchedOn, false), 0x06);
  // Quick stop from anywhere but Fault: 7, 10, 11; 16 back.
  for (State s : {State::kSwitchOnDisabled, State::kReadyToSwitchOn, State::kSwitchedOn, State::kOperationEnabled,
                  State::kQuickStopActive})
    EXPECT_EQ(command_for(s, G::kQuickStop, false), 0x02) << state_name(s);
  EXPECT_EQ(command_for(State::kQuickStopActive, G::kOperationEnabled, false), 0x0F);
  EXPECT_EQ(command_for(State::kQuickStopActive, G::kSwitchedOn, false), 0x00);
  // Fault: bit 7 low, then the reset.
  EXPECT_EQ(command_for(State::kFault, G::kOperationEnabled, false), 0x00);
  EXPECT_EQ(command_for(State::kFault, G::kOperationEnabled, true), 0x80);
  EXPECT_EQ(command_for(State::kFault, G::kQuickStop, true), 0x80);
  EXPECT_EQ(command_for(State::kFaultReactionActive, G::kOperationEnabled, true), 0x00);
  EXPECT_EQ(command_for(State::kNotReadyToSwitchOn, G::kOperationEnabled, false), 0x00);
}

TEST(Cia402Transitions, NumbersOfThePdsFsaFigure) {
  using S = State;
  EXPECT_EQ(transition_number(S::kNotReadyToSwitchOn, S::kSwitchOnDisabled), 1);
  EXPECT_EQ(transition_number(S::kSwitchOnDisabled, S::kReadyToSwitchOn), 2);
  EXPECT_EQ(transition_number(S::kReadyToSwitchOn, S::kSwitchedOn), 3);
  EXPECT_EQ(transition_number(S::kSwitchedOn, S::kOperationEnabled), 4);
  EXPECT_EQ(transition_number(S::kOperationEnabled, S::kSwitchedOn), 5);
  EXPECT_EQ(transition_number(S::kSwitchedOn, S::kReadyToSwitchOn), 6);
  EXPECT_EQ(transition_number(S::kReadyToSwitchOn, S::kSwitchOnDisabled), 7);
  EXPECT_EQ(transition_number(S::kOperationEnabled, S::kReadyToSwitchOn), 8);
  EXPECT_EQ(transition_number(S::kOperationEnabled, S::kSwitchOnDisabled), 9);
  EXPECT_EQ(transition_number(S::kSwitchedOn, S::kSwitchOnDisabled), 10);
  EXPECT_EQ(transition_number(S::kOperationEnabled, S::kQuickStopActive), 11);
  EXPECT_EQ(transition_number(S::kQuickStopActive, S::kSwitchOnDisabled), 12);
  for (S s : {S::kNotReadyToSwitchOn, S::kSwitchOnDisabled, S::kReadyToSwitchOn, S::kSwitchedOn,
              S::kOperationEnabled, S::kQuickStopActive})
    EXPECT_EQ(transition_number(s, S::kFaultReactionActive), 13);
  EXPECT_EQ(transition_number(S::kFaultReactionActive, S::kFault), 14);
  EXPECT_EQ(transition_number(S::kFault, S::kSwitchOnDisabled), 15);
  EXPECT_EQ(transition_number(S::kQuickStopActive, S::kOperationEnabled), 16);
  EXPECT_EQ(transition_number(S::kSwitchOnDisabled, S::kOperationEnabled), -1);
  EXPECT_EQ(transition_number(S::kFault, S::kOperationEnabled), -1);
}

TEST(Cia402Master, ResetEdgeNeedsAScanWithBit7LowInFault) {
  Master m;
  MasterInputs in;
  in.enable = true;
  in.statusword = 0x08;  // Fault, first scan
  in.reset = true;       // edge on the very first scan
  MasterOutputs o = m.step(in, 0);
  EXPECT_TRUE(o.fault_event);
  EXPECT_EQ(o.controlword, 0x00);  // bit 7 low first
  o = m.step(in, 1'000'000);
  EXPECT_EQ(o.controlword, 0x80);  // then the edge
  in.statusword = 0x40;             // the drive took it
  o = m.step(in, 2'000'000);
  EXPECT_TRUE(o.recovered_event);
  EXPECT_EQ(o.controlword, 0x06);  // bit 7 low again, on towards Operation enabled
}

TEST(Cia402Master, TimeoutInVirtualTimeExactly) {
  MasterConfig c;
  c.transition_timeout_ns = 50'000'000;
  Master m(c);
  MasterInputs in;
  in.enable = true;
  in.mode = in.mode_display = 8;
  in.statusword = 0x40;  // stays in Switch on disabled although told Shutdown
  for (std::int64_t t = 0; t < 50'000'000; t += 1'000'000) {
    const MasterOutputs o = m.step(in, t);
    ASSERT_FALSE(o.timeout) << t;
    ASSERT_TRUE(o.busy);
  }
  MasterOutputs o = m.step(in, 50'000'000);
  EXPECT_TRUE(o.timeout);
  EXPECT_TRUE(o.timeout_event);
  o = m.step(in, 51'000'000);
  EXPECT_TRUE(o.timeout);
  EXPECT_FALSE(o.timeout_event);  // once
  in.statusword = 0x21;            // the drive moves at last: the timeout clears
  o = m.step(in, 52'000'000);
  EXPECT_FALSE(o.timeout);
}

TEST(Cia402Master, FaultWithoutResetIsNoTimeout) {
  MasterConfig c;
  c.transition_timeout_ns = 10'000'000;
  Master m(c);
  MasterInputs in;
  in.enable = true;
  in.statusword = 0x08;
  for (std::int64_t t = 0; t < 100'000'000; t += 1'000'000) {
    const MasterOutputs o = m.step(in, t);
    ASSERT_FALSE(o.timeout);
    ASSERT_FALSE(o.busy);
    ASSERT_TRUE(o.fault);
  }
}

// A link lost in Operation enabled: Quick stop at once (not the held 000Fh),
// the state forgotten; after the link returns the drive is stopped until
// enable has been FALSE with the link up, then a new enable walks it up.
TEST(Cia402Master, LinkLossQuickStopsAndNeedsANewEnable) {
  Master m;
  MasterInputs in;
  in.enable = true;
  in.mode = in.mode_display = 8;
  in.statusword = 0x23;
  EXPECT_EQ(m.step(in, 0).controlword, 0x0F);
  in.statusword = 0x27;
  MasterOutputs o = m.step(in, 1'000'000);
  EXPECT_TRUE(o.run);
  EXPECT_FALSE(o.link_lost);
  in.link_ok = false;
  in.statusword = 0;  // stale value: must not be decoded
  o = m.step(in, 2'000'000);
  EXPECT_EQ(o.state, State::kUnknown);
  EXPECT_EQ(o.controlword, 0x02);
  EXPECT_FALSE(o.operation_enabled);
  EXPECT_FALSE(o.run);
  EXPECT_TRUE(o.link_lost);
  EXPECT_TRUE(o.link_lost_event);
  EXPECT_FALSE(o.fault_event);
  o = m.step(in, 3'000'000);
  EXPECT_EQ(o.controlword, 0x02);
  EXPECT_FALSE(o.link_lost_event);  // once
  // The link returns, the drive still in Operation enabled, enable still TRUE:
  // Quick stop, held while the drive ramps, no Enable operation.
  in.link_ok = true;
  in.statusword = 0x27;
  o = m.step(in, 4'000'000);
  EXPECT_EQ(o.controlword, 0x02);
  EXPECT_FALSE(o.run);
  EXPECT_TRUE(o.link_lost);
  in.statusword = 0x07;  // Quick stop active, ramping
  for (std::int64_t t = 5; t < 20; ++t) {
    o = m.step(in, t * 1'000'000);
    ASSERT_EQ(o.controlword, 0x02) << t;
  }
  in.statusword = 0x40;  // the drive ended in Switch on disabled (605Ah 0..4)
  for (std::int64_t t = 20; t < 40; ++t) {
    o = m.step(in, t * 1'000'000);
    ASSERT_EQ(o.controlword, 0x02) << t;  // never Shutdown: enable is not new
    ASSERT_FALSE(o.busy);
  }
  in.enable = false;
  o = m.step(in, 40'000'000);
  EXPECT_FALSE(o.link_lost);
  EXPECT_EQ(o.controlword, 0x00);
  in.enable = true;  // the new enable
  o = m.step(in, 41'000'000);
  EXPECT_TRUE(o.run);
  EXPECT_EQ(o.controlword, 0x06);
}

TEST(Cia402Master, LinkLossCanCoastWhenTheProjectAsks) {
  MasterConfig c;
  c.link_lost = Stop::kDirect;
  Master m(c);
  MasterInputs in;
  in.enable = true;
  in.mode = in.mode_display = 8;
  in.statusword = 0x27;
  m.step(in, 0);
  in.link_ok = false;
  EXPECT_EQ(m.step(in, 1'000'000).controlword, 0x00);
  in.link_ok = true;
  const MasterOutputs o = m.step(in, 2'000'000);
  EXPECT_EQ(o.controlword, 0x00);  // 9
  EXPECT_FALSE(o.run);
}

// Before the link is first up is the start, not a loss: enable TRUE from the
// start walks the drive up once the first statusword arrives.
TEST(Cia402Master, NoReplyYetIsNoLinkLoss) {
  Master m;
  MasterInputs in;
  in.enable = true;
  in.link_ok = false;
  MasterOutputs o = m.step(in, 0);
  EXPECT_FALSE(o.link_lost_event);
  EXPECT_FALSE(o.run);
  in.link_ok = true;
  in.statusword = 0x40;
  o = m.step(in, 1'000'000);
  EXPECT_TRUE(o.run);
  EXPECT_EQ(o.controlword, 0x06);
}

// A drive found in Operation enabled at the first statusword (a restarted
// PLC, a drive left running): stopped, and a new enable is needed.
TEST(Cia402Master, ADriveFoundRunningAtTheStartIsStopped) {
  Master m;
  MasterInputs in;
  in.enable = true;
  in.mode = in.mode_display = 8;
  in.statusword = 0x27;
  const MasterOutputs o = m.step(in, 0);
  EXPECT_EQ(o.controlword, 0x02);
  EXPECT_FALSE(o.run);
  EXPECT_TRUE(o.link_lost);
}

// enable FALSE in Operation enabled: Quick stop by default, held until the
// drive reports the ramp done, never Disable voltage first.
TEST(Cia402Master, DisableGoesThroughQuickStopByDefault) {
  Master m;
  MasterInputs in;
  in.enable = true;
  in.mode = in.mode_display = 8;
  in.statusword = 0x40;
  m.step(in, 0);
  in.statusword = 0x27;
  in.enable = false;
  m.step(in, 0);
  MasterOutputs o = m.step(in, 1'000'000);
  EXPECT_EQ(o.controlword, 0x02);
  in.statusword = 0x07;  // ramping
  o = m.step(in, 2'000'000);
  EXPECT_EQ(o.controlword, 0x02);
  in.statusword = 0x07 | sw::kTargetReached;  // stopped (option code 5..8 keeps it here)
  o = m.step(in, 3'000'000);
  EXPECT_EQ(o.controlword, 0x00);  // 12
}

}  // namespace
}  // namespace syncplc::drives::cia402
