// What a subscription keeps of the samples it receives (docs/dds.md,
// "Quality: age, loss, reactions"), on the real link's receive thread and
// the virtual link's scan alike: a sample newer than the last one taken is
// handed over to the scan (SubscriptionCells layout) and the gap in the
// publisher's scan count before it is counted lost; an older one is late and
// dropped; another writer (the publishing node restarted, its scan count
// starting again) starts the count afresh.
#pragma once

#include <cstdint>

#include "runtime/core/triple_buffer.hpp"
#include "runtime/io/dds/subscription_latch.hpp"

namespace syncplc::dds {

struct IntakeCounters {
  std::uint64_t lost = 0, late = 0, writers_changed = 0;  // what accept added (the caller sums them)
};

class SubscriptionIntake {
 public:
  // Takes one sample of `writer` (values: `count` doubles) into `out`.
  // Returns what it added to the counters.
  IntakeCounters accept(TripleBuffer& out, std::uint64_t writer, std::uint64_t scan, std::int64_t started,
                        const double* values, std::uint32_t count) noexcept {
    IntakeCounters added;
    if (have_ && writer != writer_) {
      ++added.writers_changed;
      have_ = false;
    }
    if (have_ && scan <= last_) {
      ++late_;
      ++added.late;
      return added;
    }
    if (have_ && scan > last_ + 1) {
      lost_ += scan - last_ - 1;
      added.lost = scan - last_ - 1;
    }
    writer_ = writer;
    have_ = true;
    last_ = scan;
    ++received_;
    Cell* b = out.back();
    b[SubscriptionCells::kReceived].set<std::uint64_t>(received_);
    b[SubscriptionCells::kScan].set<std::uint64_t>(scan);
    b[SubscriptionCells::kStarted].set<std::int64_t>(started);
    b[SubscriptionCells::kLost].set<std::uint64_t>(lost_);
    b[SubscriptionCells::kLate].set<std::uint64_t>(late_);
    for (std::uint32_t v = 0; v < count; ++v) b[SubscriptionCells::kValues + v].set<double>(values[v]);
    out.publish();
    return added;
  }
  std::uint64_t received() const { return received_; }

 private:
  std::uint64_t writer_ = 0;
  bool have_ = false;
  std::uint64_t last_ = 0, received_ = 0, lost_ = 0, late_ = 0;
};

}  // namespace syncplc::dds
