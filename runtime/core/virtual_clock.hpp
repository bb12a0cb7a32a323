// The scheduler in virtual time: the same tasks and the same scan as in real
// time, driven by a virtual clock instead of clock_nanosleep. Tasks are
// released on their own grids (phase + k × period) in time order; at equal
// release the higher priority runs first (then the task declared first).
// A scan takes the virtual execution time its blocks consume
// (ScanContext::consumed_ns, 0 by default); its snapshot is published when
// it ends. What other tasks read of it does not depend on when it ends, only
// on its logical instant (snapshot_channel.hpp), which is why a run here
// gives, scan by scan, the values the real-time scheduler gives. Nothing
// depends on the wall clock, so a run is bit-for-bit reproducible.
//
// Online change (program_change.hpp) works here exactly as in real time:
// each task switches at its first release at or after the switch instant.
#pragma once

#include <cstdint>
#include <functional>
#include <limits>
#include <vector>

#include "runtime/core/program.hpp"
#include "runtime/core/program_change.hpp"
#include "runtime/core/task_switch.hpp"

namespace syncplc {

class VirtualClock {
 public:
  explicit VirtualClock(Program& program);

  // Runs every scan that starts before t (inclusive: at or before t).
  void run_until(std::int64_t t, bool inclusive = false);
  // The time of the last event processed.
  std::int64_t now() const { return now_; }
  // The time of the next event (a scan's start or a publication); kNever
  // when no task will run again. Several programs on one clock (a system's
  // nodes, system_clock.hpp) step together by it.
  static constexpr std::int64_t kNever = std::numeric_limits<std::int64_t>::max();
  std::int64_t next_event() const;
  // Called after all scans that started at time t have run (once per such t).
  void on_time_point(std::function<void(std::int64_t t)> f) { observer_ = std::move(f); }
  // Planned release of scan number n of a task (ignores overruns).
  std::int64_t release_of(std::uint16_t task, std::uint64_t n) const;
  // Scans of the current program's task (an online change carries the count over).
  std::uint64_t scans(std::uint16_t task) const;
  Program& program() const { return *program_; }
  // The clock's one thread is every task's thread: virtual-time tools
  // (scan-cycle tests, traces, metrics) touch the images through it
  // (image_access.hpp), between two run_until calls or in an observer.
  ImageAccess image_access() const { return ImageAccess{}; }
  Cell* live_cell(const CellRef& r) const { return program_->live_cell(r, ImageAccess{}); }

  // Online change: from now on every old task mirrors its publications; each
  // task switches at its first release at or after change.switch_ns (set it
  // with switch_instant, or later). The change is complete once every task
  // has switched (change_complete()); program() is then change.to.
  void begin_change(ProgramChange& change);
  bool change_complete() const { return change_ == nullptr; }

 private:
  struct TaskState {
    Task* task = nullptr;
    std::int64_t k = 0;              // grid index of the next planned release
    std::int64_t not_before = 0;     // the next scan cannot start before the previous ended
    std::int64_t prev_planned = 0;
    std::int64_t publish_at = -1;    // pending publication time, -1 none
    std::uint64_t scans = 0;
    bool stopped = false;
    bool gone = false;               // removed by an online change
  };
  struct Next {
    int state = -1;  // index into state_, -1 none
    bool publish = false;
    std::int64_t time = kNever;
  };
  Next pick() const;
  void flush_observer();
  static OldGrid old_grid(const TaskState& s);
  // At a task's first release >= T: switches it (true) or ends it (removed).
  void switch_task(TaskState& s);
  void finish_change();

  Program* program_;
  std::vector<TaskState> state_;
  std::int64_t now_ = 0;
  std::int64_t observed_ = -1;       // time point with scans not yet reported
  std::function<void(std::int64_t)> observer_;
  ProgramChange* change_ = nullptr;
};

}  // namespace syncplc
