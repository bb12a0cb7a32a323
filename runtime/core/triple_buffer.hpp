// Wait-free single-producer single-consumer snapshot channel (triple buffer).
// The producer (a task publishing its tags at the end of a scan) never waits
// for the consumer and vice versa; the consumer always gets a whole,
// consistent publication: a value spanning several cells is never torn.
#pragma once

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <vector>

#include "runtime/core/iec_type.hpp"

namespace syncplc {

class TripleBuffer {
 public:
  explicit TripleBuffer(std::size_t cells = 0) { resize(cells); }
  TripleBuffer(const TripleBuffer&) = delete;
  TripleBuffer& operator=(const TripleBuffer&) = delete;

  // Sized at project load, before any thread uses it.
  void resize(std::size_t cells) {
    cells_ = cells;
    storage_.assign(3 * cells, Cell{});
  }
  std::size_t size() const { return cells_; }

  // Producer side.
  Cell* back() noexcept { return storage_.data() + back_ * cells_; }
  void publish() noexcept {
    // Hand the filled back buffer over and take the old middle one.
    std::uint8_t old = middle_.exchange(static_cast<std::uint8_t>(back_ | kFresh), std::memory_order_acq_rel);
    back_ = old & kIndex;
  }
  void publish(const Cell* src) noexcept {
    if (cells_) std::memcpy(static_cast<void*>(back()), src, cells_ * sizeof(Cell));
    publish();
  }

  // Consumer side: takes the newest publication if there is one, then returns
  // the consumer's buffer (stable until the next acquire()).
  const Cell* acquire() noexcept {
    if (middle_.load(std::memory_order_relaxed) & kFresh) {
      std::uint8_t old = middle_.exchange(front_, std::memory_order_acq_rel);
      front_ = old & kIndex;
    }
    return storage_.data() + front_ * cells_;
  }
  const Cell* front() const noexcept { return storage_.data() + front_ * cells_; }

  // Before the threads start: make every buffer hold `src`.
  void fill(const Cell* src) {
    if (cells_ == 0) return;  // a task that owns no tags publishes nothing
    for (std::size_t b = 0; b < 3; ++b) std::memcpy(static_cast<void*>(storage_.data() + b * cells_), src, cells_ * sizeof(Cell));
  }

 private:
  static constexpr std::uint8_t kIndex = 3;
  static constexpr std::uint8_t kFresh = 4;
  std::vector<Cell> storage_;
  std::size_t cells_ = 0;
  std::uint8_t back_ = 0;                 // producer-owned
  std::uint8_t front_ = 2;                // consumer-owned
  std::atomic<std::uint8_t> middle_{1};   // shared
};

}  // namespace syncplc
