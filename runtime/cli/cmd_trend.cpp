// syncplc trend TAG... : the historian's points of some tags, as a table or
// CSV, from the database read-only (also while `run` writes it: WAL).
#include <SQLiteCpp/Statement.h>
#include <fmt/format.h>

#include <iostream>
#include <limits>

#include "runtime/cli/commands.hpp"
#include "runtime/cli/plc_store.hpp"
#include "runtime/cli/wall_time.hpp"
#include "runtime/store/database.hpp"

namespace syncplc::cli {
namespace {

struct Found {
  std::int64_t id;
  std::string label;
};

// A name matches a series by label ("pos[2]") or by tag (all of "pos"'s elements).
std::vector<Found> find_series(SQLite::Database& db, const std::vector<std::string>& names, std::string* error) {
  std::vector<Found> out;
  SQLite::Statement q(db, "SELECT id, label FROM trend_series WHERE label = ?1 OR tag = ?1 ORDER BY id");
  for (const auto& n : names) {
    q.reset();
    q.bind(1, n);
    bool any = false;
    while (q.executeStep()) {
      out.push_back({q.getColumn(0).getInt64(), q.getColumn(1).getString()});
      any = true;
    }
    if (any) continue;
    std::string known;
    SQLite::Statement all(db, "SELECT label FROM trend_series ORDER BY label");
    while (all.executeStep()) known += (known.empty() ? "" : ", ") + all.getColumn(0).getString();
    *error = "no trend of '" + n + "' in " + db.getFilename() + " (trended: " + (known.empty() ? "none" : known) + ")";
    return {};
  }
  return out;
}

}  // namespace

int cmd_trend(const TrendOptions& o) {
  const std::string path = o.db.empty() ? default_database_path() : o.db;
  const std::int64_t now = wall_now_ns();
  std::string err;
  std::int64_t since = std::numeric_limits<std::int64_t>::min(), until = std::numeric_limits<std::int64_t>::max();
  for (auto [text, out, name] : {std::tuple{&o.since, &since, "--since"}, std::tuple{&o.until, &until, "--until"}}) {
    if (text->empty()) continue;
    auto t = parse_when(*text, now, &err);
    if (!t) {
      std::cerr << "syncplc: " << name << ": " << err << "\n";
      return kExitInvalid;
    }
    *out = *t;
  }
  auto db = store::Database::open_read_only(path, &err);
  if (!db) {
    std::cerr << "syncplc: " << err << "\n";
    return kExitInvalid;
  }
  SQLite::Database& sql = db->sql();
  if (!sql.tableExists("trend_point")) {
    std::cerr << "syncplc: " << path << " has no trends yet (no `syncplc run` with trended tags wrote it)\n";
    return kExitInvalid;
  }
  auto series = find_series(sql, o.tags, &err);
  if (series.empty()) {
    std::cerr << "syncplc: " << err << "\n";
    return kExitInvalid;
  }
  std::string ids;
  for (const auto& s : series) ids += (ids.empty() ? "" : ",") + std::to_string(s.id);
  SQLite::Statement q(sql, "SELECT s.label, p.t, p.min, p.max, p.mean, p.count FROM trend_point p "
                           "JOIN trend_series s ON s.id = p.series WHERE p.series IN (" + ids +
                               ") AND p.t >= ? AND p.t < ? ORDER BY p.t, s.label");
  q.bind(1, since);
  q.bind(2, until);
  if (o.csv) std::cout << "time,tag,min,max,mean,count\n";
  else std::cout << fmt::format("{:<24}  {:<16} {:>14} {:>14} {:>14} {:>7}\n", "time (UTC)", "tag", "min", "max", "mean", "scans");
  while (q.executeStep()) {
    const std::string label = q.getColumn(0).getString(), when = format_wall(q.getColumn(1).getInt64());
    const double mn = q.getColumn(2).getDouble(), mx = q.getColumn(3).getDouble(), mean = q.getColumn(4).getDouble();
    const std::int64_t count = q.getColumn(5).getInt64();
    if (o.csv) std::cout << fmt::format("{},{},{},{},{},{}\n", when, label, mn, mx, mean, count);
    else std::cout << fmt::format("{:<24}  {:<16} {:>14.6g} {:>14.6g} {:>14.6g} {:>7}\n", when, label, mn, mx, mean, count);
  }
  return kExitOk;
}

}  // namespace syncplc::cli
