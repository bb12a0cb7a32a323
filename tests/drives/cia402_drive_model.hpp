// Test support: the drive side of the CiA 402 PDS state machine (CiA 402-2 /
// IEC 61800-7-201, the finite state automaton figure), written from the
// standard independently of fblocks/drives/cia402_math, as a drive would run
// it: one transition per drive cycle, decided from the controlword, with the
// automatic transitions 0, 1, 12 (quick stop option codes 0..4), 13 and 14;
// in Quick stop active bit 10 (target reached) tells the ramp is done.
// It logs every transition it makes, so a test can check that the block
// walked it through each arrow of the figure.
#pragma once

#include <cstdint>
#include <vector>

#include "fblocks/drives/cia402_math.hpp"

namespace syncplc::drives::test {

using cia402::State;

class DriveModel {
 public:
  struct Options {
    int quick_stop_option = 2;   // 605Ah: 0..4 end in Switch on disabled, 5..8 stay in Quick stop active
    int not_ready_cycles = 2;    // cycles in Not ready to switch on after power on (transition 1)
    int quick_stop_cycles = 3;   // cycles a quick stop ramp takes (then 12 for codes 0..4)
    int fault_reaction_cycles = 3;  // cycles of the fault reaction (then 14)
  };

  DriveModel() : DriveModel(Options{}) {}
  explicit DriveModel(Options o) : o_(o), timer_(o.not_ready_cycles) { log_.push_back(0); }  // 0: power on -> Not ready to switch on

  // One drive cycle with this controlword and modes of operation.
  void cycle(std::uint16_t controlword, int mode) {
    const bool reset_edge = (controlword & 0x80) && !(prev_cw_ & 0x80);
    prev_cw_ = controlword;
    if (mode == 1 || mode == 3 || mode == 4 || mode == 8 || mode == 9 || mode == 10) display_ = mode;
    if (stuck_) return;
    if (fault_pending_ && state_ != State::kFaultReactionActive && state_ != State::kFault) {
      fault_pending_ = false;
      go(State::kFaultReactionActive, 13);
      timer_ = o_.fault_reaction_cycles;
      return;
    }
    // Command coding table (bits 7, 3, 2, 1, 0).
    const bool disable_voltage = !(controlword & 0x02);
    const bool quick_stop = (controlword & 0x06) == 0x02;
    const bool shutdown = (controlword & 0x87) == 0x06;
    const bool switch_on = (controlword & 0x8F) == 0x07;
    const bool enable_op = (controlword & 0x8F) == 0x0F;
    switch (state_) {
      case State::kNotReadyToSwitchOn:
        if (--timer_ <= 0) go(State::kSwitchOnDisabled, 1);
        break;
      case State::kSwitchOnDisabled:
        if (shutdown) go(State::kReadyToSwitchOn, 2);
        break;
      case State::kReadyToSwitchOn:
        if (switch_on || enable_op) go(State::kSwitchedOn, 3);  // 3 (+4 next cycle for 16#0F)
        else if (disable_voltage || quick_stop) go(State::kSwitchOnDisabled, 7);
        break;
      case State::kSwitchedOn:
        if (enable_op) go(State::kOperationEnabled, 4);
        else if (shutdown) go(State::kReadyToSwitchOn, 6);
        else if (disable_voltage || quick_stop) go(State::kSwitchOnDisabled, 10);
        break;
      case State::kOperationEnabled:
        if (switch_on) go(State::kSwitchedOn, 5);
        else if (shutdown) go(State::kReadyToSwitchOn, 8);
        else if (disable_voltage) go(State::kSwitchOnDisabled, 9);
        else if (quick_stop) {
          go(State::kQuickStopActive, 11);
          timer_ = o_.quick_stop_cycles;
        }
        break;
      case State::kQuickStopActive:
        if (disable_voltage) go(State::kSwitchOnDisabled, 12);
        else if (o_.quick_stop_option >= 5 && enable_op) go(State::kOperationEnabled, 16);
        else if (timer_ > 0 && --timer_ == 0 && o_.quick_stop_option <= 4) go(State::kSwitchOnDisabled, 12);
        break;
      case State::kFaultReactionActive:
        if (--timer_ <= 0) go(State::kFault, 14);
        break;
      case State::kFault:
        if (reset_edge) {
          if (persistent_fault_) break;
          error_code_ = 0;
          go(State::kSwitchOnDisabled, 15);
        }
        break;
      case State::kUnknown:
        break;
    }
  }

  std::uint16_t statusword() const {
    std::uint16_t s = cia402::statusword_of(state_) | 0x0200;  // bit 9 remote
    if (state_ == State::kReadyToSwitchOn || state_ == State::kSwitchedOn || state_ == State::kOperationEnabled)
      s |= 0x20;  // quick stop bit (low active)
    if (state_ == State::kSwitchedOn || state_ == State::kOperationEnabled || state_ == State::kQuickStopActive)
      s |= 0x10;  // voltage enabled
    if (state_ == State::kQuickStopActive && timer_ <= 0) s |= 0x0400;  // target reached: the quick stop ramp is done
    return s;
  }
  State state() const { return state_; }
  int mode_display() const { return display_; }
  std::uint16_t error_code() const { return error_code_; }
  const std::vector<int>& transitions() const { return log_; }

  void inject_fault(std::uint16_t code, bool persistent = false) {
    fault_pending_ = true;
    error_code_ = code;
    persistent_fault_ = persistent;
  }
  void clear_persistent_fault() { persistent_fault_ = false; }
  void set_stuck(bool s) { stuck_ = s; }  // ignores every command (a drive that never answers the FSA)

 private:
  void go(State to, int transition) {
    log_.push_back(transition);
    state_ = to;
  }

  Options o_;
  int timer_ = 0;
  State state_ = State::kNotReadyToSwitchOn;
  int display_ = 0;
  std::uint16_t prev_cw_ = 0;
  std::uint16_t error_code_ = 0;
  bool fault_pending_ = false, persistent_fault_ = false, stuck_ = false;
  std::vector<int> log_;
};

}  // namespace syncplc::drives::test
