// Reading the event log and the historian (docs/store.md) on a read-only
// connection, also while `syncplc run` writes the database (WAL): one place
// for `syncplc events`, `syncplc trend` and the HTTP API.
#pragma once

#include <cstdint>
#include <functional>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "runtime/store/database.hpp"

namespace syncplc::store {

struct LoggedEvent {
  std::int64_t id = 0;
  std::int64_t time_ns = 0;
  std::string kind, task, source, message, client;
  std::optional<std::int64_t> scan;
};

struct EventFilter {
  std::int64_t after_id = 0;             // only ids above this
  std::optional<std::int64_t> since_ns;  // wall time
  std::vector<std::string> kinds;        // empty: every kind
  std::int64_t limit = 0;                // > 0: at most `limit` of them,
  bool newest = true;                    // the newest (else the oldest, to page forward from after_id)
};

// The events the filter selects, oldest first. Throws SQLite::Exception; a
// database without an event log gives a clear std::runtime_error.
std::vector<LoggedEvent> read_events(Database& db, const EventFilter& f);

struct TrendRow {
  std::string label;  // the series: "speed", "pos[2]"
  std::int64_t t_ns = 0;
  double min = 0, max = 0, mean = 0;
  std::int64_t count = 0;
};

// The series that `names` select: each by label ("pos[2]") or by tag (all of
// "pos"'s elements), in id order. Empty with `error` naming the trended tags
// when a name selects none, or when the database has no trends.
struct TrendSeriesRow {
  std::int64_t id = 0;
  std::string label, unit;
};
std::vector<TrendSeriesRow> find_trend_series(Database& db, const std::vector<std::string>& names, std::string* error);
// Their points with since <= t < until, by time then label, one row at a
// time, never all in memory (a day of a 1 ms trend is 86 million rows);
// and how many there are.
void for_each_trend_row(Database& db, const std::vector<TrendSeriesRow>& series, std::int64_t since,
                        std::int64_t until, const std::function<void(const TrendRow&)>& f);
std::int64_t count_trend_rows(Database& db, const std::vector<TrendSeriesRow>& series, std::int64_t since,
                              std::int64_t until);

}  // namespace syncplc::store
