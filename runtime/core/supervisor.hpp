// The supervisor of a real-time run. From a non-real-time thread (the main
// thread of `syncplc run`) it watches what a task cannot judge by itself, a
// scan that does not end, and it ends a run whose task threads cannot all be
// joined.
//
// A scan that runs past its task's hang limit is given up on: the task is
// stopped (Task::stop_from_supervisor: Modbus writes to it are refused with
// exception 04, no further scan of it starts should this one ever end), each
// of its drivers is put in its safe state through
// IoDriver::write_safe_outputs (the `safe:` values of the tags bound to its
// outputs; outputs without one hold their last value; a scan that ends late
// cannot change them), and events are raised. The scan itself cannot be
// interrupted: its thread stays where it is.
//
// Hang limit: for a task whose watchdog stops it (action stop or safe_stop),
// the watchdog's limit for one scan, time × sensitivity (the scan has tripped
// it already; the watchdog can only act when the scan ends). Otherwise (no
// watchdog, or action log) the longest of 1 s, 10 periods and time ×
// sensitivity: a `log` watchdog tolerates overruns, not a scan that never
// ends. A task with action log is reported once a scan when it passes its
// watchdog's limit.
//
// Events go to the supervisor's own channel (pop_event): a task's event ring
// has one producer, the task's own thread. Every member function is for one
// thread, the one that runs the supervisor.
#pragma once

#include <cstdint>
#include <deque>
#include <vector>

#include "runtime/core/program.hpp"
#include "runtime/core/realtime.hpp"

namespace syncplc {

class Supervisor {
 public:
  // How long stop() waits for the task threads before it gives up on them.
  static constexpr std::int64_t kStopGraceNs = 500'000'000;

  Supervisor(Program& program, RealtimeRunner& runner);
  // After an online change: the program and runner that run now.
  void attach(Program& program, RealtimeRunner& runner);

  // Looks at every task once; call it a few times a second.
  void check();
  // Ends the run: asks the tasks to stop and waits up to `grace_ns` for their
  // threads. A scan still running then is given up on (as above). True when
  // every thread has ended (join the runner, close the drivers); false when a
  // thread is stuck in a scan: it cannot be joined, and the process must end
  // without it (the drivers of its task are in their safe state).
  bool stop(std::int64_t grace_ns = kStopGraceNs);

  // The supervisor's events, oldest first.
  bool pop_event(Event& e);
  // Whether a scan of task i was given up on.
  bool hung(std::size_t task) const { return task < watch_.size() && watch_[task].hung; }
  bool any_hung() const;
  // Every task has stopped: by its watchdog, or given up on here.
  bool all_stopped() const;

  static std::int64_t hang_limit_ns(const TaskConfig& c);

 private:
  struct DriverSafeState {
    IoDriver* driver;
    std::vector<SafeOutput> outputs;  // the `safe:` values of the tags bound to its outputs
  };
  struct Watch {
    bool reported = false;  // this scan passed a `log` watchdog's limit and was reported
    bool hung = false;      // given up on
    std::vector<DriverSafeState> drivers;
  };
  void give_up(std::size_t task, std::int64_t running_ns, const char* why);
  void raise(std::size_t task, EventKind kind, const char* message, double value);

  Program* program_;
  RealtimeRunner* runner_;
  std::vector<Watch> watch_;
  std::deque<Event> events_;
};

}  // namespace syncplc
