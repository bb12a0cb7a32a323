#include "runtime/core/iec_type.hpp"

#include <array>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <limits>

#include "runtime/core/duration_text.hpp"

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
  char buf[kDurationTextMax];
  return std::string(buf, write_duration(buf, ns));
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
  const DurationScan d = scan_duration(text);
  if (d.fault == DurationFault::None) return d.ns;
  if (err) {
    const std::string number(d.number), unit(d.unit);
    std::string why;
    switch (d.fault) {
      case DurationFault::None: break;
      case DurationFault::Empty: why = "empty"; break;
      case DurationFault::MissingNumber: why = "missing number"; break;
      case DurationFault::BadNumber: why = "bad number '" + number + "'"; break;
      case DurationFault::MissingUnit: why = "missing unit after " + number; break;
      case DurationFault::SpacedUnit: why = "no space may separate " + number + " from its unit: " + number + unit; break;
      case DurationFault::UnknownUnit: why = "unknown unit '" + unit + "'"; break;
      case DurationFault::UnitOrder: why = "units must go from largest to smallest"; break;
      case DurationFault::TooLong: why = "too long for TIME (at most about 106751 days)"; break;
    }
    *err = "'" + std::string(trim(text)) + "' is not a duration (" + why + "; write e.g. 1ms, 250us, 0.5s, T#1m30s)";
  }
  return std::nullopt;
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
