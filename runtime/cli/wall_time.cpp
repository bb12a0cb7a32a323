#include "runtime/cli/wall_time.hpp"

#include <cctype>
#include <cstdio>
#include <ctime>
#include <limits>

#include <fmt/format.h>

#include "runtime/core/iec_type.hpp"

namespace syncplc::cli {

std::int64_t wall_now_ns() {
  timespec ts{};
  clock_gettime(CLOCK_REALTIME, &ts);
  return static_cast<std::int64_t>(ts.tv_sec) * 1'000'000'000 + ts.tv_nsec;
}

std::optional<std::int64_t> parse_when(const std::string& text, std::int64_t now_ns, std::string* error) {
  if (text == "now") return now_ns;
  std::tm tm{};
  int frac_start = 0;
  int y = 0, mo = 0, d = 0, h = 0, mi = 0, s = 0, n = 0;
  char sep = 0;
  if (std::sscanf(text.c_str(), "%4d-%2d-%2d%c%2d:%2d:%2d%n", &y, &mo, &d, &sep, &h, &mi, &s, &n) == 7 &&
      (sep == 'T' || sep == ' ')) {
    frac_start = n;
  } else if (std::sscanf(text.c_str(), "%4d-%2d-%2d%n", &y, &mo, &d, &n) == 3 && static_cast<std::size_t>(n) == text.size()) {
    frac_start = n;
  } else {
    std::string err;
    if (auto ago = parse_duration_ns(text, &err); ago && *ago >= 0) return now_ns - *ago;
    *error = "'" + text + "' is not a time (write 2026-11-25T04:00:00Z, 2026-11-25, now, or a duration ago such as 10m)";
    return std::nullopt;
  }
  std::int64_t frac = 0;
  std::size_t i = static_cast<std::size_t>(frac_start);
  if (i < text.size() && text[i] == '.') {
    std::int64_t scale = 100'000'000;
    for (++i; i < text.size() && std::isdigit(static_cast<unsigned char>(text[i])); ++i, scale /= 10)
      frac += (text[i] - '0') * scale;
  }
  if (i < text.size() && text[i] == 'Z') ++i;
  if (i != text.size() || mo < 1 || mo > 12 || d < 1 || d > 31 || h > 23 || mi > 59 || s > 60) {
    *error = "'" + text + "' is not a time (write 2026-11-25T04:00:00Z, 2026-11-25, now, or a duration ago such as 10m)";
    return std::nullopt;
  }
  tm.tm_year = y - 1900;
  tm.tm_mon = mo - 1;
  tm.tm_mday = d;
  tm.tm_hour = h;
  tm.tm_min = mi;
  tm.tm_sec = s;
  // ns since 1970 end in 2262: a later time is "after every point".
  const std::int64_t sec = static_cast<std::int64_t>(timegm(&tm));
  constexpr std::int64_t kMaxSec = std::numeric_limits<std::int64_t>::max() / 1'000'000'000 - 1;
  if (sec > kMaxSec) return std::numeric_limits<std::int64_t>::max();
  if (sec < -kMaxSec) return std::numeric_limits<std::int64_t>::min();
  return sec * 1'000'000'000 + frac;
}

std::string format_wall(std::int64_t ns) {
  const std::int64_t sec = ns >= 0 ? ns / 1'000'000'000 : (ns - 999'999'999) / 1'000'000'000;
  const std::int64_t ms = (ns - sec * 1'000'000'000) / 1'000'000;
  const std::time_t t = static_cast<std::time_t>(sec);
  std::tm tm{};
  gmtime_r(&t, &tm);
  return fmt::format("{:04}-{:02}-{:02}T{:02}:{:02}:{:02}.{:03}Z", tm.tm_year + 1900, tm.tm_mon + 1, tm.tm_mday,
                     tm.tm_hour, tm.tm_min, tm.tm_sec, ms);
}

}  // namespace syncplc::cli
