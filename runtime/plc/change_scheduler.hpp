// What an online change needs of the scheduler that runs the tasks: the
// time on the tasks' axis, the start of the switch, and whether every task
// has switched. The real-time runner and the virtual clock both provide it,
// so one transaction (transaction.hpp) drives a change in either; each task's
// switch itself is the one rule of runtime/core/task_switch.hpp.
#pragma once

#include <cstdint>

#include "runtime/core/program_change.hpp"
#include "runtime/core/realtime.hpp"
#include "runtime/core/virtual_clock.hpp"

namespace syncplc::plc {

class ChangeScheduler {
 public:
  virtual ~ChangeScheduler() = default;
  virtual std::int64_t now_ns() const = 0;
  // Every old task mirrors into the new program from now on; each switches
  // between two scans (task_switch.hpp). change.switch_ns is set.
  virtual void begin_change(ProgramChange& change) = 0;
  virtual bool change_complete() const = 0;
  // The scheduler runs only the new program from now on; the old one may go.
  virtual void finish_change() = 0;
};

class RealtimeScheduler final : public ChangeScheduler {
 public:
  explicit RealtimeScheduler(RealtimeRunner& r) : r_(r) {}
  std::int64_t now_ns() const override { return r_.now_ns(); }
  void begin_change(ProgramChange& c) override { r_.begin_change(c); }
  bool change_complete() const override { return r_.change_complete(); }
  void finish_change() override { r_.finish_change(); }

 private:
  RealtimeRunner& r_;
};

// Virtual time: the test (or `syncplc sim`) advances the clock; the change
// completes as the clock passes each task's switch.
class VirtualScheduler final : public ChangeScheduler {
 public:
  explicit VirtualScheduler(VirtualClock& c) : c_(c) {}
  std::int64_t now_ns() const override { return c_.now(); }
  void begin_change(ProgramChange& c) override { c_.begin_change(c); }
  bool change_complete() const override { return c_.change_complete(); }
  void finish_change() override {}  // the clock finishes by itself once every task switched

 private:
  VirtualClock& c_;
};

}  // namespace syncplc::plc
