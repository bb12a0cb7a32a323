// The supervisor of a real-time run: watches what a task cannot judge by
// itself, a scan that does not end, and ends a run whose task threads cannot
// all be joined. It runs on its own thread (runtime/plc/supervisor_thread.hpp),
// independent of online changes, signals and the servers.
//
// It watches threads, not a program's task list: each task thread reports the
// task it runs now (an online change moves it from an old task to its
// successor between two scans, RealtimeRunner::threads), so a scan that hangs
// while a change is under way is judged, and made safe, on the task and the
// drivers that thread really runs.
//
// A scan that runs past its task's hang limit is given up on: the task is
// stopped (Task::stop_from_supervisor: Modbus writes to it are refused with
// exception 04, no further scan of it starts should this one ever end), each
// of the drivers that task uses is put in its safe state through
// IoDriver::write_safe_outputs (the `safe:` values of the tags bound to its
// outputs in the program the task belongs to; outputs without one hold their
// last value; a scan that ends late cannot change them), and events are
// raised. The scan itself cannot be interrupted: its thread stays where it is.
//
// Hang limit: for a task whose watchdog stops it (action stop or safe_stop),
// the watchdog's limit for one scan, time × sensitivity (the scan has tripped
// it already; the watchdog can only act when the scan ends). Otherwise (no
// watchdog, or action log) the longest of 1 s, 10 periods and time ×
// sensitivity: a `log` watchdog tolerates overruns, not a scan that never
// ends. A task with action log is reported once a scan when it passes its
// watchdog's limit.
//
// Every member function is thread-safe (one mutex, never taken by a task thread).
#pragma once

#include <cstdint>
#include <deque>
#include <map>
#include <mutex>
#include <string>
#include <vector>

#include "runtime/core/program.hpp"
#include "runtime/core/realtime.hpp"

namespace syncplc {

// An event of the supervisor's, with the name of the task it concerns (the
// task's program may be gone when it is read: an online change completed).
struct SupervisorEvent {
  Event event;
  std::string task;
};

class Supervisor {
 public:
  // How long stop() waits for the task threads before it gives up on them.
  static constexpr std::int64_t kStopGraceNs = 500'000'000;

  // Watches `runner`'s threads; `program` is the one it runs.
  Supervisor(Program& program, RealtimeRunner& runner);

  // Online change: the tasks of `next` may run from now on (its drivers' safe
  // outputs are taken now, while every driver is still in its binding).
  void watch(Program& next);
  // The tasks of `p` run no more (the change completed; p is about to go).
  void forget(const Program& p);

  // Looks at every task thread once; call it a few times a second.
  void check();
  // Ends the run: asks the tasks to stop and waits up to `grace_ns` for their
  // threads. A scan still running then is given up on (as above). True when
  // every thread has ended (join the runner, close the drivers); false when a
  // thread is stuck in a scan: it cannot be joined, and the process must end
  // without it (the drivers of its task are in their safe state).
  bool stop(std::int64_t grace_ns = kStopGraceNs);

  // The supervisor's events, oldest first.
  bool pop_event(SupervisorEvent& e);
  // Whether a scan of task `t` was given up on.
  bool hung(const Task* t) const;
  bool any_hung() const;
  // Every task thread's task has stopped: by its watchdog, or given up on here.
  bool all_stopped() const;

  static std::int64_t hang_limit_ns(const TaskConfig& c);

 private:
  // A task's drivers by their slot in Task::drivers, with their safe outputs.
  struct TaskSafety {
    const Program* program = nullptr;
    std::uint16_t index = 0;
    std::vector<std::vector<SafeOutput>> by_slot;
  };
  struct Watch {
    bool reported = false;  // this scan passed a `log` watchdog's limit and was reported
    bool hung = false;      // given up on
  };
  void add(Program& p);
  void give_up(const RealtimeRunner::ThreadView& v, const char* why);
  void raise(const Task& t, EventKind kind, const char* message, double value);

  RealtimeRunner* runner_;
  mutable std::mutex mutex_;
  std::map<const Task*, TaskSafety> safety_;
  std::map<const void*, Watch> watch_;  // by thread
  std::map<const Task*, bool> hung_;
  std::deque<SupervisorEvent> events_;
};

}  // namespace syncplc
