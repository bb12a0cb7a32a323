// The drivers' part in an online change (transaction.hpp): a driver whose
// settings are unchanged moves into the new program open, with its state
// (runtime/core/program_change.hpp, at each task's switch); the others:
//
//   prepare   each new driver of a type that an old, replaced driver has
//             is paired with at most one of them, its namesake first, and
//             told it will take over what that one holds open
//             (IoDriver::will_take_over: a modbus_client device at the same
//             address keeps its one TCP connection); then every new driver
//             opens. One that cannot refuses the change; those opened close.
//   complete  each pair's take_over, then the old drivers close.
//
// One to one: a connection handed to two successors would be held by one
// and leaked by the other (issue 21: six reloads of two drivers left seven
// sockets in CLOSE-WAIT).
#pragma once

#include <cstddef>
#include <utility>
#include <vector>

#include "runtime/plc/transaction.hpp"

namespace syncplc::plc {

// (old binding, new binding) pairs for take-over: one to one, same type,
// the same name first.
std::vector<std::pair<std::size_t, std::size_t>> pair_takeovers(const Program& old, const Program& next,
                                                                const ProgramChange& change);

class DriverChange final : public ChangeParticipant {
 public:
  const char* name() const override { return "drivers"; }
  bool prepare(ChangeContext& c, std::string* why) override;
  void abort(ChangeContext& c) override;
  void complete(ChangeContext& c) override;
  // Closes what a change that never completed left open (the PLC stops
  // while a task has not reached its switch; after its thread was joined).
  void close_left_over(ChangeContext& c);

 private:
  std::vector<std::pair<std::size_t, std::size_t>> pairs_;
  std::size_t opened_ = 0;  // of change.new_drivers
};

}  // namespace syncplc::plc
