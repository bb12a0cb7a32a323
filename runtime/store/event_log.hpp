// The event log (docs/store.md, "The event log"): what happened to the PLC,
// kept in the table `events` by the store thread. The non-real-time threads
// (run's main thread, the Modbus server thread) hand records to an
// EventQueue; the EventLog job writes what is queued, one transaction per
// run, and keeps the table within the project's events_max_count and
// events_max_age (an age by the retention clock, retention_clock.hpp).
//
// The queue is bounded (kEventQueueCapacity records, those waiting for a
// failed transaction included): while the database refuses to write (disk
// full, read-only) records wait there and a record that finds it full is
// dropped and counted, never blocking the thread that raised it. Records
// keep the wall time they were raised at, so those written late after a
// fault are still in order of time.
#pragma once

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "runtime/store/retention_clock.hpp"
#include "runtime/store/schema.hpp"
#include "runtime/store/store_thread.hpp"

namespace syncplc::store {

inline constexpr std::size_t kEventQueueCapacity = 10'000;

struct EventRecord {
  std::int64_t wall_ns = 0;          // CLOCK_REALTIME, ns since 1970
  std::string kind;                  // "start", "reload-failed", "watchdog", "hmi-write", ...
  std::string task;                  // "" when no task is concerned
  std::optional<std::uint64_t> scan; // the task's scan count, when known
  std::string source;                // who raised it: "run", "modbus", "store", "main/PID1", ...
  std::string message;
  std::string client;                // "ip:port" of an HMI (writes, refused connections); "" otherwise
};

// Now, in CLOCK_REALTIME ns.
std::int64_t wall_now_ns();

class EventQueue {
 public:
  explicit EventQueue(std::size_t capacity = kEventQueueCapacity) : capacity_(capacity) {}
  // Called after each accepted record (StoreThread::wake): the job is due.
  void on_push(std::function<void()> f) { on_push_ = std::move(f); }
  // False (and counted in dropped()) when the queue is full. Never waits
  // longer than another push or the job's take/settle.
  bool push(EventRecord r);
  std::uint64_t dropped() const;
  // Records queued or taken but not yet committed.
  std::size_t pending() const;
  std::size_t capacity() const { return capacity_; }

  // For the job: moves every queued record to `out` (still counted pending);
  // settle(n) once n of them are committed.
  void take(std::vector<EventRecord>& out);
  void settle(std::size_t n);
  bool empty() const;

 private:
  const std::size_t capacity_;
  mutable std::mutex mutex_;
  std::vector<EventRecord> queued_;
  std::size_t in_flight_ = 0;  // taken by the job, not yet committed
  std::uint64_t dropped_ = 0;
  std::function<void()> on_push_;
};

struct EventRetention {
  std::uint64_t max_count = 100'000;
  std::int64_t max_age_ns = 90LL * 24 * 3600 * 1'000'000'000;
};

class EventLog : public StoreJob {
 public:
  // The table: rows are written with increasing id (AUTOINCREMENT: an id is
  // never reused after a deletion, so a reader follows the log by id).
  static const SchemaPart& schema();

  EventLog(EventQueue& queue, EventRetention retention);
  const char* name() const override { return "events"; }
  bool prepare(Database& db, std::string* error) override;
  std::int64_t due_ns() const override;
  void run(Database& db, std::int64_t now_ns, bool final) override;
  void switch_program(Program& next, const StoreSettings& settings) override;

  // Applies the limits now (also done by run()); `now` by the retention
  // clock (retention_clock.hpp).
  void enforce_retention(SQLite::Database& db, std::int64_t now);
  // The wall clock run() reads (a test steps it). Before the first run.
  void set_wall_clock(WallClock clock) { wall_ = std::move(clock); }

 private:
  EventQueue& queue_;
  EventRetention retention_;
  WallClock wall_;
  RetentionClock clock_{"events"};
  std::vector<EventRecord> batch_;  // taken, waiting for a commit (kept across a failed run)
  // Read by due_ns() while switch_program (under StoreThread::exclusive) may set it.
  std::atomic<std::int64_t> next_retention_ns_{0};
};

EventRetention retention_of(const StoreSettings& s);

}  // namespace syncplc::store
