// The historian (docs/store.md, "The historian"): the store job that takes
// the tasks' finished trend buckets (trend_fold.hpp) and stores them in the
// tables trend_series and trend_point.
//
//   - every 100 ms it drains the tasks' rings into a bounded queue of its own
//     (the real-time side never waits for the database);
//   - once a second (and at a clean stop) it stores the queue in one
//     transaction, each bucket that passes its series' deadband;
//   - once a minute it downsamples and trims the tables (trend_retention.hpp).
//
// No bucket is left behind: after an online change it goes on draining the
// previous program's tasks (they run until each reaches its switch) until
// tasks_ended() says they all switched, and then takes their buckets in
// progress too; at a clean stop, the served program's buckets in progress.
#pragma once

#include <atomic>
#include <cstdint>
#include <deque>
#include <optional>
#include <vector>

#include "runtime/store/retention_clock.hpp"
#include "runtime/store/store_thread.hpp"
#include "runtime/store/trend_series.hpp"

namespace syncplc::store {

class Historian final : public StoreJob {
 public:
  Historian(Program& p, const StoreSettings& s);
  const char* name() const override { return "trends"; }
  bool prepare(Database& db, std::string* error) override;
  std::int64_t due_ns() const override { return next_drain_; }
  void run(Database& db, std::int64_t now_ns, bool final) override;
  void switch_program(Program& next, const StoreSettings& settings) override;
  void tasks_ended(Program& p) override;

  // Wall time (ns since the Unix epoch) of the program's logical time 0. By
  // default taken from the program's real-time epoch at the first run; a
  // virtual-time test sets it.
  void set_time_base(std::int64_t wall_ns) { time_base_ = wall_ns; }
  // The wall clock run() reads (a test steps it). Before the first run.
  void set_wall_clock(WallClock clock) { wall_ = std::move(clock); }
  // Buckets lost so far: dropped by a full task ring or a full queue. Any thread.
  std::uint64_t lost() const { return lost_.load(std::memory_order_relaxed); }
  std::uint64_t stored() const { return stored_; }

  static constexpr std::int64_t kDrainNs = 100'000'000;
  static constexpr std::int64_t kCommitNs = 1'000'000'000;
  static constexpr std::int64_t kRetentionNs = 60'000'000'000;
  // Buckets the queue keeps while the database refuses them (further ones are lost, counted).
  static constexpr std::size_t kMaxQueued = 1'000'000;
  // Inside a long store, the rings are drained again after this many points.
  static constexpr std::size_t kDrainEvery = 8192;

 private:
  struct Queued {
    std::uint32_t series;  // index in series_
    std::int64_t rate_ns;  // the bucket's length as its program folded it (an online change may change the series')
    TrendBucket bucket;
  };
  struct Series {
    TrendSeries spec;
    std::int64_t id = 0;                // trend_series.id (0: not yet written)
    std::optional<double> last_stored;  // the mean of the last stored point (deadband)
  };
  // A program whose tasks' rings are drained: the one served, and after an
  // online change the previous one until its tasks_ended().
  struct Feed {
    Program* program = nullptr;
    std::vector<std::uint32_t> active;        // the program's fold series number -> index in series_
    std::vector<std::int64_t> rate_ns;        // the program's fold series number -> its bucket length
    std::vector<std::uint64_t> seen_dropped;  // per task: its fold's dropped() counted so far
  };
  // The program's series, by label: series_ only grows (an online change
  // adds the new labels; a queued bucket of a removed tag is still stored).
  Feed take_series(Program& p, const StoreSettings& s);
  void drain();
  void drain(Feed& f);
  void register_series(SQLite::Database& db);
  void store_queue(SQLite::Database& db);

  StoreSettings settings_;
  std::vector<Series> series_;
  Feed served_;
  std::vector<Feed> previous_;  // programs left by an online change whose tasks may still run
  std::deque<Queued> queue_;
  bool series_changed_ = true;               // series_ has entries not yet in trend_series
  std::optional<std::int64_t> time_base_;
  WallClock wall_;
  RetentionClock clock_{"trends"};
  std::int64_t next_drain_ = 0, next_commit_ = 0, next_retention_ = 0;
  std::atomic<std::uint64_t> lost_{0};
  std::uint64_t stored_ = 0;
};

}  // namespace syncplc::store
