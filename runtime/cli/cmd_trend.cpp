// syncplc trend TAG... : the historian's points of some tags, as a table or
// CSV, from the database read-only (also while `run` writes it: WAL).
#include <fmt/format.h>

#include <iostream>
#include <limits>

#include "runtime/cli/commands.hpp"
#include "runtime/plc/store_link.hpp"
#include "runtime/cli/wall_time.hpp"
#include "runtime/store/log_queries.hpp"

namespace syncplc::cli {
using namespace plc;  // the PLC instance's database paths and stored versions (runtime/plc)


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
  auto series = store::find_trend_series(*db, o.tags, &err);
  if (series.empty()) {
    std::cerr << "syncplc: " << err << "\n";
    return kExitInvalid;
  }
  if (o.csv) std::cout << "time,tag,min,max,mean,count\n";
  else std::cout << fmt::format("{:<24}  {:<16} {:>14} {:>14} {:>14} {:>7}\n", "time (UTC)", "tag", "min", "max", "mean", "scans");
  store::for_each_trend_row(*db, series, since, until, [&](const store::TrendRow& p) {
    const std::string when = format_wall(p.t_ns);
    if (o.csv) std::cout << fmt::format("{},{},{},{},{},{}\n", when, p.label, p.min, p.max, p.mean, p.count);
    else std::cout << fmt::format("{:<24}  {:<16} {:>14.6g} {:>14.6g} {:>14.6g} {:>7}\n", when, p.label, p.min, p.max, p.mean, p.count);
  });
  return kExitOk;
}

}  // namespace syncplc::cli
