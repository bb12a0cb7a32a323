#include "runtime/core/trend_fold.hpp"

#include <algorithm>
#include <cmath>

namespace syncplc {
namespace {

// How long a ring holds the buckets of its elements: the store thread drains
// every 100 ms; a commit (WAL fsync, checkpoint) on a loaded machine was seen
// to hold it up past 1.3 s (docs/benchmarks.md, "The historian").
constexpr std::int64_t kRingSpanNs = 4'000'000'000;

}  // namespace

void TrendFold::add(std::uint32_t series, std::uint32_t cell, IecType type, std::int64_t rate_ns) {
  Element e;
  e.series = series;
  e.cell = cell;
  e.type = type;
  e.rate_ns = std::max<std::int64_t>(rate_ns, 1);
  e.running.series = series;
  elements_.push_back(e);
}

void TrendFold::finalize() {
  std::size_t capacity = 0;
  for (const auto& e : elements_) capacity += static_cast<std::size_t>(kRingSpanNs / e.rate_ns) + 2;
  ring_.reset(capacity);
}

void TrendFold::fold(const Cell* image, std::int64_t release_ns) noexcept {
  for (auto& e : elements_) {
    const double v = cell_as_double(e.type, image[e.cell]);
    const std::int64_t index = release_ns / e.rate_ns;  // release times are >= 0
    TrendBucket& b = e.running;
    if (b.count != 0 && b.index != index) {
      if (!ring_.push(b)) dropped_.fetch_add(1, std::memory_order_relaxed);
      b.count = 0;
    }
    if (!std::isfinite(v)) continue;
    if (b.count == 0) {
      b.index = index;
      b.min = b.max = b.sum = v;
      b.count = 1;
    } else {
      b.min = std::min(b.min, v);
      b.max = std::max(b.max, v);
      b.sum += v;
      ++b.count;
    }
  }
}

void TrendFold::flush() noexcept {
  for (auto& e : elements_) {
    if (e.running.count == 0) continue;
    if (!ring_.push(e.running)) dropped_.fetch_add(1, std::memory_order_relaxed);
    e.running.count = 0;
  }
}

}  // namespace syncplc
