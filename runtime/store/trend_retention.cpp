#include "runtime/store/trend_retention.hpp"

#include <SQLiteCpp/Statement.h>
#include <SQLiteCpp/Transaction.h>

#include <algorithm>
#include <vector>

#include "runtime/store/schema.hpp"

namespace syncplc::store {

bool ensure_trend_schema(SQLite::Database& db, std::string* error) {
  // A series is a trended tag's element, known by its label across project
  // changes. A point is one bucket: t its start (ns since the Unix epoch,
  // UTC), span its length; level 0 raw, 1 downsampled. The HMI's trend view
  // reads a series' range through the primary key.
  static const SchemaPart part{"trends",
                               {"CREATE TABLE trend_series ("
                                "  id INTEGER PRIMARY KEY,"
                                "  label TEXT NOT NULL UNIQUE,"
                                "  tag TEXT NOT NULL,"
                                "  element INTEGER NOT NULL,"
                                "  type TEXT NOT NULL,"
                                "  unit TEXT NOT NULL,"
                                "  rate_ns INTEGER NOT NULL,"
                                "  deadband REAL NOT NULL);"
                                "CREATE TABLE trend_point ("
                                "  series INTEGER NOT NULL REFERENCES trend_series (id),"
                                "  level INTEGER NOT NULL,"
                                "  t INTEGER NOT NULL,"
                                "  span INTEGER NOT NULL,"
                                "  min REAL NOT NULL,"
                                "  max REAL NOT NULL,"
                                "  mean REAL NOT NULL,"
                                "  count INTEGER NOT NULL,"
                                "  PRIMARY KEY (series, level, t)) WITHOUT ROWID;"}};
  return ensure_schema(db, part, error);
}

std::uint64_t database_used_bytes(SQLite::Database& db) {
  const std::int64_t pages = db.execAndGet("PRAGMA page_count").getInt64();
  const std::int64_t free = db.execAndGet("PRAGMA freelist_count").getInt64();
  const std::int64_t size = db.execAndGet("PRAGMA page_size").getInt64();
  return static_cast<std::uint64_t>((pages - free) * size);
}

namespace {

// Every step goes series by series through the primary key (series, level,
// t): no index on t to keep up at each insert, no scan of the whole table.
std::vector<std::int64_t> series_ids(SQLite::Database& db) {
  std::vector<std::int64_t> ids;
  SQLite::Statement q(db, "SELECT id FROM trend_series ORDER BY id");
  while (q.executeStep()) ids.push_back(q.getColumn(0).getInt64());
  return ids;
}

// Whole downsample buckets older than the raw age: a level-1 bucket never
// overlaps raw points still kept.
std::uint64_t downsample(SQLite::Database& db, const StoreSettings& s, std::int64_t now) {
  const std::int64_t d = s.trend_downsample_ns;
  std::int64_t cutoff = now - s.trend_raw_age_ns;
  cutoff -= ((cutoff % d) + d) % d;
  SQLite::Transaction tr(db);
  SQLite::Statement fold(db,
                         "INSERT INTO trend_point (series, level, t, span, min, max, mean, count) "
                         "SELECT series, 1, (t / :d) * :d, :d, min(min), max(max), sum(mean * count) / sum(count), sum(count) "
                         "FROM trend_point WHERE series = :s AND level = 0 AND t < :cutoff GROUP BY t / :d "
                         "ON CONFLICT (series, level, t) DO UPDATE SET "
                         "min = min(min, excluded.min), max = max(max, excluded.max), "
                         "mean = (mean * count + excluded.mean * excluded.count) / (count + excluded.count), "
                         "count = count + excluded.count");
  SQLite::Statement del(db, "DELETE FROM trend_point WHERE series = ? AND level = 0 AND t < ?");
  std::uint64_t n = 0;
  for (std::int64_t id : series_ids(db)) {
    fold.reset();
    fold.bind(":d", d);
    fold.bind(":s", id);
    fold.bind(":cutoff", cutoff);
    fold.exec();
    del.reset();
    del.bind(1, id);
    del.bind(2, cutoff);
    n += static_cast<std::uint64_t>(del.exec());
  }
  tr.commit();
  return n;
}

// Deletes, in every series and level, the points older than `before`.
std::uint64_t delete_before(SQLite::Database& db, std::int64_t before) {
  SQLite::Transaction tr(db);
  SQLite::Statement del(db, "DELETE FROM trend_point WHERE series = ? AND level = ? AND t < ?");
  std::uint64_t n = 0;
  for (std::int64_t id : series_ids(db))
    for (int level = 0; level <= 1; ++level) {
      del.reset();
      del.bind(1, id);
      del.bind(2, level);
      del.bind(3, before);
      n += static_cast<std::uint64_t>(del.exec());
    }
  tr.commit();
  return n;
}

// The oldest points, a twentieth of the stored time span at a time, until
// the database fits. Freed pages are reused by later points (the file does
// not shrink).
std::uint64_t trim(SQLite::Database& db, const StoreSettings& s) {
  std::uint64_t deleted = 0;
  while (database_used_bytes(db) > s.trend_max_bytes) {
    // Each series' first and last point through its key, not a scan.
    SQLite::Statement span(db,
                           "SELECT min(lo), max(hi) FROM (SELECT "
                           "(SELECT min(t) FROM trend_point WHERE series = s.id AND level = l.level) AS lo, "
                           "(SELECT max(t) FROM trend_point WHERE series = s.id AND level = l.level) AS hi "
                           "FROM trend_series s, (SELECT 0 AS level UNION ALL SELECT 1) l)");
    if (!span.executeStep() || span.getColumn(0).isNull()) break;  // no points left
    const std::int64_t lo = span.getColumn(0).getInt64(), hi = span.getColumn(1).getInt64();
    deleted += delete_before(db, lo + std::max<std::int64_t>((hi - lo) / 20, 1));
  }
  return deleted;
}

}  // namespace

RetentionReport apply_trend_retention(SQLite::Database& db, const StoreSettings& s, std::int64_t now_ns) {
  RetentionReport r;
  r.downsampled = downsample(db, s, now_ns);
  r.expired = delete_before(db, now_ns - s.trend_max_age_ns);
  r.trimmed = trim(db, s);
  return r;
}

}  // namespace syncplc::store
