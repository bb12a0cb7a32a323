// A task's published tags, as other tasks and other threads see them.
//
// Logical-execution-time (LET) semantics: the outputs of a scan released at
// t_k become visible at the logical instant t_k + period (the task's next
// grid point), never when the CPU happens to finish. A consumer whose scan is
// released at t reads, from each producer, the newest publication whose
// visible instant is <= t. Both schedulers give the same values scan by scan,
// whatever the execution times and the number of CPUs, as long as no producer
// overruns (a scan that ends after its visible instant is published late, and
// the consumers that start in between read the one before; the overrun is
// counted). docs/user-guide.md, "Task timing", has the timeline.
//
// At a consumer's release t, the producer has published at most one scan
// whose visible instant is after t (the one released in (t - period, t]; a
// later one cannot have been released yet). So every publication carries the
// one before it, and the consumer picks between the two: one wait-free triple
// buffer per consumer, no seqlock, nothing a preempted producer can hold up.
//
// Entry layout in the triple buffer: [stamp | cells][stamp | cells] (newest
// first, then the one before it). The external channel (status, Modbus) keeps
// only the newest.
#pragma once

#include <cstdint>
#include <cstring>
#include <limits>
#include <vector>

#include "runtime/core/triple_buffer.hpp"

namespace syncplc {

// What a publication says about itself: which scan, released when, visible when.
struct SnapshotStamp {
  std::uint64_t scan = 0;        // scans of the producer so far (1 = its first scan)
  std::int64_t release_ns = 0;   // planned release of that scan (logical time)
  std::int64_t visible_ns = std::numeric_limits<std::int64_t>::min();  // LET instant; min: before any scan
};

class SnapshotChannel {
 public:
  static constexpr std::size_t kStampCells = 3;

  // history: keep the publication before the newest (consumer tasks need it).
  explicit SnapshotChannel(bool history = true) : history_(history) {}

  // Sized at project load, before any thread uses it.
  void resize(std::size_t cells) {
    cells_ = cells;
    buffer_.resize(parts() * (kStampCells + cells));
    last_.assign(kStampCells + cells, Cell{});
    write_stamp(last_.data(), SnapshotStamp{});
  }
  std::size_t size() const { return cells_; }

  // Producer side (the task's thread): one publication.
  void publish(const Cell* src, const SnapshotStamp& s) noexcept {
    Cell* back = buffer_.back();
    write_stamp(back, s);
    if (cells_) std::memcpy(static_cast<void*>(back + kStampCells), src, cells_ * sizeof(Cell));
    if (history_) {
      std::memcpy(static_cast<void*>(back + kStampCells + cells_), last_.data(), (kStampCells + cells_) * sizeof(Cell));
      std::memcpy(static_cast<void*>(last_.data()), back, (kStampCells + cells_) * sizeof(Cell));
    }
    buffer_.publish();
  }

  // Before any thread runs (or from the one thread that publishes): make the
  // channel hold `src` as if published with stamp `s`, the one before it too.
  void fill(const Cell* src, const SnapshotStamp& s = SnapshotStamp{}) {
    std::vector<Cell> entry(parts() * (kStampCells + cells_));
    for (std::size_t p = 0; p < parts(); ++p) {
      Cell* e = entry.data() + p * (kStampCells + cells_);
      write_stamp(e, s);
      if (cells_) std::memcpy(static_cast<void*>(e + kStampCells), src, cells_ * sizeof(Cell));
    }
    std::memcpy(static_cast<void*>(last_.data()), entry.data(), (kStampCells + cells_) * sizeof(Cell));
    buffer_.fill(entry.data());
  }

  // Consumer side (one consumer per channel). The values a scan released at
  // t reads: the newest publication visible at t. *late is set when even the
  // one before it is not visible yet (the consumer started more than a
  // producer period late): the older is returned.
  const Cell* read_at(std::int64_t t, bool* late = nullptr) noexcept {
    const Cell* e = buffer_.acquire();
    if (!history_ || stamp_of(e).visible_ns <= t) return e + kStampCells;
    const Cell* prev = e + kStampCells + cells_;
    if (late) *late = stamp_of(prev).visible_ns > t;
    return prev + kStampCells;
  }
  // The newest publication, whatever its visible instant (status, Modbus).
  const Cell* latest(SnapshotStamp* s = nullptr) noexcept {
    const Cell* e = buffer_.acquire();
    if (s) *s = stamp_of(e);
    return e + kStampCells;
  }

 private:
  std::size_t parts() const { return history_ ? 2 : 1; }
  static void write_stamp(Cell* c, const SnapshotStamp& s) noexcept {
    c[0].set<std::uint64_t>(s.scan);
    c[1].set<std::int64_t>(s.release_ns);
    c[2].set<std::int64_t>(s.visible_ns);
  }
  static SnapshotStamp stamp_of(const Cell* c) noexcept {
    return SnapshotStamp{c[0].get<std::uint64_t>(), c[1].get<std::int64_t>(), c[2].get<std::int64_t>()};
  }

  bool history_;
  std::size_t cells_ = 0;
  TripleBuffer buffer_;
  std::vector<Cell> last_;  // producer-owned: the previous publication, stamp first
};

}  // namespace syncplc
