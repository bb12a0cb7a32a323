// The scan's "outputs handed over" signal to a driver's device threads
// (timing cycle, docs/modbus-client.md "Threads and timing"): a 32-bit
// hand-over count the scan increments, and a Linux futex on that word the
// device threads sleep on, each with an absolute CLOCK_MONOTONIC deadline
// for the fallback when no scan hands over. One word per driver.
//
// The scan side (hand_over) never waits, allocates or takes a lock: one
// atomic increment, and a FUTEX_WAKE of ONE device thread only when one
// sleeps on the word (device threads still busy with the previous burst
// cost the scan no system call). The first device thread woken wakes the
// others (relay in wait()): a wake-up costs the waker a few µs and up to
// tens under load (IPIs in a VM), and the scan pays for one, not one per
// device. Why a futex and not an eventfd per device or polling (measured by
// bench/cycle_wake.cpp, docs/benchmarks.md section 10): the wake is the
// kernel's least work to wake a thread, without an eventfd's file layer;
// polling the count with short sleeps costs the scan nothing but the device
// threads thousands of wake-ups a second, and adds up to the poll interval
// to every exchange.
//
// The futex protocol (futex(2)): a waiter counts itself in `sleepers_`
// (sequentially consistent) and then re-checks the count inside FUTEX_WAIT,
// which sleeps only while the word still holds the value it saw; the scan
// increments the count before it reads `sleepers_`, so one of the two
// always sees the other (no lost wake-up).
#pragma once

#include <linux/futex.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <atomic>
#include <climits>
#include <cstdint>
#include <ctime>

#include "runtime/core/monotonic_clock.hpp"

namespace syncplc {

class CycleSignal {
 public:
  static_assert(std::atomic<std::uint32_t>::is_always_lock_free && sizeof(std::atomic<std::uint32_t>) == 4,
                "the futex word is the atomic itself");

  // The scan (write_outputs), or any thread: one more hand-over; wakes one
  // sleeping waiter, which wakes the rest.
  void hand_over() noexcept {
    count_.fetch_add(1, std::memory_order_seq_cst);
    if (sleepers_.load(std::memory_order_seq_cst) > 0) wake(1);
  }

  std::uint32_t count() const noexcept { return count_.load(std::memory_order_acquire); }

  // A device thread: sleeps while the count is `seen` and `stop` is false,
  // until `deadline` (monotonic ns) at the latest. Returns the count then
  // (== seen: timed out or stopped). A stopper sets `stop`, then hand_over().
  std::uint32_t wait(std::uint32_t seen, std::int64_t deadline, const std::atomic<bool>& stop) noexcept {
    sleepers_.fetch_add(1, std::memory_order_seq_cst);
    while (count_.load(std::memory_order_seq_cst) == seen && !stop.load(std::memory_order_acquire)) {
      if (monotonic_ns() >= deadline) break;
      const timespec at{static_cast<time_t>(deadline / 1'000'000'000), static_cast<long>(deadline % 1'000'000'000)};
      // FUTEX_WAIT_BITSET takes an absolute CLOCK_MONOTONIC time; EAGAIN
      // (the count moved), EINTR and ETIMEDOUT all just look again.
      syscall(SYS_futex, &count_, FUTEX_WAIT_BITSET_PRIVATE, seen, &at, nullptr, FUTEX_BITSET_MATCH_ANY);
    }
    // The relay: a waiter that leaves on a new count wakes those still
    // asleep on it (off the scan's thread).
    const std::uint32_t now = count_.load(std::memory_order_seq_cst);
    if (sleepers_.fetch_sub(1, std::memory_order_seq_cst) > 1 && now != seen) wake(INT_MAX);
    return now;
  }

 private:
  void wake(int n) noexcept { syscall(SYS_futex, &count_, FUTEX_WAKE_PRIVATE, n, nullptr, nullptr, 0); }

  std::atomic<std::uint32_t> count_{0};
  std::atomic<int> sleepers_{0};
};

}  // namespace syncplc
