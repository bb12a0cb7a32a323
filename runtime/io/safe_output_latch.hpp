// The handshake between a driver's write_outputs (the scan thread) and its
// write_safe_outputs (the supervisor, io_driver.hpp) with no lock on the scan
// path: one atomic word with a "writing" and an "engaged" bit. The scan sets
// "writing" only while "engaged" is clear (compare-and-swap); the supervisor
// sets "engaged" and learns in the same step whether a write was under way,
// and then waits for that one write only.
//
//   scan:        if (!latch.begin_write()) return;  ...write...;  latch.end_write();
//   supervisor:  if (!latch.engage(limit)) return false;  ...write the safe values...
//
// Once engage() has returned true no write_outputs is under way and none
// starts until reset() (the driver's open()), and everything the last write
// stored is visible to the supervisor's thread (release/acquire on the word).
#pragma once

#include <atomic>
#include <chrono>
#include <cstdint>
#include <thread>

namespace syncplc {

class SafeOutputLatch {
 public:
  // Scan side: false when the outputs are held in the safe state (write nothing).
  bool begin_write() noexcept {
    std::uint8_t s = state_.load(std::memory_order_relaxed);
    do {
      if (s & kEngaged) return false;
    } while (!state_.compare_exchange_weak(s, static_cast<std::uint8_t>(s | kWriting), std::memory_order_acquire,
                                           std::memory_order_relaxed));
    return true;
  }
  void end_write() noexcept { state_.fetch_and(static_cast<std::uint8_t>(~kWriting), std::memory_order_release); }

  // Supervisor side: holds the outputs, then waits up to `limit` for a write
  // that was under way to finish. False when it did not (a scan thread stuck
  // inside write_outputs): the outputs stay held, but their values are the scan's.
  bool engage(std::chrono::nanoseconds limit = std::chrono::milliseconds(100)) noexcept {
    if (!(state_.fetch_or(kEngaged, std::memory_order_acq_rel) & kWriting)) return true;
    const auto until = std::chrono::steady_clock::now() + limit;
    while (state_.load(std::memory_order_acquire) & kWriting) {
      if (std::chrono::steady_clock::now() >= until) return false;
      std::this_thread::yield();
    }
    return true;
  }
  bool engaged() const noexcept { return state_.load(std::memory_order_acquire) & kEngaged; }
  // Before the first scan of a new run (the driver's open()).
  void reset() noexcept { state_.fetch_and(static_cast<std::uint8_t>(~kEngaged), std::memory_order_acq_rel); }

 private:
  static constexpr std::uint8_t kWriting = 1, kEngaged = 2;
  std::atomic<std::uint8_t> state_{0};
};

}  // namespace syncplc
