// Live values of a task's block pins for non-real-time readers (the HTTP
// server, the command line). Pins live in the task's image past the
// published tags, so nobody outside the task sees them; while someone
// monitors, the task copies its pin cells into a triple buffer at each
// publication. Monitoring is a lease counted in the task's scans, which a
// reader extends at every read: a program nobody watches pays one relaxed
// atomic load and a branch per scan, nothing else.
#pragma once

#include <atomic>
#include <cstdint>
#include <cstring>
#include <mutex>
#include <vector>

#include "runtime/core/triple_buffer.hpp"

namespace syncplc {

class PinMonitor {
 public:
  // At load: the task's pins are image[first, first + cells). Fills the
  // buffer with the image as loaded (stamped scan 0).
  void resize(std::uint32_t first, std::uint32_t cells, const Cell* image) {
    first_ = first;
    cells_ = cells;
    buffer_.resize(1 + cells);
    std::vector<Cell> entry(1 + cells);
    if (cells) std::memcpy(static_cast<void*>(entry.data() + 1), image + first, cells * sizeof(Cell));
    buffer_.fill(entry.data());
  }
  std::uint32_t first() const noexcept { return first_; }
  std::uint32_t cells() const noexcept { return cells_; }

  // Task thread, at each publication of scan `scan`: copies the pins when
  // someone monitors.
  void publish(const Cell* image, std::uint64_t scan) noexcept {
    if (scan >= until_.load(std::memory_order_relaxed)) [[likely]]
      return;
    Cell* back = buffer_.back();
    back[0].set<std::uint64_t>(scan);
    if (cells_) std::memcpy(static_cast<void*>(back + 1), image + first_, cells_ * sizeof(Cell));
    buffer_.publish();
  }

  // Readers: monitor until the task's scan count reaches `until_scan` (an
  // earlier lease is never shortened).
  void extend(std::uint64_t until_scan) noexcept {
    std::uint64_t cur = until_.load(std::memory_order_relaxed);
    while (cur < until_scan && !until_.compare_exchange_weak(cur, until_scan, std::memory_order_relaxed)) {
    }
  }
  // Readers (serialised here): copies image cells [cell, cell + n), which
  // must be pins, from the newest copy; returns the scan it was taken at.
  std::uint64_t read(std::uint32_t cell, std::uint32_t n, Cell* out) {
    std::lock_guard lock(readers_);
    const Cell* e = buffer_.acquire();
    if (n) std::memcpy(static_cast<void*>(out), e + 1 + (cell - first_), n * sizeof(Cell));
    return e[0].get<std::uint64_t>();
  }
  bool monitoring(std::uint64_t scan) const noexcept { return scan < until_.load(std::memory_order_relaxed); }

 private:
  std::uint32_t first_ = 0;
  std::uint32_t cells_ = 0;
  TripleBuffer buffer_;  // [scan | pins]
  std::atomic<std::uint64_t> until_{0};
  std::mutex readers_;   // the triple buffer has one consumer; never taken by the scan
};

}  // namespace syncplc
