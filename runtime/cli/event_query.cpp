#include "runtime/cli/event_query.hpp"

#include <SQLiteCpp/Statement.h>
#include <fmt/format.h>
#include <time.h>

#include <stdexcept>

#include "runtime/core/iec_type.hpp"

namespace syncplc::cli {

std::optional<std::int64_t> parse_since(const std::string& text, std::int64_t wall_now_ns, std::string* error) {
  std::string why;
  if (auto d = parse_duration_ns(text, &why); d && *d >= 0) return wall_now_ns - *d;
  for (const char* format : {"%Y-%m-%dT%H:%M:%S", "%Y-%m-%d %H:%M:%S", "%Y-%m-%dT%H:%M", "%Y-%m-%d %H:%M", "%Y-%m-%d"}) {
    std::tm tm{};
    const char* end = strptime(text.c_str(), format, &tm);
    if (!end || *end != '\0') continue;
    tm.tm_isdst = -1;  // local time, summer time as it was on that day
    const std::time_t t = std::mktime(&tm);
    if (t == static_cast<std::time_t>(-1)) break;
    return static_cast<std::int64_t>(t) * 1'000'000'000;
  }
  *error = "--since " + text + ": expected a time back from now (10m, 2h) or a local time (2026-11-25T10:00:00)";
  return std::nullopt;
}

std::vector<LoggedEvent> read_events(store::Database& db, const EventFilter& f) {
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
  q += " ORDER BY id";
  SQLite::Statement s(sql, q);
  int at = 1;
  s.bind(at++, f.after_id);
  if (f.since_ns) s.bind(at++, *f.since_ns);
  for (const auto& k : f.kinds) s.bind(at++, k);
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
  return out;
}

std::string format_logged_event(const LoggedEvent& e) {
  const std::time_t secs = static_cast<std::time_t>(e.time_ns / 1'000'000'000);
  std::tm tm{};
  localtime_r(&secs, &tm);
  char when[32];
  std::strftime(when, sizeof when, "%Y-%m-%d %H:%M:%S", &tm);
  std::string message = e.message;
  for (std::size_t at = message.find('\n'); at != std::string::npos; at = message.find('\n', at + 1))
    message.replace(at, 1, "\n    ");
  std::string line = fmt::format("{}.{:03}  {:<17} {:<10} {:>9}  {}", when, (e.time_ns / 1'000'000) % 1000, e.kind,
                                 e.task.empty() ? "-" : e.task, e.scan ? "scan " + std::to_string(*e.scan) : "-",
                                 message);
  if (!e.client.empty()) line += "  client " + e.client;
  return line;
}

}  // namespace syncplc::cli
