#include "runtime/st/vm/st_string.hpp"

#include <algorithm>
#include <cassert>
#include <charconv>
#include <cmath>
#include <cstring>
#include <limits>
#include <string_view>

#include "runtime/core/duration_text.hpp"

namespace syncplc::st::vm {
namespace {

// Characters are read and written through bytes (memcpy): the cells are
// uint64 objects, and only char may alias them.
template <class C>
C char_at(const Cell* s, std::int64_t i) noexcept {
  C c;
  std::memcpy(&c, str_chars(s) + i * static_cast<std::int64_t>(sizeof(C)), sizeof(C));
  return c;
}

unsigned char* bytes_of(Cell* s) noexcept { return reinterpret_cast<unsigned char*>(s + 1); }

// Whether the cells of [a, a + na) and [b, b + nb) overlap (the debug check
// that a destination is no source; a source's cells counted from its length,
// the fewest it can have).
[[maybe_unused]] bool overlaps(const Cell* a, int na, const Cell* b, std::int64_t nb) noexcept {
  const auto pa = reinterpret_cast<std::uintptr_t>(a), pb = reinterpret_cast<std::uintptr_t>(b);
  return pa < pb + static_cast<std::uintptr_t>(nb) * 8 && pb < pa + static_cast<std::uintptr_t>(na) * 8;
}

// Builds a destination string piece by piece, cutting at the capacity, then
// writes the length and zeroes the rest of the cells (the invariant).
template <class C>
class Out {
 public:
  Out(Cell* dst, int capacity) noexcept : dst_(dst), cap_(capacity) {}

  // Appends n characters of src from index `from` (0-based).
  void append(const Cell* src, std::int64_t from, std::int64_t n) noexcept {
    assert(!overlaps(dst_, string_cells_of<C>(static_cast<int>(cap_)), src, 1 + ((str_len(src) + 1) * static_cast<std::int64_t>(sizeof(C)) + 7) / 8));
    append_bytes(str_chars(src) + from * static_cast<std::int64_t>(sizeof(C)), n);
  }
  void append_bytes(const void* chars, std::int64_t n) noexcept {
    if (n <= 0) return;
    const std::int64_t room = cap_ - len_;
    if (n > room) {
      truncated_ = true;
      n = room;
    }
    if (n <= 0) return;
    std::memcpy(bytes_of(dst_) + len_ * static_cast<std::int64_t>(sizeof(C)), chars,
                static_cast<std::size_t>(n) * sizeof(C));
    len_ += n;
  }
  void push(C c) noexcept { append_bytes(&c, 1); }
  std::int64_t room() const noexcept { return cap_ - len_; }
  void mark_truncated() noexcept { truncated_ = true; }

  StringStatus finish(bool bad) noexcept {
    dst_[0].set<std::uint64_t>(static_cast<std::uint64_t>(len_));
    const std::size_t used = static_cast<std::size_t>(len_) * sizeof(C);
    const std::size_t all = (static_cast<std::size_t>(string_cells_of<C>(cap_)) - 1) * 8;
    std::memset(bytes_of(dst_) + used, 0, all - used);
    return bad ? StringStatus::BadArgument : truncated_ ? StringStatus::Truncated : StringStatus::Ok;
  }

 private:
  Cell* dst_;
  std::int64_t cap_;
  std::int64_t len_ = 0;
  bool truncated_ = false;
};

constexpr StringStatus kBadCapacity = StringStatus::BadArgument;

// A gap position for DELETE/REPLACE/MID: P in 1 .. len + 1 is valid.
bool position_ok(std::int64_t p, std::int64_t len) noexcept { return p >= 1 && p <= len + 1; }

}  // namespace

// ---- copies and literals ----------------------------------------------------

template <StringChar C>
StringStatus str_assign(Cell* dst, int capacity, const Cell* src) noexcept {
  if (capacity < 0) return kBadCapacity;
  Out<C> o(dst, capacity);
  o.append(src, 0, str_len(src));
  return o.finish(false);
}

StringStatus str_set(Cell* dst, int capacity, const char* text, std::size_t n) noexcept {
  if (capacity < 0) return kBadCapacity;
  Out<char> o(dst, capacity);
  o.append_bytes(text, static_cast<std::int64_t>(std::min<std::size_t>(n, INT64_MAX / 2)));
  return o.finish(false);
}

StringStatus str_set(Cell* dst, int capacity, const char16_t* text, std::size_t n) noexcept {
  if (capacity < 0) return kBadCapacity;
  Out<char16_t> o(dst, capacity);
  o.append_bytes(text, static_cast<std::int64_t>(std::min<std::size_t>(n, INT64_MAX / 2)));
  return o.finish(false);
}

StringStatus wstr_set_utf8(Cell* dst, int capacity, const char* text, std::size_t n) noexcept {
  if (capacity < 0) return kBadCapacity;
  Out<char16_t> o(dst, capacity);
  bool bad = false;
  const auto* s = reinterpret_cast<const unsigned char*>(text);
  std::size_t i = 0;
  while (i < n) {
    const unsigned b = s[i];
    char32_t cp;
    int more;
    char32_t min;
    if (b < 0x80) { cp = b; more = 0; min = 0; }
    else if ((b & 0xE0) == 0xC0) { cp = b & 0x1F; more = 1; min = 0x80; }
    else if ((b & 0xF0) == 0xE0) { cp = b & 0x0F; more = 2; min = 0x800; }
    else if ((b & 0xF8) == 0xF0) { cp = b & 0x07; more = 3; min = 0x10000; }
    else { cp = 0xFFFD; more = -1; min = 0; }
    std::size_t j = i + 1;
    if (more > 0) {
      for (int k = 0; k < more; ++k, ++j) {
        if (j >= n || (s[j] & 0xC0) != 0x80) { more = -1; break; }
        cp = (cp << 6) | (s[j] & 0x3F);
      }
      // Overlong forms, surrogates and values past U+10FFFF are malformed.
      if (more > 0 && (cp < min || cp > 0x10FFFF || (cp >= 0xD800 && cp <= 0xDFFF))) more = -1;
    }
    if (more < 0) {
      bad = true;
      cp = 0xFFFD;
    }
    i = j;
    if (cp >= 0x10000) {
      if (o.room() < 2) {  // never half a pair
        o.mark_truncated();
        break;
      }
      cp -= 0x10000;
      o.push(static_cast<char16_t>(0xD800 + (cp >> 10)));
      o.push(static_cast<char16_t>(0xDC00 + (cp & 0x3FF)));
    } else {
      o.push(static_cast<char16_t>(cp));
    }
  }
  return o.finish(bad);
}

// ---- the string functions ---------------------------------------------------

template <StringChar C>
StringStatus str_left(Cell* dst, int capacity, const Cell* in, std::int64_t l) noexcept {
  if (capacity < 0) return kBadCapacity;
  Out<C> o(dst, capacity);
  o.append(in, 0, std::min(std::max<std::int64_t>(l, 0), str_len(in)));
  return o.finish(l < 0);
}

template <StringChar C>
StringStatus str_right(Cell* dst, int capacity, const Cell* in, std::int64_t l) noexcept {
  if (capacity < 0) return kBadCapacity;
  Out<C> o(dst, capacity);
  const std::int64_t len = str_len(in);
  const std::int64_t n = std::min(std::max<std::int64_t>(l, 0), len);
  o.append(in, len - n, n);
  return o.finish(l < 0);
}

template <StringChar C>
StringStatus str_mid(Cell* dst, int capacity, const Cell* in, std::int64_t l, std::int64_t p) noexcept {
  if (capacity < 0) return kBadCapacity;
  Out<C> o(dst, capacity);
  const std::int64_t len = str_len(in);
  const bool bad = l < 0 || !position_ok(p, len);
  if (!bad) o.append(in, p - 1, std::min(l, len - (p - 1)));
  return o.finish(bad);
}

template <StringChar C>
StringStatus str_concat(Cell* dst, int capacity, const Cell* in1, const Cell* in2) noexcept {
  if (capacity < 0) return kBadCapacity;
  Out<C> o(dst, capacity);
  o.append(in1, 0, str_len(in1));
  o.append(in2, 0, str_len(in2));
  return o.finish(false);
}

template <StringChar C>
StringStatus str_insert(Cell* dst, int capacity, const Cell* in1, const Cell* in2, std::int64_t p) noexcept {
  if (capacity < 0) return kBadCapacity;
  Out<C> o(dst, capacity);
  const std::int64_t len = str_len(in1);
  const std::int64_t at = std::clamp<std::int64_t>(p, 0, len);
  o.append(in1, 0, at);
  o.append(in2, 0, str_len(in2));
  o.append(in1, at, len - at);
  return o.finish(at != p);
}

// DELETE and REPLACE: IN1 without the L characters from P, `put` (may be
// null) in their place.
template <StringChar C>
StringStatus cut_and_put(Cell* dst, int capacity, const Cell* in, const Cell* put, std::int64_t l,
                         std::int64_t p) noexcept {
  if (capacity < 0) return kBadCapacity;
  Out<C> o(dst, capacity);
  const std::int64_t len = str_len(in);
  bool bad = l < 0;
  std::int64_t gap, n = 0;  // characters kept before the cut, characters cut
  if (position_ok(p, len)) {
    gap = p - 1;
    n = std::min(std::max<std::int64_t>(l, 0), len - gap);
  } else {
    bad = true;
    gap = p < 1 ? 0 : len;
  }
  o.append(in, 0, gap);
  if (put) o.append(put, 0, str_len(put));
  o.append(in, gap + n, len - gap - n);
  return o.finish(bad);
}

template <StringChar C>
StringStatus str_delete(Cell* dst, int capacity, const Cell* in, std::int64_t l, std::int64_t p) noexcept {
  return cut_and_put<C>(dst, capacity, in, nullptr, l, p);
}

template <StringChar C>
StringStatus str_replace(Cell* dst, int capacity, const Cell* in1, const Cell* in2, std::int64_t l,
                         std::int64_t p) noexcept {
  return cut_and_put<C>(dst, capacity, in1, in2, l, p);
}

template <StringChar C>
std::int64_t str_find(const Cell* in1, const Cell* in2) noexcept {
  const std::int64_t n1 = str_len(in1), n2 = str_len(in2);
  if (n2 == 0 || n2 > n1) return 0;
  const char* a = str_chars(in1);
  const char* b = str_chars(in2);
  if constexpr (sizeof(C) == 1) {
    // The library's search (memchr for the first character, then memcmp): no allocation.
    const std::string_view hay(a, static_cast<std::size_t>(n1)), needle(b, static_cast<std::size_t>(n2));
    const std::size_t at = hay.find(needle);
    return at == std::string_view::npos ? 0 : static_cast<std::int64_t>(at) + 1;
  } else {
    const std::size_t w = sizeof(C);
    for (std::int64_t i = 0; i + n2 <= n1; ++i)
      if (std::memcmp(a + i * w, b, static_cast<std::size_t>(n2) * w) == 0) return i + 1;
    return 0;
  }
}

template <StringChar C>
int str_compare(const Cell* a, const Cell* b) noexcept {
  const std::int64_t na = str_len(a), nb = str_len(b);
  const std::int64_t n = std::min(na, nb);
  for (std::int64_t i = 0; i < n; ++i) {
    using U = std::make_unsigned_t<C>;
    const auto x = static_cast<U>(char_at<C>(a, i)), y = static_cast<U>(char_at<C>(b, i));
    if (x != y) return x < y ? -1 : 1;
  }
  return na < nb ? -1 : na > nb ? 1 : 0;
}

// ---- values as text -----------------------------------------------------------

namespace {

char* put_text(char* p, std::string_view s) noexcept {
  std::memcpy(p, s.data(), s.size());
  return p + s.size();
}

// T#1h2m3s4ms5us6ns, as format_value writes a TIME (runtime/core/duration_text.hpp).
char* put_duration(char* p, std::int64_t ns) noexcept { return write_duration(put_text(p, "T#"), ns); }

}  // namespace

int value_text(IecType t, Cell value, char* buf) noexcept {
  char* end = buf + kValueTextMax;
  char* p = dispatch_type(t, [&]<IecType T>() -> char* {
    using N = typename Native<T>::type;
    const N v = value.get<N>();
    if constexpr (T == IecType::BOOL) return put_text(buf, v ? "TRUE" : "FALSE");
    else if constexpr (T == IecType::TIME) return put_duration(buf, v);
    else return std::to_chars(buf, end, v).ptr;  // integers in decimal; reals shortest round-trip
  });
  return static_cast<int>(p - buf);
}

template <StringChar C>
StringStatus to_string(IecType t, Cell value, Cell* dst, int capacity) noexcept {
  if (capacity < 0) return kBadCapacity;
  char text[kValueTextMax];
  const int n = value_text(t, value, text);
  Out<C> o(dst, capacity);
  for (int i = 0; i < n; ++i) o.push(static_cast<C>(static_cast<unsigned char>(text[i])));
  return o.finish(false);
}

// ---- text as values (parse_value's forms, runtime/core/iec_type.cpp) ----------

namespace {

bool is_space(char c) noexcept { return c == ' ' || c == '\t' || c == '\n' || c == '\v' || c == '\f' || c == '\r'; }
char to_upper(char c) noexcept { return c >= 'a' && c <= 'z' ? static_cast<char>(c - 'a' + 'A') : c; }

std::string_view trim(std::string_view s) noexcept {
  while (!s.empty() && is_space(s.front())) s.remove_prefix(1);
  while (!s.empty() && is_space(s.back())) s.remove_suffix(1);
  return s;
}

bool iequals(std::string_view a, std::string_view b) noexcept {
  if (a.size() != b.size()) return false;
  for (std::size_t i = 0; i < a.size(); ++i)
    if (to_upper(a[i]) != to_upper(b[i])) return false;
  return true;
}

// s without underscores, into buf (room for kMaxNumberText).
std::string_view strip_underscores(std::string_view s, char* buf) noexcept {
  std::size_t n = 0;
  for (char c : s)
    if (c != '_') buf[n++] = c;
  return {buf, n};
}

// The type a "NAME#" prefix names (the sixteen, LTIME as TIME), or -1.
int prefix_type(std::string_view name) noexcept {
  name = trim(name);
  for (int i = 0; i < kIecTypeCount; ++i)
    if (iequals(name, kIecTypeNames[i])) return i;
  if (iequals(name, "LTIME")) return static_cast<int>(IecType::TIME);
  return -1;
}

// 128-bit integers hold any 64-bit magnitude and its sign (a GCC/Clang
// extension; syncplc_st builds with -Wpedantic).
__extension__ using u128 = unsigned __int128;
__extension__ using i128 = __int128;

enum class Parse { Ok, Saturated, Invalid };

// An integer with optional sign and base prefix (16#, 8#, 2#, 0x, 0b), as
// parse_integer; a magnitude past 2^65 is kept as "huge" (saturates).
Parse parse_integer(std::string_view text, bool& negative, u128& mag) noexcept {
  char buf[kMaxNumberText];
  std::string_view s = strip_underscores(trim(text), buf);
  negative = false;
  if (!s.empty() && (s[0] == '+' || s[0] == '-')) {
    negative = s[0] == '-';
    s.remove_prefix(1);
  }
  unsigned base = 10;
  if (s.size() > 3 && s.substr(0, 3) == "16#") { base = 16; s.remove_prefix(3); }
  else if (s.size() > 2 && s.substr(0, 2) == "8#") { base = 8; s.remove_prefix(2); }
  else if (s.size() > 2 && s.substr(0, 2) == "2#") { base = 2; s.remove_prefix(2); }
  else if (s.size() > 2 && (s.substr(0, 2) == "0x" || s.substr(0, 2) == "0X")) { base = 16; s.remove_prefix(2); }
  else if (s.size() > 2 && (s.substr(0, 2) == "0b" || s.substr(0, 2) == "0B")) { base = 2; s.remove_prefix(2); }
  if (s.empty()) return Parse::Invalid;
  constexpr u128 kHuge = (static_cast<u128>(1) << 65) + 1;
  mag = 0;
  bool huge = false;
  for (char ch : s) {
    unsigned d;
    if (ch >= '0' && ch <= '9') d = static_cast<unsigned>(ch - '0');
    else if (ch >= 'a' && ch <= 'f') d = static_cast<unsigned>(ch - 'a' + 10);
    else if (ch >= 'A' && ch <= 'F') d = static_cast<unsigned>(ch - 'A' + 10);
    else d = 99;
    if (d >= base) return Parse::Invalid;
    if (!huge) {
      mag = mag * base + d;
      if (mag > (static_cast<u128>(1) << 65)) huge = true;
    }
  }
  if (huge) mag = kHuge;
  return huge ? Parse::Saturated : Parse::Ok;
}

// A real as parse_double reads it; out of a double's range: the largest
// double of its sign (overflow) or zero (underflow), Saturated.
Parse parse_double(std::string_view text, double& out) noexcept {
  char buf[kMaxNumberText];
  std::string_view s = strip_underscores(trim(text), buf);
  if (s.empty()) return Parse::Invalid;
  const char* b = s.data();
  const char* e = s.data() + s.size();
  if (*b == '+') ++b;
  auto [p, ec] = std::from_chars(b, e, out);
  if (p != e) return Parse::Invalid;
  if (ec == std::errc::result_out_of_range) {
    // Over- or underflow? A long double reaches further; past it, the
    // exponent's sign tells.
    long double x = 0;
    auto r = std::from_chars(b, e, x);
    bool over;
    if (r.ec == std::errc()) {
      over = std::fabs(x) >= 1;
    } else {
      const char* ex = std::find_if(b, e, [](char c) { return c == 'e' || c == 'E'; });
      over = !(ex + 1 < e && ex[1] == '-');
    }
    const bool neg = *b == '-';
    out = over ? (neg ? -std::numeric_limits<double>::max() : std::numeric_limits<double>::max())
               : (neg ? -0.0 : 0.0);
    return Parse::Saturated;
  }
  if (ec != std::errc() || !std::isfinite(out)) return Parse::Invalid;
  return Parse::Ok;
}

// A duration as parse_duration_ns reads it (one reading: scan_duration);
// past TIME's range: the limit of its sign, Saturated.
Parse parse_duration(std::string_view text, std::int64_t& out) noexcept {
  const DurationScan d = scan_duration(text);
  if (d.fault == DurationFault::TooLong) {
    out = d.ns;
    return Parse::Saturated;
  }
  if (d.fault != DurationFault::None) return Parse::Invalid;
  out = d.ns;
  return Parse::Ok;
}

// parse_value's steps on a trimmed ASCII text.
Parse parse_text(IecType t, std::string_view s, Cell& out) noexcept {
  // An optional IEC type prefix such as INT#5 or REAL#1.5 (a TIME reads its own).
  if (auto h = s.find('#'); h != std::string_view::npos && t != IecType::TIME) {
    const int pt = prefix_type(s.substr(0, h));
    if (pt >= 0) {
      if (pt != static_cast<int>(t)) return Parse::Invalid;
      s.remove_prefix(h + 1);
    }
  }
  switch (t) {
    case IecType::BOOL:
      for (std::string_view w : {"TRUE", "1", "ON", "YES"})
        if (iequals(s, w)) return out.set<bool>(true), Parse::Ok;
      for (std::string_view w : {"FALSE", "0", "OFF", "NO"})
        if (iequals(s, w)) return out.set<bool>(false), Parse::Ok;
      return Parse::Invalid;
    case IecType::REAL:
    case IecType::LREAL: {
      double d;
      Parse r = parse_double(s, d);
      if (r == Parse::Invalid) return r;
      if (t == IecType::LREAL) return out.set<double>(d), r;
      // From 2^128 - 2^103 on a double rounds to infinity as a float (real_cell).
      if (std::fabs(d) >= std::ldexp(1.0, 128) - std::ldexp(1.0, 103)) {
        d = d < 0 ? -std::numeric_limits<float>::max() : std::numeric_limits<float>::max();
        r = Parse::Saturated;
      }
      return out.set<float>(static_cast<float>(d)), r;
    }
    case IecType::TIME: {
      std::int64_t ns;
      const Parse r = parse_duration(s, ns);
      if (r != Parse::Invalid) out.set<std::int64_t>(ns);
      return r;
    }
    default: break;
  }
  bool neg;
  u128 mag;
  Parse r = parse_integer(s, neg, mag);
  if (r == Parse::Invalid) return r;
  return dispatch_type(t, [&]<IecType T>() -> Parse {
    using N = typename Native<T>::type;
    if constexpr (std::is_integral_v<N> && !std::is_same_v<N, bool>) {
      using L = std::numeric_limits<N>;
      const i128 v = neg ? -static_cast<i128>(mag) : static_cast<i128>(mag);
      const i128 c = std::clamp<i128>(v, L::min(), L::max());
      out.set<N>(static_cast<N>(c));
      return c != v ? Parse::Saturated : r;
    } else {
      return Parse::Invalid;
    }
  });
}

}  // namespace

template <StringChar C>
StringStatus from_string(IecType t, const Cell* src, Cell* out) noexcept {
  *out = Cell{};
  const std::int64_t len = str_len(src);
  std::int64_t b = 0, e = len;
  // Trim first, so that only the number's own characters count against the buffer.
  const auto space_at = [&](std::int64_t i) {
    const auto c = static_cast<std::make_unsigned_t<C>>(char_at<C>(src, i));
    return c < 128 && is_space(static_cast<char>(c));
  };
  while (b < e && space_at(b)) ++b;
  while (e > b && space_at(e - 1)) --e;
  if (e - b > kMaxNumberText) return StringStatus::BadArgument;
  char text[kMaxNumberText];
  for (std::int64_t i = b; i < e; ++i) {
    const auto c = static_cast<std::make_unsigned_t<C>>(char_at<C>(src, i));
    if (c == 0 || c >= 128) return StringStatus::BadArgument;  // no number has one
    text[i - b] = static_cast<char>(c);
  }
  Cell v;
  const Parse r = parse_text(t, std::string_view(text, static_cast<std::size_t>(e - b)), v);
  if (r == Parse::Invalid) return StringStatus::BadArgument;
  *out = v;
  return r == Parse::Ok ? StringStatus::Ok : StringStatus::BadArgument;
}

// ---- the instantiations for STRING and WSTRING ------------------------------

#define SYNCPLC_ST_STRING_FUNCTIONS(C)                                                                      \
  template StringStatus str_assign<C>(Cell*, int, const Cell*) noexcept;                                 \
  template StringStatus str_left<C>(Cell*, int, const Cell*, std::int64_t) noexcept;                     \
  template StringStatus str_right<C>(Cell*, int, const Cell*, std::int64_t) noexcept;                    \
  template StringStatus str_mid<C>(Cell*, int, const Cell*, std::int64_t, std::int64_t) noexcept;        \
  template StringStatus str_concat<C>(Cell*, int, const Cell*, const Cell*) noexcept;                    \
  template StringStatus str_insert<C>(Cell*, int, const Cell*, const Cell*, std::int64_t) noexcept;      \
  template StringStatus str_delete<C>(Cell*, int, const Cell*, std::int64_t, std::int64_t) noexcept;     \
  template StringStatus str_replace<C>(Cell*, int, const Cell*, const Cell*, std::int64_t,               \
                                       std::int64_t) noexcept;                                           \
  template std::int64_t str_find<C>(const Cell*, const Cell*) noexcept;                                  \
  template int str_compare<C>(const Cell*, const Cell*) noexcept;                                        \
  template StringStatus to_string<C>(IecType, Cell, Cell*, int) noexcept;                                \
  template StringStatus from_string<C>(IecType, const Cell*, Cell*) noexcept;

SYNCPLC_ST_STRING_FUNCTIONS(char)
SYNCPLC_ST_STRING_FUNCTIONS(char16_t)
#undef SYNCPLC_ST_STRING_FUNCTIONS

}  // namespace syncplc::st::vm
