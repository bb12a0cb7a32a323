// Bounded lock-free single-producer single-consumer ring. push() and pop()
// never block; a batch of pushes becomes visible to the consumer at once
// (commit), so a multi-register write is applied within one scan.
#pragma once

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <vector>

namespace syncplc {

template <class T>
class SpscRing {
 public:
  explicit SpscRing(std::size_t capacity = 0) { reset(capacity); }
  SpscRing(const SpscRing&) = delete;
  SpscRing& operator=(const SpscRing&) = delete;

  // Before any thread uses it. Capacity rounds up to a power of two.
  void reset(std::size_t capacity) {
    std::size_t c = 1;
    while (c < capacity) c <<= 1;
    buf_.assign(capacity ? c : 0, T{});
    mask_ = capacity ? c - 1 : 0;
    head_.store(0);
    tail_.store(0);
    pending_ = 0;
  }
  std::size_t capacity() const { return buf_.size(); }

  // Producer: room for n more entries (counting uncommitted ones)?
  bool has_room(std::size_t n) const noexcept {
    std::size_t tail = tail_.load(std::memory_order_relaxed) + pending_;
    return tail - head_.load(std::memory_order_acquire) + n <= buf_.size();
  }
  // Producer: stage one entry; false when full. Visible after commit().
  bool stage(const T& v) noexcept {
    if (!has_room(1)) return false;
    std::size_t tail = tail_.load(std::memory_order_relaxed) + pending_;
    buf_[tail & mask_] = v;
    ++pending_;
    return true;
  }
  void commit() noexcept {
    tail_.store(tail_.load(std::memory_order_relaxed) + pending_, std::memory_order_release);
    pending_ = 0;
  }
  void rollback() noexcept { pending_ = 0; }
  bool push(const T& v) noexcept {
    if (!stage(v)) return false;
    commit();
    return true;
  }

  // Consumer.
  bool pop(T& out) noexcept {
    std::size_t head = head_.load(std::memory_order_relaxed);
    if (head == tail_.load(std::memory_order_acquire)) return false;
    out = buf_[head & mask_];
    head_.store(head + 1, std::memory_order_release);
    return true;
  }
  std::size_t size_approx() const noexcept {
    return tail_.load(std::memory_order_acquire) - head_.load(std::memory_order_acquire);
  }

 private:
  std::vector<T> buf_;
  std::size_t mask_ = 0;
  alignas(64) std::atomic<std::size_t> head_{0};
  alignas(64) std::atomic<std::size_t> tail_{0};
  std::size_t pending_ = 0;  // producer-owned
};

}  // namespace syncplc
