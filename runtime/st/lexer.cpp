#include "runtime/st/lexer.hpp"

#include <algorithm>
#include <array>
#include <cctype>
#include <charconv>
#include <cmath>
#include <limits>
#include <string>

#include <fmt/format.h>

namespace syncplc::st {

namespace {

bool is_digit(char c) { return c >= '0' && c <= '9'; }
bool is_alpha(char c) { return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || c == '_'; }
bool is_alnum(char c) { return is_alpha(c) || is_digit(c); }
int hex_value(char c) {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'a' && c <= 'z') return c - 'a' + 10;
  if (c >= 'A' && c <= 'Z') return c - 'A' + 10;
  return 99;
}

// A character as a message shows it: printable as itself, else its byte value.
std::string shown(char c) {
  const auto u = static_cast<unsigned char>(c);
  if (u >= 0x21 && u < 0x7f) return fmt::format("'{}'", c);
  return fmt::format("byte 0x{:02X}", u);
}

// Digits with single underscores between them (1_000): the IEC rule.
bool underscores_ok(std::string_view digits) {
  if (digits.empty() || digits.front() == '_' || digits.back() == '_') return false;
  return digits.find("__") == std::string_view::npos;
}

std::string without_underscores(std::string_view s) {
  std::string out;
  for (char c : s)
    if (c != '_') out += c;
  return out;
}

enum class PrefixClass { None, Number, Duration, Date, TimeOfDay, DateAndTime, String };

// What may follow `NAME#` for an elementary type name, and the name the token carries.
PrefixClass prefix_class(const std::string& up, std::string& canonical) {
  static const std::array<std::string_view, 15> numbers = {"SINT", "INT", "DINT", "LINT", "USINT",
                                                           "UINT", "UDINT", "ULINT", "REAL", "LREAL",
                                                           "BYTE", "WORD", "DWORD", "LWORD", "BOOL"};
  for (std::string_view n : numbers)
    if (up == n) {
      canonical = up;
      return PrefixClass::Number;
    }
  if (up == "T" || up == "TIME") return canonical = "TIME", PrefixClass::Duration;
  if (up == "LT" || up == "LTIME") return canonical = "LTIME", PrefixClass::Duration;
  if (up == "D" || up == "DATE") return canonical = "DATE", PrefixClass::Date;
  if (up == "LD" || up == "LDATE") return canonical = "LDATE", PrefixClass::Date;
  if (up == "TOD" || up == "TIME_OF_DAY") return canonical = "TOD", PrefixClass::TimeOfDay;
  if (up == "LTOD" || up == "LTIME_OF_DAY") return canonical = "LTOD", PrefixClass::TimeOfDay;
  if (up == "DT" || up == "DATE_AND_TIME") return canonical = "DT", PrefixClass::DateAndTime;
  if (up == "LDT" || up == "LDATE_AND_TIME") return canonical = "LDT", PrefixClass::DateAndTime;
  if (up == "STRING" || up == "WSTRING" || up == "CHAR" || up == "WCHAR") return canonical = up, PrefixClass::String;
  return PrefixClass::None;
}

void append_utf8(std::string& out, unsigned cp) {
  if (cp < 0x80) {
    out += static_cast<char>(cp);
  } else if (cp < 0x800) {
    out += static_cast<char>(0xC0 | (cp >> 6));
    out += static_cast<char>(0x80 | (cp & 0x3F));
  } else {
    out += static_cast<char>(0xE0 | (cp >> 12));
    out += static_cast<char>(0x80 | ((cp >> 6) & 0x3F));
    out += static_cast<char>(0x80 | (cp & 0x3F));
  }
}

class Lexer {
 public:
  Lexer(std::string_view src, const SourceFile& file, StDiagnostics& diags)
      : src_(src), file_(file), diags_(diags) {
    // A UTF-8 byte order mark, as Windows editors and some PLC tools' exports write it.
    if (src_.substr(0, 3) == "\xEF\xBB\xBF") i_ = line_start_ = 3;
  }

  std::vector<Token> run() {
    std::vector<Token> out;
    // About one token per 4 to 8 bytes of ST: no regrowth copies for a usual
    // file; beyond 64k tokens the vector grows as usual.
    out.reserve(std::min<std::size_t>(src_.size() / 6 + 1, std::size_t{1} << 16));
    for (;;) {
      skip_space_and_comments();
      Token t;
      t.loc = here();
      // Directly before: the group began on a line of its own (not after the
      // previous token) and ends on the line before this token or on its line.
      t.comment_directly_before = !pending_comment_.empty() && pending_start_line_ > last_token_line_ &&
                                  pending_end_line_ >= t.loc.line - 1;
      t.comment_before = std::move(pending_comment_);
      pending_comment_.clear();
      if (i_ >= src_.size()) {
        t.kind = TokenKind::End;
        out.push_back(std::move(t));
        return out;
      }
      const std::size_t start = i_;
      token_start_ = start;
      scan(t);
      t.text = std::string(src_.substr(start, i_ - start));
      last_token_line_ = line_;
      out.push_back(std::move(t));
    }
  }

 private:
  char peek(std::size_t ahead = 0) const { return i_ + ahead < src_.size() ? src_[i_ + ahead] : '\0'; }
  SourceLoc here() const { return SourceLoc{file_, line_, static_cast<int>(i_ - line_start_) + 1}; }
  SourceLoc at(std::size_t pos) const {
    // Only used within the current line (pos >= line_start_).
    return SourceLoc{file_, line_, static_cast<int>(pos - line_start_) + 1};
  }
  void advance() {
    if (i_ < src_.size() && src_[i_] == '\n') {
      ++line_;
      line_start_ = i_ + 1;
    }
    ++i_;
  }
  void error(const SourceLoc& loc, std::string msg) { diags_.error(loc, std::move(msg)); }

  void skip_space_and_comments() {
    for (;;) {
      const char c = peek();
      if (c == ' ' || c == '\t' || c == '\r' || c == '\n' || c == '\f' || c == '\v') {
        advance();
      } else if (c == '/' && peek(1) == '/') {
        const std::size_t body = i_ + 2;
        const int start_line = line_;
        while (i_ < src_.size() && src_[i_] != '\n') advance();
        add_comment(src_.substr(body, i_ - body), start_line);
      } else if ((c == '(' && peek(1) == '*') || (c == '/' && peek(1) == '*')) {
        block_comment(c == '(' ? '(' : '/', c == '(' ? ')' : '/');
      } else {
        return;
      }
    }
  }

  // (* … *) and /* … */, nested as the 3rd edition's table 5 allows
  // ((* outer (* inner *) still outer *)); each kind nests only within itself.
  void block_comment(char open, char close) {
    const SourceLoc loc = here();
    advance();
    advance();
    const std::size_t body = i_;
    std::size_t depth = 1;
    while (i_ < src_.size()) {
      if (peek() == open && peek(1) == '*') {
        ++depth;
        advance();
        advance();
      } else if (peek() == '*' && peek(1) == close) {
        advance();
        advance();
        if (--depth == 0) {
          add_comment(src_.substr(body, i_ - 2 - body), loc.line);
          return;
        }
      } else {
        advance();
      }
    }
    error(loc, open == '(' ? "comment '(*' is not closed by '*)'" : "comment '/*' is not closed by '*/'");
  }

  // Comments on adjacent lines form one group, the comment before the next
  // token; a blank line, or a new line after a comment trailing the previous
  // token, starts a new group.
  void add_comment(std::string_view text, int start_line) {
    const auto b = text.find_first_not_of(" \t\r\n*");
    if (b == std::string_view::npos) return;
    const auto e = text.find_last_not_of(" \t\r\n*");
    const bool trailing_group = pending_start_line_ == last_token_line_ && last_token_line_ > 0;
    if (!pending_comment_.empty() &&
        (start_line > pending_end_line_ + 1 || (trailing_group && start_line > last_token_line_)))
      pending_comment_.clear();
    if (pending_comment_.empty()) {
      pending_start_line_ = start_line;
    } else {
      pending_comment_ += '\n';
    }
    pending_comment_ += text.substr(b, e - b + 1);
    pending_end_line_ = line_;
  }

  void scan(Token& t) {
    const char c = peek();
    if (is_alpha(c)) return identifier(t);
    if (is_digit(c)) return number(t, false);
    if (c == '\'' || c == '"') return string_literal(t, c);
    if (c == '%') return direct_address(t);
    if (c == '{') return pragma(t);
    advance();
    auto two = [&](char next, TokenKind k2, TokenKind k1) {
      if (peek() == next) {
        advance();
        t.kind = k2;
      } else {
        t.kind = k1;
      }
    };
    switch (c) {
      case '(': t.kind = TokenKind::LParen; return;
      case ')': t.kind = TokenKind::RParen; return;
      case '[': t.kind = TokenKind::LBracket; return;
      case ']': t.kind = TokenKind::RBracket; return;
      case ',': t.kind = TokenKind::Comma; return;
      case ';': t.kind = TokenKind::Semicolon; return;
      case ':': return two('=', TokenKind::Assign, TokenKind::Colon);
      case '.': return two('.', TokenKind::DotDot, TokenKind::Dot);
      case '#': t.kind = TokenKind::Hash; return;
      case '+': t.kind = TokenKind::Plus; return;
      case '-': t.kind = TokenKind::Minus; return;
      case '*': return two('*', TokenKind::Power, TokenKind::Star);
      case '/': t.kind = TokenKind::Slash; return;
      case '&': t.kind = TokenKind::Ampersand; return;
      case '^': t.kind = TokenKind::Caret; return;
      case '=': return two('>', TokenKind::OutputAssign, TokenKind::Equal);
      case '<':
        if (peek() == '>') {
          advance();
          t.kind = TokenKind::NotEqual;
          return;
        }
        return two('=', TokenKind::LessEqual, TokenKind::Less);
      case '>': return two('=', TokenKind::GreaterEqual, TokenKind::Greater);
      default:
        t.kind = TokenKind::Error;
        error(t.loc, "unexpected character " + shown(c));
        // A UTF-8 sequence is one character: skip its continuation bytes.
        while (i_ < src_.size() && (static_cast<unsigned char>(peek()) & 0xC0) == 0x80) advance();
        return;
    }
  }

  void identifier(Token& t) {
    const std::size_t start = i_;
    while (is_alnum(peek())) advance();
    const std::string up = upper(src_.substr(start, i_ - start));
    if (peek() == '#') {
      std::string canonical;
      const PrefixClass pc = prefix_class(up, canonical);
      if (pc != PrefixClass::None) {
        advance();  // '#'
        t.type_prefix = canonical;
        switch (pc) {
          case PrefixClass::Number: return typed_number(t);
          case PrefixClass::Duration: return duration(t);
          case PrefixClass::Date: return date_time(t, TokenKind::Date);
          case PrefixClass::TimeOfDay: return date_time(t, TokenKind::TimeOfDay);
          case PrefixClass::DateAndTime: return date_time(t, TokenKind::DateAndTime);
          case PrefixClass::String:
            if (peek() == '\'' || peek() == '"') return string_literal(t, peek());
            t.kind = TokenKind::Error;
            error(t.loc, fmt::format("{}# must be followed by a string literal", canonical));
            return;
          case PrefixClass::None: break;
        }
      }
    }
    t.kind = keyword_kind(up);
  }

  // After INT#, REAL#, BOOL#, …: an optionally signed number, or TRUE/FALSE for BOOL.
  void typed_number(Token& t) {
    if (t.type_prefix == "BOOL" && is_alpha(peek())) {
      const std::size_t start = i_;
      while (is_alnum(peek())) advance();
      const std::string v = upper(src_.substr(start, i_ - start));
      t.kind = TokenKind::Integer;
      if (v == "TRUE" || v == "FALSE") {
        t.int_value = v == "TRUE";
      } else {
        t.kind = TokenKind::Error;
        error(t.loc, "BOOL# must be followed by TRUE, FALSE, 0 or 1");
      }
      return;
    }
    bool negative = false;
    if (peek() == '-' || peek() == '+') {
      negative = peek() == '-';
      advance();
    }
    if (!is_digit(peek())) {
      t.kind = TokenKind::Error;
      error(t.loc, fmt::format("{}# must be followed by a number", t.type_prefix));
      return;
    }
    number(t, negative);
  }

  void number(Token& t, bool negative) {
    const SourceLoc loc = here();
    const std::size_t start = i_;
    while (is_digit(peek()) || peek() == '_') advance();
    std::string_view digits = src_.substr(start, i_ - start);
    t.negative = negative;
    if (peek() == '#') {
      advance();
      return based_integer(t, loc, digits);
    }
    const bool fraction = peek() == '.' && is_digit(peek(1));
    const bool exponent_only = (peek() == 'e' || peek() == 'E') &&
                               (is_digit(peek(1)) || ((peek(1) == '+' || peek(1) == '-') && is_digit(peek(2))));
    if (fraction || exponent_only) {
      if (fraction) {
        advance();
        while (is_digit(peek()) || peek() == '_') advance();
      }
      if (peek() == 'e' || peek() == 'E') {
        advance();
        if (peek() == '+' || peek() == '-') advance();
        if (!is_digit(peek())) {
          t.kind = TokenKind::Error;
          error(loc, "bad REAL literal: no digits after the exponent's 'E'");
          return;
        }
        while (is_digit(peek()) || peek() == '_') advance();
      }
      t.kind = TokenKind::Real;
      const std::string_view text = src_.substr(start, i_ - start);
      if (!fraction) {
        t.kind = TokenKind::Error;
        error(loc, fmt::format("bad REAL literal '{}': IEC 61131-3 needs a '.' before the exponent (e.g. 1.0E3)", text));
        return;
      }
      if (trailing_letters(t, loc)) return;
      const std::string clean = without_underscores(text);
      // Each part between '.', 'E' must follow the underscore rule.
      bool ok = true;
      std::size_t p = 0;
      for (std::size_t q = 0; q <= text.size(); ++q)
        if (q == text.size() || text[q] == '.' || text[q] == 'e' || text[q] == 'E' || text[q] == '+' || text[q] == '-') {
          if (q > p && !underscores_ok(text.substr(p, q - p))) ok = false;
          p = q + 1;
        }
      double v = 0;
      const auto r = std::from_chars(clean.data(), clean.data() + clean.size(), v);
      if (!ok || r.ec != std::errc() || !std::isfinite(v)) {
        t.kind = TokenKind::Error;
        error(loc, fmt::format("bad REAL literal '{}'", text));
        return;
      }
      t.real_value = v;
      return;
    }
    t.kind = TokenKind::Integer;
    if (trailing_letters(t, loc)) return;
    if (!underscores_ok(digits)) {
      t.kind = TokenKind::Error;
      error(loc, fmt::format("bad integer literal '{}': an '_' goes only between digits", digits));
      return;
    }
    if (!to_integer(without_underscores(digits), 10, t.int_value)) {
      t.kind = TokenKind::Error;
      error(loc, fmt::format("integer literal '{}' does not fit in 64 bits", digits));
    }
  }

  // A number run into letters (5abc): one bad literal, not a number and a name.
  bool trailing_letters(Token& t, const SourceLoc& loc) {
    if (!is_alpha(peek())) return false;
    const std::size_t start = i_;
    while (is_alnum(peek())) advance();
    t.kind = TokenKind::Error;
    error(loc, fmt::format("bad number: '{}' right after its digits", src_.substr(start, i_ - start)));
    return true;
  }

  static bool to_integer(const std::string& digits, unsigned base, std::uint64_t& out) {
    std::uint64_t v = 0;
    for (char c : digits) {
      const auto d = static_cast<std::uint64_t>(hex_value(c));
      if (v > (std::numeric_limits<std::uint64_t>::max() - d) / base) return false;
      v = v * base + d;
    }
    out = v;
    return true;
  }

  void based_integer(Token& t, const SourceLoc& loc, std::string_view base_text) {
    const std::size_t start = i_;
    while (is_alnum(peek())) advance();
    const std::string_view digits = src_.substr(start, i_ - start);
    t.kind = TokenKind::Integer;
    if (base_text != "2" && base_text != "8" && base_text != "16") {
      t.kind = TokenKind::Error;
      error(loc, fmt::format("bad integer literal: base {} (IEC 61131-3 has 2#, 8# and 16#)", base_text));
      return;
    }
    const unsigned base = static_cast<unsigned>(std::stoi(std::string(base_text)));
    for (std::size_t k = 0; k < digits.size(); ++k)
      if (digits[k] != '_' && static_cast<unsigned>(hex_value(digits[k])) >= base) {
        t.kind = TokenKind::Error;
        error(at(start + k), fmt::format("digit '{}' is not a base-{} digit", digits[k], base));
        return;
      }
    if (!underscores_ok(digits)) {
      t.kind = TokenKind::Error;
      error(loc, digits.empty() ? fmt::format("bad integer literal: no digits after '{}#'", base)
                                : fmt::format("bad integer literal '{}#{}': an '_' goes only between digits", base, digits));
      return;
    }
    if (!to_integer(without_underscores(digits), base, t.int_value)) {
      t.kind = TokenKind::Error;
      error(loc, fmt::format("integer literal '{}#{}' does not fit in 64 bits", base, digits));
    }
  }

  // T#1d2h3m4s5ms6us7ns, T#-5ms, T#1.5s: components in falling order, a
  // fraction only on the last one.
  void duration(Token& t) {
    const SourceLoc loc = t.loc;
    t.kind = TokenKind::Duration;
    bool negative = false;
    if (peek() == '-' || peek() == '+') {
      negative = peek() == '-';
      advance();
    }
    const std::size_t start = i_;
    while (is_alnum(peek()) || (peek() == '.' && peek(1) != '.')) advance();
    const std::string_view text = src_.substr(start, i_ - start);
    const std::string_view literal = src_.substr(token_start_, i_ - token_start_);
    struct Unit {
      std::string_view name;
      long double ns;
    };
    static const std::array<Unit, 7> units = {{{"d", 86400e9L}, {"h", 3600e9L}, {"m", 60e9L}, {"s", 1e9L},
                                               {"ms", 1e6L}, {"us", 1e3L}, {"ns", 1.0L}}};
    long double total = 0;
    std::size_t p = 0;
    int last_unit = -1;
    bool fraction_seen = false;
    auto fail = [&](std::string msg) {
      t.kind = TokenKind::Error;
      error(loc, std::move(msg));
    };
    if (text.empty()) return fail(fmt::format("{}# must be followed by a duration (e.g. T#1s200ms)", t.type_prefix));
    while (p < text.size()) {
      if (text[p] == '_' && p > 0) ++p;  // T#1h_30m
      const std::size_t num_start = p;
      while (p < text.size() && (is_digit(text[p]) || text[p] == '_' || text[p] == '.')) ++p;
      const std::string_view num = text.substr(num_start, p - num_start);
      const std::size_t unit_start = p;
      while (p < text.size() && std::isalpha(static_cast<unsigned char>(text[p]))) ++p;
      const std::string unit_name = [&] {
        std::string u(text.substr(unit_start, p - unit_start));
        for (char& c : u) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
        return u;
      }();
      if (num.empty() || !is_digit(num.front()))
        return fail(fmt::format("bad duration '{}': a number must come before each unit", literal));
      int u = -1;
      for (std::size_t k = 0; k < units.size(); ++k)
        if (unit_name == units[k].name) u = static_cast<int>(k);
      if (u < 0)
        return fail(unit_name.empty()
                        ? fmt::format("bad duration '{}': '{}' has no unit (d, h, m, s, ms, us, ns)", literal, num)
                        : fmt::format("bad duration unit '{}' (d, h, m, s, ms, us, ns)", unit_name));
      if (u <= last_unit) return fail(fmt::format("bad duration '{}': units go from days down to nanoseconds, each once", literal));
      if (fraction_seen) return fail(fmt::format("bad duration '{}': only the last unit may have a fraction", literal));
      const std::string clean = without_underscores(num);
      const std::size_t dot = num.find('.');
      if (dot != std::string_view::npos) {
        fraction_seen = true;
        if (num.find('.', dot + 1) != std::string_view::npos || dot + 1 == num.size())
          return fail(fmt::format("bad duration '{}'", literal));
      }
      if (!underscores_ok(num.substr(0, dot)) ||
          (dot != std::string_view::npos && !underscores_ok(num.substr(dot + 1))))
        return fail(fmt::format("bad duration '{}': an '_' goes only between digits", literal));
      long double v = 0;
      double d = 0;
      if (std::from_chars(clean.data(), clean.data() + clean.size(), d).ec != std::errc())
        return fail(fmt::format("bad duration '{}'", literal));
      v = d;
      total += v * units[static_cast<std::size_t>(u)].ns;
      last_unit = u;
      if (total > 9.2e18L) return fail(fmt::format("duration '{}' does not fit in 64-bit nanoseconds", literal));
    }
    const auto ns = static_cast<std::int64_t>(std::llround(static_cast<double>(total)));
    t.duration_ns = negative ? -ns : ns;
  }

  // D#2024-01-31, TOD#12:30:00.5, DT#2024-01-31-12:30:00: the text after
  // '#' checked field by field and kept as written.
  void date_time(Token& t, TokenKind kind) {
    t.kind = kind;
    const std::size_t start = i_;
    while (is_digit(peek()) || peek() == '-' || peek() == ':' || peek() == '_' || (peek() == '.' && is_digit(peek(1))))
      advance();
    const std::string_view text = src_.substr(start, i_ - start);
    t.str_value = std::string(text);
    auto field = [&](std::string_view& s, char sep, int lo, int hi, bool last) -> bool {
      std::size_t e = last ? s.size() : s.find(sep);
      if (e == std::string_view::npos || e == 0) return false;
      int v = 0;
      const std::string_view f = s.substr(0, e);
      if (f.size() > 4) return false;
      for (char c : f) {
        if (!is_digit(c)) return false;
        v = v * 10 + (c - '0');
      }
      if (v < lo || v > hi) return false;
      s.remove_prefix(last ? e : e + 1);
      return true;
    };
    auto date_ok = [&](std::string_view& s, bool last) {
      return field(s, '-', 1, 9999, false) && field(s, '-', 1, 12, false) && field(s, '-', 1, 31, last);
    };
    auto tod_ok = [&](std::string_view s) {
      if (!field(s, ':', 0, 23, false) || !field(s, ':', 0, 59, false)) return false;
      const std::size_t dot = s.find('.');
      std::string_view sec = s.substr(0, dot);
      if (!field(sec, ':', 0, 60, true)) return false;
      if (dot == std::string_view::npos) return true;
      const std::string_view frac = s.substr(dot + 1);
      if (frac.empty() || frac.size() > 9) return false;
      for (char c : frac)
        if (!is_digit(c)) return false;
      return true;
    };
    bool ok = false;
    std::string_view s = text;
    if (kind == TokenKind::Date) {
      ok = date_ok(s, true) && s.empty();
    } else if (kind == TokenKind::TimeOfDay) {
      ok = tod_ok(s);
    } else {
      ok = date_ok(s, false) && tod_ok(s);
    }
    if (!ok) {
      static constexpr const char* forms[] = {"YYYY-MM-DD", "hh:mm:ss[.f]", "YYYY-MM-DD-hh:mm:ss[.f]"};
      const char* form = forms[kind == TokenKind::Date ? 0 : kind == TokenKind::TimeOfDay ? 1 : 2];
      t.kind = TokenKind::Error;
      error(t.loc, fmt::format("bad {} literal '{}' (expected {})", t.type_prefix, text, form));
    }
  }

  // '…' (STRING, $ escapes with two hex digits) and "…" (WSTRING, four).
  void string_literal(Token& t, char quote) {
    const bool wide = quote == '"';
    t.kind = wide ? TokenKind::WString : TokenKind::String;
    const SourceLoc loc = here();
    advance();
    std::string value;
    bool bad = false;
    for (;;) {
      const char c = peek();
      if (i_ >= src_.size() || c == '\n' || c == '\r') {
        t.kind = TokenKind::Error;
        error(loc, fmt::format("string not closed: {} missing before the end of the line", quote == '\'' ? "\"'\"" : "'\"'"));
        return;
      }
      if (c == quote) {
        advance();
        break;
      }
      if (c != '$') {
        value += c;
        advance();
        continue;
      }
      const SourceLoc esc = here();
      advance();
      const char e = peek();
      switch (std::toupper(static_cast<unsigned char>(e))) {
        case '$': value += '$'; advance(); continue;
        case '\'': value += '\''; advance(); continue;
        case '"': value += '"'; advance(); continue;
        case 'L': case 'N': value += '\n'; advance(); continue;
        case 'P': value += '\f'; advance(); continue;
        case 'R': value += '\r'; advance(); continue;
        case 'T': value += '\t'; advance(); continue;
        default: break;
      }
      const std::size_t n = wide ? 4 : 2;
      unsigned cp = 0;
      bool hex = true;
      for (std::size_t k = 0; k < n; ++k) {
        const int h = hex_value(peek(k));
        if (h > 15) hex = false;
        cp = cp * 16 + static_cast<unsigned>(h);
      }
      if (!hex) {
        error(esc, fmt::format("bad escape in a string: '${}' ($$, $', $\", $L, $N, $P, $R, $T or ${})",
                               e == '\n' || e == '\0' ? std::string() : std::string(1, e), wide ? "hhhh" : "hh"));
        bad = true;
        continue;
      }
      for (std::size_t k = 0; k < n; ++k) advance();
      if (wide) {
        append_utf8(value, cp);
      } else {
        value += static_cast<char>(cp);
      }
    }
    if (bad) t.kind = TokenKind::Error;
    t.str_value = std::move(value);
  }

  // %IX0.0, %QW4, %MD10, %I*: location, size and address checked here,
  // overlap and ranges later.
  void direct_address(Token& t) {
    const SourceLoc loc = here();
    advance();
    t.kind = TokenKind::DirectAddress;
    const std::size_t start = i_;
    while (is_alnum(peek()) || peek() == '*' || (peek() == '.' && is_digit(peek(1)))) advance();
    std::string_view s = src_.substr(start, i_ - start);
    bool ok = !s.empty() && std::string_view("IQMiqm").find(s[0]) != std::string_view::npos;
    if (ok) {
      s.remove_prefix(1);
      if (!s.empty() && std::string_view("XBWDLxbwdl").find(s[0]) != std::string_view::npos) s.remove_prefix(1);
      if (s == "*") {
        ok = true;
      } else {
        bool digit_seen = false;
        for (std::size_t k = 0; k < s.size() && ok; ++k) {
          if (is_digit(s[k])) {
            digit_seen = true;
          } else if (s[k] != '.' || !digit_seen || k + 1 == s.size()) {
            ok = false;
          } else {
            digit_seen = false;
          }
        }
        ok = ok && digit_seen;
      }
    }
    if (!ok) {
      t.kind = TokenKind::Error;
      error(loc, fmt::format("bad direct address '%{}' (e.g. %IX0.0, %QW4, %MD10, %I*)", src_.substr(start, i_ - start)));
    }
  }

  void pragma(Token& t) {
    const SourceLoc loc = here();
    advance();
    const std::size_t start = i_;
    while (i_ < src_.size() && peek() != '}') advance();
    if (i_ >= src_.size()) {
      t.kind = TokenKind::Error;
      error(loc, "pragma '{' is not closed by '}'");
      return;
    }
    t.kind = TokenKind::Pragma;
    t.str_value = std::string(src_.substr(start, i_ - start));
    advance();
  }

  std::string_view src_;
  SourceFile file_;
  StDiagnostics& diags_;
  std::size_t i_ = 0;
  std::size_t token_start_ = 0;  // where the token being scanned starts (for messages)
  int line_ = 1;
  std::size_t line_start_ = 0;
  std::string pending_comment_;
  int pending_start_line_ = 0;  // first and last line of the pending comment group
  int pending_end_line_ = 0;
  int last_token_line_ = 0;  // the line the previous token ended on (0: none yet)
};

}  // namespace

std::vector<Token> lex(std::string_view source, const SourceFile& file, StDiagnostics& diagnostics) {
  return Lexer(source, file, diagnostics).run();
}

}  // namespace syncplc::st
