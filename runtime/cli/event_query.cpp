#include "runtime/cli/event_query.hpp"

#include <fmt/format.h>
#include <time.h>


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
