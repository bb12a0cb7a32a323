#include "runtime/store/retention_clock.hpp"

#include <SQLiteCpp/Statement.h>

#include <algorithm>

#include "runtime/store/schema.hpp"

namespace syncplc::store {

bool RetentionClock::prepare(SQLite::Database& db, std::string* error) {
  static const SchemaPart part{"retention_clock",
                               {"CREATE TABLE retention_clock ("
                               " name TEXT PRIMARY KEY,"        // the job: events, trends
                               " now_ns INTEGER NOT NULL"       // its retention clock's last reading, ns since 1970
                               ")"}};
  return ensure_schema(db, part, error);
}

std::int64_t RetentionClock::now(SQLite::Database& db, std::int64_t wall_ns, std::int64_t monotonic_ns) {
  std::int64_t ahead = wall_ns;  // how far it may go: the last reading plus the time measured since
  if (last_) {
    ahead = *last_ + std::max<std::int64_t>(monotonic_ns - *last_monotonic_, 0);
  } else {
    SQLite::Statement q(db, "SELECT now_ns FROM retention_clock WHERE name = ?");
    q.bind(1, name_);
    if (q.executeStep()) ahead = q.getColumn(0).getInt64();  // the time since the last run is not known: none
  }
  const std::int64_t now = std::min(wall_ns, ahead);
  SQLite::Statement up(db, "INSERT INTO retention_clock (name, now_ns) VALUES (?, ?) "
                           "ON CONFLICT (name) DO UPDATE SET now_ns = excluded.now_ns");
  up.bind(1, name_);
  up.bind(2, now);
  up.exec();
  last_ = now;
  last_monotonic_ = monotonic_ns;
  return now;
}

}  // namespace syncplc::store
