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
  // Each copy: [scan | release_ns | pins].
  static constexpr std::uint32_t kStampCells = 2;

  // At load: the task's pins are image[first, first + cells). Fills the
  // buffer with the image as loaded (stamped scan 0, release 0).
  void resize(std::uint32_t first, std::uint32_t cells, const Cell* image) {
    first_ = first;
    cells_ = cells;
    buffer_.resize(kStampCells + cells);
    std::vector<Cell> entry(kStampCells + cells);
    entry[0].set<std::uint64_t>(0);
    entry[1].set<std::int64_t>(0);
    if (cells) std::memcpy(static_cast<void*>(entry.data() + kStampCells), image + first, cells * sizeof(Cell));
    buffer_.fill(entry.data());
  }
  std::uint32_t first() const noexcept { return first_; }
  std::uint32_t cells() const noexcept { return cells_; }

  // Task thread, at each publication of scan `scan` (planned release at
  // logical time release_ns): copies the pins when someone monitors.
  void publish(const Cell* image, std::uint64_t scan, std::int64_t release_ns) noexcept {
    if (scan >= until_.load(std::memory_order_relaxed)) [[likely]]
      return;
    Cell* back = buffer_.back();
    back[0].set<std::uint64_t>(scan);
    back[1].set<std::int64_t>(release_ns);
    if (cells_) std::memcpy(static_cast<void*>(back + kStampCells), image + first_, cells_ * sizeof(Cell));
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
  // must be pins, from the newest copy; returns the scan it was taken at
  // and that scan's planned release (*release_ns, when given).
  std::uint64_t read(std::uint32_t cell, std::uint32_t n, Cell* out, std::int64_t* release_ns = nullptr) {
    std::lock_guard lock(readers_);
    const Cell* e = buffer_.acquire();
    if (n) std::memcpy(static_cast<void*>(out), e + kStampCells + (cell - first_), n * sizeof(Cell));
    if (release_ns) *release_ns = e[1].get<std::int64_t>();
    return e[0].get<std::uint64_t>();
  }
  bool monitoring(std::uint64_t scan) const noexcept { return scan < until_.load(std::memory_order_relaxed); }

 private:
  std::uint32_t first_ = 0;
  std::uint32_t cells_ = 0;
  TripleBuffer buffer_;  // [scan | release_ns | pins]
  std::atomic<std::uint64_t> until_{0};
  std::mutex readers_;   // the triple buffer has one consumer; never taken by the scan
};

}  // namespace syncplc
