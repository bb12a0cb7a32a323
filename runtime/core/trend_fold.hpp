// The historian's task side (docs/store.md, "The historian"): after its
// blocks run, a task folds the value of each trended element into the
// element's running bucket (bucket = floor(release time / rate)); when the
// bucket index changes, the finished bucket (min, max, sum, count) goes into
// a lock-free ring that the store thread drains. Every scan is counted, so a
// one-scan spike in a 1 ms task sampled at 100 ms is in its bucket's max —
// the store thread, which sees only published snapshots, could miss it.
//
// Real-time safe: fold() neither allocates nor locks; the ring is sized at
// project load to hold 4 s of buckets (trend_fold.cpp: the store thread
// drains every 100 ms, but a commit with its fsync and checkpoint on a busy
// disk can hold it up for seconds). A full ring drops the bucket and counts
// it (dropped()).
#pragma once

#include <atomic>
#include <cstdint>
#include <vector>

#include "runtime/core/iec_type.hpp"
#include "runtime/core/spsc_ring.hpp"

namespace syncplc {

// A finished bucket of one trended element.
struct TrendBucket {
  std::uint32_t series = 0;  // the historian's series number (TrendFold::add)
  std::uint32_t count = 0;   // scans folded in
  std::int64_t index = 0;    // bucket number: its start is index * rate
  double min = 0, max = 0, sum = 0;
};

class TrendFold {
 public:
  // Built by the loader, before the task runs. `cell`: the element in the
  // task's image; `rate_ns` > 0.
  void add(std::uint32_t series, std::uint32_t cell, IecType type, std::int64_t rate_ns);
  // Sizes the ring (after the last add).
  void finalize();
  bool empty() const { return elements_.empty(); }
  std::size_t size() const { return elements_.size(); }
  std::int64_t rate_of(std::size_t i) const { return elements_[i].rate_ns; }
  std::uint32_t series_of(std::size_t i) const { return elements_[i].series; }

  // The task, after its blocks ran (release_ns: the scan's planned release).
  // Non-finite values are left out of the bucket (a bucket of only such
  // scans is not stored).
  void fold(const Cell* image, std::int64_t release_ns) noexcept;

  // Once the task has stopped folding for good (a clean stop after its
  // thread was joined, or an online change after the task switched to the
  // new program): the buckets in progress go into the ring as they are, so
  // the last partial bucket is stored too. The caller becomes the ring's
  // producer: never while fold() may still run.
  void flush() noexcept;

  // The store thread.
  bool pop(TrendBucket& out) noexcept { return ring_.pop(out); }
  std::uint64_t dropped() const noexcept { return dropped_.load(std::memory_order_relaxed); }

 private:
  struct Element {
    std::uint32_t series = 0;
    std::uint32_t cell = 0;
    IecType type = IecType::LREAL;
    std::int64_t rate_ns = 1;
    TrendBucket running;  // count 0: none yet
  };
  std::vector<Element> elements_;
  SpscRing<TrendBucket> ring_;
  std::atomic<std::uint64_t> dropped_{0};
};

}  // namespace syncplc
