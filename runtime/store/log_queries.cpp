#include "runtime/store/log_queries.hpp"

#include <SQLiteCpp/Statement.h>

#include <algorithm>
#include <stdexcept>

namespace syncplc::store {

std::vector<LoggedEvent> read_events(Database& db, const EventFilter& f) {
  SQLite::Database& sql = db.sql();
  if (!sql.tableExists("events"))
    throw std::runtime_error("the database " + db.path() + " has no event log yet (no `syncplc run` has used it)");
  std::string q = "SELECT id, time_ns, kind, task, scan, source, message, client FROM events WHERE id > ?";
  if (f.since_ns) q += " AND time_ns >= ?";
  if (!f.kinds.empty()) {
    q += " AND kind IN (";
    for (std::size_t i = 0; i < f.kinds.size(); ++i) q += i ? ", ?" : "?";
    q += ")";
  }
  // The newest `limit`, handed out oldest first; or the oldest `limit`.
  const bool newest = f.limit > 0 && f.newest;
  q += newest ? " ORDER BY id DESC LIMIT ?" : f.limit > 0 ? " ORDER BY id LIMIT ?" : " ORDER BY id";
  SQLite::Statement s(sql, q);
  int at = 1;
  s.bind(at++, f.after_id);
  if (f.since_ns) s.bind(at++, *f.since_ns);
  for (const auto& k : f.kinds) s.bind(at++, k);
  if (f.limit > 0) s.bind(at++, f.limit);
  std::vector<LoggedEvent> out;
  while (s.executeStep()) {
    LoggedEvent e;
    e.id = s.getColumn(0).getInt64();
    e.time_ns = s.getColumn(1).getInt64();
    e.kind = s.getColumn(2).getString();
    e.task = s.getColumn(3).getString();  // "" for NULL
    if (!s.getColumn(4).isNull()) e.scan = s.getColumn(4).getInt64();
    e.source = s.getColumn(5).getString();
    e.message = s.getColumn(6).getString();
    e.client = s.getColumn(7).getString();
    out.push_back(std::move(e));
  }
  if (newest) std::reverse(out.begin(), out.end());
  return out;
}

std::vector<TrendSeriesRow> find_trend_series(Database& db, const std::vector<std::string>& names, std::string* error) {
  SQLite::Database& sql = db.sql();
  if (!sql.tableExists("trend_point")) {
    *error = db.path() + " has no trends yet (no `syncplc run` with trended tags wrote it)";
    return {};
  }
  std::vector<TrendSeriesRow> out;
  SQLite::Statement q(sql, "SELECT id, label, unit FROM trend_series WHERE label = ?1 OR tag = ?1 ORDER BY id");
  for (const auto& n : names) {
    q.reset();
    q.bind(1, n);
    bool any = false;
    while (q.executeStep()) {
      out.push_back({q.getColumn(0).getInt64(), q.getColumn(1).getString(), q.getColumn(2).getString()});
      any = true;
    }
    if (any) continue;
    std::string known;
    SQLite::Statement all(sql, "SELECT label FROM trend_series ORDER BY label");
    while (all.executeStep()) known += (known.empty() ? "" : ", ") + all.getColumn(0).getString();
    *error = "no trend of '" + n + "' in " + db.path() + " (trended: " + (known.empty() ? "none" : known) + ")";
    return {};
  }
  return out;
}

namespace {

std::string series_ids(const std::vector<TrendSeriesRow>& series) {
  std::string ids;
  for (const auto& s : series) ids += (ids.empty() ? "" : ",") + std::to_string(s.id);
  return ids;
}

}  // namespace

void for_each_trend_row(Database& db, const std::vector<TrendSeriesRow>& series, std::int64_t since,
                        std::int64_t until, const std::function<void(const TrendRow&)>& f) {
  if (series.empty()) return;
  SQLite::Statement q(db.sql(), "SELECT s.label, p.t, p.min, p.max, p.mean, p.count FROM trend_point p "
                                "JOIN trend_series s ON s.id = p.series WHERE p.series IN (" + series_ids(series) +
                                    ") AND p.t >= ? AND p.t < ? ORDER BY p.t, s.label");
  q.bind(1, since);
  q.bind(2, until);
  while (q.executeStep())
    f(TrendRow{q.getColumn(0).getString(), q.getColumn(1).getInt64(), q.getColumn(2).getDouble(),
               q.getColumn(3).getDouble(), q.getColumn(4).getDouble(), q.getColumn(5).getInt64()});
}

std::int64_t count_trend_rows(Database& db, const std::vector<TrendSeriesRow>& series, std::int64_t since,
                              std::int64_t until) {
  if (series.empty()) return 0;
  SQLite::Statement q(db.sql(), "SELECT COUNT(*) FROM trend_point WHERE series IN (" + series_ids(series) +
                                    ") AND t >= ? AND t < ?");
  q.bind(1, since);
  q.bind(2, until);
  return q.executeStep() ? q.getColumn(0).getInt64() : 0;
}

}  // namespace syncplc::store
