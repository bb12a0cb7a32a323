// The clock the store's age limits are measured by (docs/store.md, "Age
// limits and the wall clock"): events_max_age, trend_raw_age, trend_max_age.
//
// Rows are stamped with the wall clock, which can step: an RTC set wrong at
// boot, a mistyped date, NTP correcting a clock that drifted. An age read off
// the wall clock alone trusts every step: one run with the clock 200 days
// ahead would delete 200 days of audit trail. So an age counts only as far
// as a clock that cannot step confirms it:
//
//   the retention clock moves with the wall clock, but never further forward
//   than the monotonic clock measured while `run` ran since it last moved;
//   it follows the wall clock back; it stands still while `run` is stopped
//   (it is kept in the database, table retention_clock, one row per job).
//
// A row goes when it is older than its limit by this clock. So no step of
// the wall clock, forward or back, deletes a row before the limit has
// passed for it in time the PLC lived through; the price is that rows are
// kept longer than the limit by the time the PLC was stopped and by a step
// back that was later undone (the count and size limits still hold).
#pragma once

#include <SQLiteCpp/Database.h>

#include <cstdint>
#include <functional>
#include <optional>
#include <string>

namespace syncplc::store {

// ns since 1970 (UTC); by default CLOCK_REALTIME (wall_now_ns(), event_log.hpp).
using WallClock = std::function<std::int64_t()>;

class RetentionClock {
 public:
  // `name`: the job's row in retention_clock ("events", "trends").
  explicit RetentionClock(std::string name) : name_(std::move(name)) {}
  // The table (schema part "retention_clock").
  static bool prepare(SQLite::Database& db, std::string* error);
  // The retention clock now, from the wall clock `wall_ns` and the monotonic
  // clock `monotonic_ns` (ns, any origin within one run); written to the
  // table, inside the caller's transaction. The first reading of a run goes
  // on from the value stored by the last run (none stored: the wall clock).
  std::int64_t now(SQLite::Database& db, std::int64_t wall_ns, std::int64_t monotonic_ns);

 private:
  std::string name_;
  std::optional<std::int64_t> last_, last_monotonic_;  // this run's last reading
};

}  // namespace syncplc::store
