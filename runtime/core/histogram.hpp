// Lock-free log-linear histogram of non-negative nanosecond values (like
// HdrHistogram with 32 sub-buckets per power of two: a reported percentile is
// within 1/32 of the true value). One writer (the task), any number of
// readers; all fields are relaxed atomics, so a reader may see a snapshot that
// is a few samples behind, never a torn one.
#pragma once

#include <algorithm>
#include <array>
#include <atomic>
#include <cstdint>
#include <limits>

namespace syncplc {

class Histogram {
 public:
  static constexpr int kSubBits = 5;
  static constexpr int kSub = 1 << kSubBits;
  static constexpr int kBuckets = (64 - kSubBits + 1) * kSub;

  void record(std::int64_t v) noexcept {
    std::uint64_t u = v < 0 ? 0 : static_cast<std::uint64_t>(v);
    buckets_[index(u)].fetch_add(1, std::memory_order_relaxed);
    count_.fetch_add(1, std::memory_order_relaxed);
    sum_.fetch_add(v, std::memory_order_relaxed);
    if (v < min_.load(std::memory_order_relaxed)) min_.store(v, std::memory_order_relaxed);
    if (v > max_.load(std::memory_order_relaxed)) max_.store(v, std::memory_order_relaxed);
  }

  struct Summary {
    std::uint64_t count = 0;
    std::int64_t min = 0, max = 0, p50 = 0, p99 = 0;
    double mean = 0;
  };

  Summary summary() const noexcept {
    Summary s;
    std::array<std::uint64_t, kBuckets> b;
    std::uint64_t n = 0;
    for (int i = 0; i < kBuckets; ++i) n += (b[i] = buckets_[i].load(std::memory_order_relaxed));
    if (n == 0) return s;
    s.count = n;
    s.min = min_.load(std::memory_order_relaxed);
    s.max = max_.load(std::memory_order_relaxed);
    s.mean = static_cast<double>(sum_.load(std::memory_order_relaxed)) /
             static_cast<double>(count_.load(std::memory_order_relaxed));
    s.p50 = percentile(b, n, 0.50, s.min, s.max);
    s.p99 = percentile(b, n, 0.99, s.min, s.max);
    return s;
  }

  void reset() noexcept {
    for (auto& x : buckets_) x.store(0, std::memory_order_relaxed);
    count_.store(0, std::memory_order_relaxed);
    sum_.store(0, std::memory_order_relaxed);
    min_.store(std::numeric_limits<std::int64_t>::max(), std::memory_order_relaxed);
    max_.store(std::numeric_limits<std::int64_t>::min(), std::memory_order_relaxed);
  }

  // Takes over another histogram's counts (online change: the new task's
  // statistics go on from the old one's). Call before this one records.
  void continue_from(const Histogram& o) noexcept {
    for (int i = 0; i < kBuckets; ++i) buckets_[i].store(o.buckets_[i].load(std::memory_order_relaxed), std::memory_order_relaxed);
    count_.store(o.count_.load(std::memory_order_relaxed), std::memory_order_relaxed);
    sum_.store(o.sum_.load(std::memory_order_relaxed), std::memory_order_relaxed);
    min_.store(o.min_.load(std::memory_order_relaxed), std::memory_order_relaxed);
    max_.store(o.max_.load(std::memory_order_relaxed), std::memory_order_relaxed);
  }

  // Bucket i's count (readers that draw the distribution: the HTTP API).
  std::uint64_t bucket(int i) const noexcept { return buckets_[i].load(std::memory_order_relaxed); }

  static int index(std::uint64_t u) noexcept {
    if (u < kSub) return static_cast<int>(u);
    int msb = 63 - __builtin_clzll(u);
    int shift = msb - kSubBits;
    return (shift + 1) * kSub + static_cast<int>((u >> shift) & (kSub - 1));
  }
  // Largest value that falls in bucket i.
  static std::uint64_t upper(int i) noexcept {
    if (i < kSub) return static_cast<std::uint64_t>(i);
    int shift = i / kSub - 1;
    std::uint64_t lo = (static_cast<std::uint64_t>(kSub + i % kSub)) << shift;
    return lo + ((std::uint64_t{1} << shift) - 1);
  }

 private:
  static std::int64_t percentile(const std::array<std::uint64_t, kBuckets>& b, std::uint64_t n, double q,
                                 std::int64_t lo, std::int64_t hi) noexcept {
    auto rank = static_cast<std::uint64_t>(q * static_cast<double>(n));
    if (rank >= n) rank = n - 1;
    std::uint64_t acc = 0;
    for (int i = 0; i < kBuckets; ++i) {
      acc += b[i];
      if (acc > rank) {
        auto v = static_cast<std::int64_t>(std::min<std::uint64_t>(upper(i), static_cast<std::uint64_t>(INT64_MAX)));
        return std::clamp(v, std::max<std::int64_t>(lo, 0), hi);
      }
    }
    return hi;
  }

  std::array<std::atomic<std::uint64_t>, kBuckets> buckets_{};
  std::atomic<std::uint64_t> count_{0};
  std::atomic<std::int64_t> sum_{0};
  std::atomic<std::int64_t> min_{std::numeric_limits<std::int64_t>::max()};
  std::atomic<std::int64_t> max_{std::numeric_limits<std::int64_t>::min()};
};

}  // namespace syncplc
