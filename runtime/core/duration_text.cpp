// Durations as text (duration_text.hpp).
#include "runtime/core/duration_text.hpp"

#include <charconv>
#include <cmath>
#include <cstring>
#include <limits>

namespace syncplc {

namespace {

bool blank(char c) noexcept { return c == ' ' || c == '\t' || c == '\n' || c == '\v' || c == '\f' || c == '\r'; }
bool digit(char c) noexcept { return c >= '0' && c <= '9'; }
bool letter(char c) noexcept { return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z'); }
char lower(char c) noexcept { return c >= 'A' && c <= 'Z' ? static_cast<char>(c - 'A' + 'a') : c; }

bool starts_with_ci(std::string_view s, std::string_view prefix) noexcept {
  if (s.size() < prefix.size()) return false;
  for (std::size_t i = 0; i < prefix.size(); ++i)
    if (lower(s[i]) != lower(prefix[i])) return false;
  return true;
}

// Nanoseconds per unit and its rank (largest first), or rank -1.
struct UnitScale {
  long double ns;
  int rank;
};

UnitScale unit_scale(std::string_view u) noexcept {
  char l[4] = {};
  if (u.size() > 3) return {0, -1};
  for (std::size_t i = 0; i < u.size(); ++i) l[i] = lower(u[i]);
  const std::string_view n(l, u.size());
  if (n == "d") return {86400e9L, 6};
  if (n == "h") return {3600e9L, 5};
  if (n == "m" || n == "min") return {60e9L, 4};
  if (n == "s") return {1e9L, 3};
  if (n == "ms") return {1e6L, 2};
  if (n == "us") return {1e3L, 1};
  if (n == "ns") return {1, 0};
  return {0, -1};
}

char* put(char* p, std::string_view s) noexcept {
  std::memcpy(p, s.data(), s.size());
  return p + s.size();
}

}  // namespace

DurationScan scan_duration(std::string_view s) noexcept {
  DurationScan r;
  auto fail = [&](DurationFault f) {
    r.fault = f;
    r.ns = 0;
    return r;
  };
  while (!s.empty() && blank(s.front())) s.remove_prefix(1);
  while (!s.empty() && blank(s.back())) s.remove_suffix(1);
  for (std::string_view prefix : {"LTIME#", "TIME#", "LT#", "T#"})
    if (starts_with_ci(s, prefix)) {
      s.remove_prefix(prefix.size());
      break;
    }
  if (s.empty()) return fail(DurationFault::Empty);
  bool neg = false;
  std::size_t i = 0;
  if (s[0] == '-' || s[0] == '+') {
    neg = s[0] == '-';
    i = 1;
  }
  long double total = 0;
  bool any = false;
  int last_rank = 100;
  while (i < s.size()) {
    // Underscores may stand anywhere between the parts, as in a number.
    while (i < s.size() && s[i] == '_') ++i;
    if (i == s.size()) break;
    std::size_t j = i;
    while (j < s.size() && (digit(s[j]) || s[j] == '.' || s[j] == '_')) ++j;
    if (j == i) return fail(DurationFault::MissingNumber);
    r.number = s.substr(i, j - i);
    // The number without its underscores; a longer one than this holds is no number.
    char buf[64];
    std::size_t n = 0;
    for (char c : r.number)
      if (c != '_') {
        if (n == sizeof buf) return fail(DurationFault::BadNumber);
        buf[n++] = c;
      }
    double num = 0;
    const auto [end, ec] = std::from_chars(buf, buf + n, num);
    if (n == 0 || ec != std::errc() || end != buf + n) return fail(DurationFault::BadNumber);
    std::size_t k = j;
    char unit[4];
    std::size_t unit_len = 0;
    while (k < s.size() && (letter(s[k]) || s[k] == '_')) {
      if (s[k] != '_' && unit_len < sizeof unit) unit[unit_len] = s[k];
      unit_len += s[k] != '_';
      ++k;
    }
    if (unit_len == 0) {
      std::size_t u = k;
      while (u < s.size() && blank(s[u])) ++u;
      if (u > k && u < s.size() && letter(s[u])) {
        std::size_t w = u;
        while (w < s.size() && s[w] != ' ' && s[w] != '\t') ++w;
        r.unit = s.substr(u, w - u);
        return fail(DurationFault::SpacedUnit);
      }
      return fail(DurationFault::MissingUnit);
    }
    const UnitScale scale = unit_len <= sizeof unit ? unit_scale(std::string_view(unit, unit_len)) : UnitScale{0, -1};
    if (scale.rank < 0) {
      r.unit = s.substr(j, k - j);
      return fail(DurationFault::UnknownUnit);
    }
    if (scale.rank >= last_rank) return fail(DurationFault::UnitOrder);
    last_rank = scale.rank;
    total += static_cast<long double>(num) * scale.ns;
    any = true;
    i = k;
  }
  if (!any) return fail(DurationFault::Empty);
  r.number = {};
  const long double rounded = std::roundl(total);
  // x87 long double holds 2^63 exactly; -2^63 ns is the one value whose magnitude exceeds INT64_MAX.
  const long double limit = neg ? 9223372036854775808.0L : 9223372036854775807.0L;
  if (!(rounded <= limit)) {
    r.fault = DurationFault::TooLong;
    r.ns = neg ? std::numeric_limits<std::int64_t>::min() : std::numeric_limits<std::int64_t>::max();
    return r;
  }
  if (neg) r.ns = rounded == limit ? std::numeric_limits<std::int64_t>::min() : -static_cast<std::int64_t>(rounded);
  else r.ns = static_cast<std::int64_t>(rounded);
  return r;
}

char* write_duration(char* p, std::int64_t ns) noexcept {
  if (ns == 0) return put(p, "0ms");
  if (ns < 0) *p++ = '-';
  // The magnitude as unsigned, so INT64_MIN has one.
  std::uint64_t m = ns < 0 ? 0 - static_cast<std::uint64_t>(ns) : static_cast<std::uint64_t>(ns);
  struct Unit {
    std::uint64_t f;
    std::string_view n;
  };
  constexpr Unit units[] = {{3600000000000ULL, "h"}, {60000000000ULL, "m"}, {1000000000ULL, "s"},
                            {1000000ULL, "ms"},      {1000ULL, "us"},       {1ULL, "ns"}};
  for (const auto& u : units)
    if (m >= u.f) {
      p = std::to_chars(p, p + 20, m / u.f).ptr;
      p = put(p, u.n);
      m %= u.f;
    }
  return p;
}

}  // namespace syncplc
