#include "runtime/core/iec_type.hpp"

#include <array>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <limits>

namespace syncplc {
namespace {

constexpr const auto& kNames = kIecTypeNames;

std::string upper(std::string_view s) {
  std::string r(s);
  for (auto& ch : r) ch = static_cast<char>(std::toupper(static_cast<unsigned char>(ch)));
  return r;
}

std::string strip_underscores(std::string_view s) {
  std::string r;
  r.reserve(s.size());
  for (char ch : s)
    if (ch != '_') r.push_back(ch);
  return r;
}

std::string_view trim(std::string_view s) {
  while (!s.empty() && std::isspace(static_cast<unsigned char>(s.front()))) s.remove_prefix(1);
  while (!s.empty() && std::isspace(static_cast<unsigned char>(s.back()))) s.remove_suffix(1);
  return s;
}

// 128-bit so that a literal's range check cannot overflow itself.
__extension__ using i128 = __int128;
__extension__ using u128 = unsigned __int128;

// Integer literal with optional sign and base prefix (16#, 8#, 2#, 0x, 0b).
bool parse_integer(std::string_view text, bool& negative, u128& mag, std::string* err) {
  std::string s = strip_underscores(trim(text));
  negative = false;
  std::size_t i = 0;
  if (i < s.size() && (s[i] == '+' || s[i] == '-')) {
    negative = s[i] == '-';
    ++i;
  }
  int base = 10;
  std::string_view rest(s);
  rest.remove_prefix(i);
  if (rest.size() > 3 && rest.substr(0, 3) == "16#") { base = 16; rest.remove_prefix(3); }
  else if (rest.size() > 2 && rest.substr(0, 2) == "8#") { base = 8; rest.remove_prefix(2); }
  else if (rest.size() > 2 && rest.substr(0, 2) == "2#") { base = 2; rest.remove_prefix(2); }
  else if (rest.size() > 2 && (rest.substr(0, 2) == "0x" || rest.substr(0, 2) == "0X")) { base = 16; rest.remove_prefix(2); }
  else if (rest.size() > 2 && (rest.substr(0, 2) == "0b" || rest.substr(0, 2) == "0B")) { base = 2; rest.remove_prefix(2); }
  if (rest.empty()) {
    if (err) *err = "'" + std::string(text) + "' is not an integer";
    return false;
  }
  mag = 0;
  for (char ch : rest) {
    int d;
    if (ch >= '0' && ch <= '9') d = ch - '0';
    else if (ch >= 'a' && ch <= 'f') d = ch - 'a' + 10;
    else if (ch >= 'A' && ch <= 'F') d = ch - 'A' + 10;
    else d = 99;
    if (d >= base) {
      if (err) *err = "'" + std::string(text) + "' is not an integer";
      return false;
    }
    mag = mag * static_cast<unsigned>(base) + static_cast<unsigned>(d);
    if (mag > (static_cast<u128>(1) << 65)) {
      if (err) *err = "'" + std::string(text) + "' is too large";
      return false;
    }
  }
  return true;
}

bool parse_double(std::string_view text, double& out, std::string* err) {
  std::string s = strip_underscores(trim(text));
  if (s.empty()) {
    if (err) *err = "empty number";
    return false;
  }
  const char* b = s.data();
  const char* e = s.data() + s.size();
  if (*b == '+') ++b;
  auto [p, ec] = std::from_chars(b, e, out);
  if (ec != std::errc() || p != e || !std::isfinite(out)) {
    if (err) *err = "'" + std::string(text) + "' is not a number";
    return false;
  }
  return true;
}

template <class T>
std::optional<Cell> make_int(bool neg, u128 mag, IecType t, std::string_view text, std::string* err) {
  using L = std::numeric_limits<T>;
  bool ok;
  i128 v = neg ? -static_cast<i128>(mag) : static_cast<i128>(mag);
  ok = v >= static_cast<i128>(L::min()) && v <= static_cast<i128>(L::max());
  if (!ok) {
    if (err)
      *err = "value " + std::string(trim(text)) + " is out of range for " + std::string(type_name(t)) + " (" +
             std::to_string(L::min()) + " .. " + std::to_string(L::max()) + ")";
    return std::nullopt;
  }
  Cell c;
  c.set<T>(static_cast<T>(v));
  return c;
}

}  // namespace

std::string_view type_name(IecType t) { return kNames[static_cast<int>(t)]; }

std::string_view class_name(TypeClass c) {
  switch (c) {
    case TypeClass::Exact: return "exact";
    case TypeClass::ANY: return "ANY";
    case TypeClass::ANY_MAGNITUDE: return "ANY_MAGNITUDE";
    case TypeClass::ANY_NUM: return "ANY_NUM";
    case TypeClass::ANY_INT: return "ANY_INT";
    case TypeClass::ANY_REAL: return "ANY_REAL";
    case TypeClass::ANY_BIT: return "ANY_BIT";
  }
  return "?";
}

std::optional<IecType> parse_type_name(std::string_view s) {
  std::string u = upper(trim(s));
  for (int i = 0; i < kIecTypeCount; ++i)
    if (kNames[i] == u) return static_cast<IecType>(i);
  if (u == "LTIME") return IecType::TIME;
  return std::nullopt;
}

bool is_signed_integer(IecType t) {
  return t == IecType::SINT || t == IecType::INT || t == IecType::DINT || t == IecType::LINT;
}
bool is_integer(IecType t) {
  return is_signed_integer(t) || t == IecType::USINT || t == IecType::UINT || t == IecType::UDINT ||
         t == IecType::ULINT;
}
bool is_real(IecType t) { return t == IecType::REAL || t == IecType::LREAL; }
bool is_bit_string(IecType t) {
  return t == IecType::BOOL || t == IecType::BYTE || t == IecType::WORD || t == IecType::DWORD ||
         t == IecType::LWORD;
}

bool in_class(IecType t, TypeClass c) {
  switch (c) {
    case TypeClass::Exact: return false;
    case TypeClass::ANY: return true;
    case TypeClass::ANY_MAGNITUDE: return is_integer(t) || is_real(t) || t == IecType::TIME;
    case TypeClass::ANY_NUM: return is_integer(t) || is_real(t);
    case TypeClass::ANY_INT: return is_integer(t);
    case TypeClass::ANY_REAL: return is_real(t);
    case TypeClass::ANY_BIT: return is_bit_string(t);
  }
  return false;
}

int bit_width(IecType t) {
  switch (t) {
    case IecType::BOOL: return 1;
    case IecType::SINT: case IecType::USINT: case IecType::BYTE: return 8;
    case IecType::INT: case IecType::UINT: case IecType::WORD: return 16;
    case IecType::DINT: case IecType::UDINT: case IecType::DWORD: case IecType::REAL: return 32;
    default: return 64;
  }
}

double cell_as_double(IecType t, Cell c) {
  return dispatch_type(t, [&]<IecType T>() -> double {
    using N = typename Native<T>::type;
    if constexpr (T == IecType::TIME) return static_cast<double>(c.get<N>()) * 1e-9;
    else return static_cast<double>(c.get<N>());
  });
}

std::string format_duration(std::int64_t ns) {
  if (ns == 0) return "0ms";
  std::string sign = ns < 0 ? "-" : "";
  // Magnitude as unsigned so INT64_MIN formats without overflow.
  std::uint64_t m = ns < 0 ? 0 - static_cast<std::uint64_t>(ns) : static_cast<std::uint64_t>(ns);
  struct U { std::uint64_t f; const char* n; };
  constexpr U units[] = {{3600000000000ULL, "h"}, {60000000000ULL, "m"}, {1000000000ULL, "s"},
                         {1000000ULL, "ms"}, {1000ULL, "us"}, {1ULL, "ns"}};
  std::string out = sign;
  for (const auto& u : units) {
    if (m >= u.f) {
      out += std::to_string(m / u.f) + u.n;
      m %= u.f;
    }
  }
  return out;
}

std::string format_value(IecType t, Cell c) {
  return dispatch_type(t, [&]<IecType T>() -> std::string {
    using N = typename Native<T>::type;
    N v = c.get<N>();
    if constexpr (T == IecType::BOOL) return v ? "TRUE" : "FALSE";
    else if constexpr (T == IecType::TIME) return "T#" + format_duration(v);
    else if constexpr (T == IecType::BYTE || T == IecType::WORD || T == IecType::DWORD || T == IecType::LWORD) {
      char buf[32];
      std::snprintf(buf, sizeof buf, "16#%0*llX", static_cast<int>(sizeof(N) * 2),
                    static_cast<unsigned long long>(v));
      return buf;
    } else if constexpr (std::is_floating_point_v<N>) {
      char buf[64];  // shortest text that reads back to the same value: 0.35, not 0.34999999999999998
      auto res = std::to_chars(buf, buf + sizeof buf, v);
      return std::string(buf, res.ptr);
    } else {
      return std::to_string(v);
    }
  });
}

std::optional<std::int64_t> parse_duration_ns(std::string_view text, std::string* err) {
  std::string s = strip_underscores(trim(text));
  std::string u = upper(s);
  if (u.rfind("LTIME#", 0) == 0) s = s.substr(6);
  else if (u.rfind("TIME#", 0) == 0) s = s.substr(5);
  else if (u.rfind("LT#", 0) == 0) s = s.substr(3);
  else if (u.rfind("T#", 0) == 0) s = s.substr(2);
  auto bad = [&](const std::string& why) -> std::optional<std::int64_t> {
    if (err) *err = "'" + std::string(trim(text)) + "' is not a duration (" + why + "; write e.g. 1ms, 250us, 0.5s, T#1m30s)";
    return std::nullopt;
  };
  if (s.empty()) return bad("empty");
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
    std::size_t j = i;
    while (j < s.size() && (std::isdigit(static_cast<unsigned char>(s[j])) || s[j] == '.')) ++j;
    if (j == i) return bad("missing number");
    double num;
    std::string numtxt = s.substr(i, j - i);
    auto [p, ec] = std::from_chars(numtxt.data(), numtxt.data() + numtxt.size(), num);
    if (ec != std::errc() || p != numtxt.data() + numtxt.size()) return bad("bad number '" + numtxt + "'");
    std::size_t k = j;
    while (k < s.size() && std::isalpha(static_cast<unsigned char>(s[k]))) ++k;
    std::string unit = s.substr(j, k - j);
    for (auto& ch : unit) ch = static_cast<char>(std::tolower(static_cast<unsigned char>(ch)));
    long double f;
    int rank;
    if (unit == "d") { f = 86400e9L; rank = 6; }
    else if (unit == "h") { f = 3600e9L; rank = 5; }
    else if (unit == "m" || unit == "min") { f = 60e9L; rank = 4; }
    else if (unit == "s") { f = 1e9L; rank = 3; }
    else if (unit == "ms") { f = 1e6L; rank = 2; }
    else if (unit == "us") { f = 1e3L; rank = 1; }
    else if (unit == "ns") { f = 1; rank = 0; }
    else if (unit.empty()) {
      // "10 ms": the unit is there, after a space a duration may not have.
      std::size_t u = k;
      while (u < s.size() && std::isspace(static_cast<unsigned char>(s[u]))) ++u;
      if (u > k && u < s.size() && std::isalpha(static_cast<unsigned char>(s[u])))
        return bad("no space may separate " + numtxt + " from its unit: " + numtxt + s.substr(u, s.find_first_of(" \t", u) - u));
      return bad("missing unit after " + numtxt);
    }
    else return bad("unknown unit '" + unit + "'");
    if (rank >= last_rank) return bad("units must go from largest to smallest");
    last_rank = rank;
    total += static_cast<long double>(num) * f;
    any = true;
    i = k;
  }
  if (!any) return bad("empty");
  long double r = std::roundl(total);
  // x87 long double holds 2^63 exactly; -2^63 ns is the one value whose magnitude exceeds INT64_MAX.
  const long double limit = neg ? 9223372036854775808.0L : 9223372036854775807.0L;
  if (r > limit) return bad("too long for TIME (at most about 106751 days)");
  if (neg) return r == 9223372036854775808.0L ? INT64_MIN : -static_cast<std::int64_t>(r);
  return static_cast<std::int64_t>(r);
}

std::optional<Cell> real_cell(IecType t, double v, std::string_view text, std::string* err) {
  Cell c;
  if (t == IecType::LREAL) {
    c.set<double>(v);
    return c;
  }
  // From 2^128 - 2^103 on a double rounds to infinity as a float (and the
  // conversion itself would be undefined).
  if (std::fabs(v) >= std::ldexp(1.0, 128) - std::ldexp(1.0, 103)) {
    if (err) *err = "value " + std::string(trim(text)) + " is out of range for REAL";
    return std::nullopt;
  }
  c.set<float>(static_cast<float>(v));
  return c;
}

std::optional<Cell> parse_value(IecType t, std::string_view text, std::string* err) {
  std::string_view s = trim(text);
  std::string u = upper(s);
  // Strip an optional IEC type prefix such as INT#5 or REAL#1.5.
  if (auto h = u.find('#'); h != std::string::npos && t != IecType::TIME) {
    std::string prefix = u.substr(0, h);
    if (auto pt = parse_type_name(prefix)) {
      if (*pt != t) {
        if (err) *err = "literal " + std::string(s) + " is " + prefix + ", expected " + std::string(type_name(t));
        return std::nullopt;
      }
      s.remove_prefix(h + 1);
      u = u.substr(h + 1);
    }
  }
  switch (t) {
    case IecType::BOOL: {
      Cell c;
      if (u == "TRUE" || u == "1" || u == "ON" || u == "YES") { c.set<bool>(true); return c; }
      if (u == "FALSE" || u == "0" || u == "OFF" || u == "NO") { c.set<bool>(false); return c; }
      if (err) *err = "'" + std::string(s) + "' is not a BOOL (TRUE or FALSE)";
      return std::nullopt;
    }
    case IecType::REAL:
    case IecType::LREAL: {
      double d;
      if (!parse_double(s, d, err)) return std::nullopt;
      return real_cell(t, d, s, err);
    }
    case IecType::TIME: {
      auto ns = parse_duration_ns(s, err);
      if (!ns) return std::nullopt;
      Cell c;
      c.set<std::int64_t>(*ns);
      return c;
    }
    default: break;
  }
  bool neg;
  u128 mag;
  if (!parse_integer(s, neg, mag, err)) return std::nullopt;
  if (neg && mag != 0 && !is_signed_integer(t)) {
    if (err) *err = "value " + std::string(s) + " is out of range for " + std::string(type_name(t)) + " (unsigned)";
    return std::nullopt;
  }
  return dispatch_type(t, [&]<IecType T>() -> std::optional<Cell> {
    using N = typename Native<T>::type;
    if constexpr (std::is_integral_v<N> && !std::is_same_v<N, bool>) return make_int<N>(neg, mag, t, s, err);
    else return std::nullopt;
  });
}

}  // namespace syncplc
