// The scheduler in real time: one thread per task, SCHED_FIFO at the task's
// priority where permitted (otherwise a warning and normal priority), memory
// locked with mlockall, releases on absolute CLOCK_MONOTONIC deadlines with
// clock_nanosleep(TIMER_ABSTIME). All tasks share one epoch, so their grids
// keep their phase relation and never drift.
#pragma once

#include <atomic>
#include <memory>
#include <mutex>
#include <cstdint>
#include <string>
#include <thread>
#include <vector>

#include "runtime/core/cpu_latency.hpp"
#include "runtime/core/program.hpp"

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
  };
  RealtimeRunner(Program& program, Options options);
  explicit RealtimeRunner(Program& program) : RealtimeRunner(program, Options{}) {}
  ~RealtimeRunner();

  void start();
  void request_stop() { stop_.store(true, std::memory_order_release); }
  void join();
  bool running() const;
  // Warnings collected at start (no SCHED_FIFO permission, mlockall failed...).
  std::vector<std::string> warnings() const;
  std::int64_t epoch_ns() const { return epoch_; }
  // Supervision from a non-real-time thread: for each task, how long its
  // current scan has been running (0 when it is between scans). The watchdog
  // proper is evaluated when a scan ends; this is how a scan that never ends
  // is noticed (it cannot be interrupted safely, only reported).
  std::int64_t scan_running_ns(std::size_t task) const;

  static std::int64_t monotonic_ns();

 private:
  void task_thread(std::size_t index);

  Program& program_;
  Options options_;
  std::vector<std::thread> threads_;
  CpuLatencyRequest cpu_latency_;
  std::unique_ptr<std::atomic<std::int64_t>[]> scan_started_;  // per task, -1 between scans
  std::atomic<bool> stop_{false};
  std::atomic<int> alive_{0};
  std::int64_t epoch_ = 0;
  mutable std::mutex warnings_mutex_;
  std::vector<std::string> warnings_;
};

}  // namespace syncplc
