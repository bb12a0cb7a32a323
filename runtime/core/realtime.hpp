// The scheduler in real time: one thread per task, SCHED_FIFO at the task's
// priority where permitted (otherwise a warning and normal priority), memory
// locked with mlockall, releases on absolute CLOCK_MONOTONIC deadlines with
// clock_nanosleep(TIMER_ABSTIME). All tasks share one epoch, so their grids
// keep their phase relation and never drift.
//
// Online change (program_change.hpp): each thread switches its task to the
// new program between two scans, at its first release at or after the switch
// instant, on the same grid (re-timed tasks: the new grid from there); the
// epoch never changes, so no scan is skipped or late because of a change.
#pragma once

#include <atomic>
#include <cstdint>
#include <list>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "runtime/core/cpu_latency.hpp"
#include "runtime/core/program.hpp"
#include "runtime/core/program_change.hpp"

namespace syncplc {

class RealtimeRunner {
 public:
  struct Options {
    bool lock_memory = true;
    bool fifo = true;
    std::int64_t start_delay_ns = 20'000'000;  // time to set up every thread before the epoch
    // Hold /dev/cpu_dma_latency at this many microseconds while running
    // (cpu_latency.hpp); -1 leaves the CPUs' idle states alone.
    int cpu_latency_us = 0;
    // Run for this long from the epoch (the first release), then end by
    // themselves: exactly the releases before it get a scan. 0: until stopped.
    std::int64_t duration_ns = 0;
    // Anchor the grid to CLOCK_REALTIME: the epoch (the first release) is
    // the next instant after start_delay_ns that is a whole multiple of this
    // since the Unix epoch, so that nodes whose clocks agree release their
    // scans in phase (docs/dds.md, "One grid for all nodes"). 0: the epoch
    // is start_delay_ns from now.
    std::int64_t align_ns = 0;
  };
  RealtimeRunner(Program& program, Options options);
  explicit RealtimeRunner(Program& program) : RealtimeRunner(program, Options{}) {}
  ~RealtimeRunner();

  void start();
  void request_stop() { stop_.store(true, std::memory_order_release); }
  void join();
  // Some task is still scanning (not every one stopped by its watchdog).
  bool running() const;
  // Some task thread has not returned yet (a stopped task's thread waits for
  // an online change; a thread stuck in a scan never returns).
  bool threads_alive() const;
  // Warnings collected at start (no SCHED_FIFO permission, mlockall failed...).
  std::vector<std::string> warnings() const;
  std::int64_t epoch_ns() const { return epoch_; }
  // The epoch on CLOCK_REALTIME (ns since the Unix epoch): a whole multiple
  // of Options::align_ns when that is set.
  std::int64_t epoch_realtime_ns() const { return epoch_realtime_; }
  // Now on the tasks' time axis (ns since the epoch).
  std::int64_t now_ns() const { return monotonic_ns() - epoch_; }
  // Supervision from a non-real-time thread: for each task, how long its
  // current scan has been running (0 when it is between scans). The watchdog
  // proper is evaluated when a scan ends; this is how a scan that never ends
  // is noticed (it cannot be interrupted safely, only reported).
  std::int64_t scan_running_ns(std::size_t task) const;
  // The supervisor's view of every task thread (supervisor.hpp): the task it
  // runs now (an online change moves a thread from an old task to its
  // successor between two scans) and how long its current scan has run
  // (0 between scans). Thread-safe against online changes; the task threads
  // never wait for it.
  struct ThreadView {
    const void* id;           // the thread, stable while it lives
    Task* task;
    std::int64_t running_ns;
    bool alive;
  };
  std::vector<ThreadView> threads() const;
  Program& program() const { return *program_; }

  // Online change, from the main thread: set change.switch_ns (switch_instant),
  // then begin_change; poll change_complete(); then finish_change(), after
  // which program() is change.to and change.from may be destroyed.
  void begin_change(ProgramChange& change);
  bool change_complete() const;
  void finish_change();

  static std::int64_t monotonic_ns();

 private:
  struct Worker {
    std::thread thread;
    std::atomic<Task*> task{nullptr};
    std::atomic<std::int64_t> scan_started{-1};  // -1 between scans
    std::atomic<bool> alive{true};
  };
  struct Start {
    std::int64_t k = 0;             // first grid index
    std::int64_t prev_planned = 0;
    TaskHandover* perform = nullptr;  // an added task's handover, performed before its first scan
  };
  void task_thread(Worker& w, Start start);
  void configure_thread(const TaskConfig& cfg);
  void warn(std::string w);

  Program* program_;
  Options options_;
  // workers_ and by_task_ change only under workers_mutex_ (start, online
  // change, join), which the task threads never take.
  mutable std::mutex workers_mutex_;
  std::list<Worker> workers_;    // stable addresses; one per running task, and those an online change adds
  std::vector<Worker*> by_task_; // the current program's task i runs on by_task_[i]
  ProgramChange* change_ = nullptr;
  CpuLatencyRequest cpu_latency_;
  std::atomic<bool> stop_{false};
  std::int64_t epoch_ = 0;
  std::int64_t epoch_realtime_ = 0;  // the epoch on CLOCK_REALTIME (ns since the Unix epoch)
  mutable std::mutex warnings_mutex_;
  std::vector<std::string> warnings_;
};

}  // namespace syncplc
