#include "runtime/core/units.hpp"

#include <cctype>
#include <charconv>
#include <cmath>
#include <numbers>

namespace syncplc {
namespace {

enum Dim { M, S, RAD, KG, AMP, VOLT, KELVIN, PWM, COUNT };

struct Named {
  std::string_view name;
  double scale;
  Dim dim;
  int power;
};

constexpr double kPi = std::numbers::pi;
// Units that are not dimensionless multiples; "1" and "%" are handled apart.
constexpr Named kUnits[] = {
    {"m", 1, M, 1},        {"mm", 1e-3, M, 1},     {"um", 1e-6, M, 1},      {"cm", 1e-2, M, 1},
    {"km", 1e3, M, 1},     {"nm", 1e-9, M, 1},     {"in", 0.0254, M, 1},
    {"s", 1, S, 1},        {"ms", 1e-3, S, 1},     {"us", 1e-6, S, 1},      {"ns", 1e-9, S, 1},
    {"min", 60, S, 1},     {"h", 3600, S, 1},
    {"Hz", 1, S, -1},      {"kHz", 1e3, S, -1},
    {"rad", 1, RAD, 1},    {"mrad", 1e-3, RAD, 1}, {"deg", kPi / 180, RAD, 1}, {"rev", 2 * kPi, RAD, 1},
    {"kg", 1, KG, 1},      {"g", 1e-3, KG, 1},
    {"A", 1, AMP, 1},      {"mA", 1e-3, AMP, 1},
    {"V", 1, VOLT, 1},     {"mV", 1e-3, VOLT, 1},
    {"K", 1, KELVIN, 1},
    {"PWM", 1, PWM, 1},
    {"count", 1, COUNT, 1}, {"counts", 1, COUNT, 1}, {"inc", 1, COUNT, 1},
};

struct Parser {
  std::string_view s;
  std::size_t i = 0;
  std::string err{};

  void skip() {
    while (i < s.size() && std::isspace(static_cast<unsigned char>(s[i]))) ++i;
  }
  bool atom(Unit& u) {
    skip();
    if (i < s.size() && s[i] == '(') {
      ++i;
      if (!expr(u)) return false;
      skip();
      if (i >= s.size() || s[i] != ')') return fail("missing ')'");
      ++i;
      return true;
    }
    std::size_t j = i;
    if (j < s.size() && (s[j] == '%' || s[j] == '1')) ++j;
    else
      while (j < s.size() && std::isalpha(static_cast<unsigned char>(s[j]))) ++j;
    std::string_view name = s.substr(i, j - i);
    if (name.empty()) return fail("expected a unit name");
    i = j;
    u = Unit{};
    if (name == "1") return true;
    if (name == "%") { u.scale = 0.01; return true; }
    for (const auto& n : kUnits)
      if (n.name == name) {
        u.scale = n.scale;
        u.dim[n.dim] = n.power;
        return true;
      }
    return fail("unknown unit '" + std::string(name) + "'");
  }
  bool term(Unit& u) {
    if (!atom(u)) return false;
    skip();
    if (i < s.size() && s[i] == '^') {
      ++i;
      skip();
      int p = 0;
      bool neg = i < s.size() && s[i] == '-';
      if (neg) ++i;
      auto [q, ec] = std::from_chars(s.data() + i, s.data() + s.size(), p);
      if (ec != std::errc() || p < 1 || p > 4) return fail("bad exponent");
      i = static_cast<std::size_t>(q - s.data());
      if (neg) p = -p;
      Unit r;
      r.scale = std::pow(u.scale, p);
      for (int d = 0; d < 9; ++d) r.dim[static_cast<std::size_t>(d)] = u.dim[static_cast<std::size_t>(d)] * p;
      u = r;
    }
    return true;
  }
  bool expr(Unit& u) {
    if (!term(u)) return false;
    for (;;) {
      skip();
      if (i >= s.size() || (s[i] != '*' && s[i] != '/' && s[i] != '.')) return true;
      char op = s[i++];
      Unit r;
      if (!term(r)) return false;
      if (op == '/') {
        u.scale /= r.scale;
        for (std::size_t d = 0; d < 9; ++d) u.dim[d] -= r.dim[d];
      } else {
        u.scale *= r.scale;
        for (std::size_t d = 0; d < 9; ++d) u.dim[d] += r.dim[d];
      }
    }
  }
  bool fail(std::string m) {
    if (err.empty()) err = std::move(m);
    return false;
  }
};

}  // namespace

std::optional<Unit> parse_unit(std::string_view text, std::string* error) {
  Parser p{text};
  Unit u;
  p.skip();
  if (p.i >= text.size()) return Unit{};
  if (!p.expr(u) || (p.skip(), p.i != text.size())) {
    if (error) {
      *error = "bad unit '" + std::string(text) + "': " + (p.err.empty() ? "unexpected text" : p.err);
      // A power written without ^ (m/s2): suggest the spelling that parses.
      std::string fixed;
      for (std::size_t k = 0; k < text.size(); ++k) {
        if (k > 0 && std::isdigit(static_cast<unsigned char>(text[k])) && std::isalpha(static_cast<unsigned char>(text[k - 1])))
          fixed += '^';
        fixed += text[k];
      }
      if (fixed != text && parse_unit(fixed, nullptr)) *error += " (powers are written with ^: '" + fixed + "')";
    }
    return std::nullopt;
  }
  return u;
}

void split_quantity(std::string_view text, std::string& number, std::string& unit) {
  std::size_t b = 0;
  while (b < text.size() && std::isspace(static_cast<unsigned char>(text[b]))) ++b;
  std::size_t i = b;
  if (i < text.size() && (text[i] == '+' || text[i] == '-')) ++i;
  while (i < text.size()) {
    char c = text[i];
    if (std::isdigit(static_cast<unsigned char>(c)) || c == '.' || c == '_') { ++i; continue; }
    if ((c == 'e' || c == 'E') && i + 1 < text.size() &&
        (std::isdigit(static_cast<unsigned char>(text[i + 1])) || text[i + 1] == '-' || text[i + 1] == '+')) {
      i += 2;
      continue;
    }
    break;
  }
  number = std::string(text.substr(b, i - b));
  std::string_view u = text.substr(i);
  while (!u.empty() && std::isspace(static_cast<unsigned char>(u.front()))) u.remove_prefix(1);
  while (!u.empty() && std::isspace(static_cast<unsigned char>(u.back()))) u.remove_suffix(1);
  unit = std::string(u);
}

std::optional<Cell> parse_value_in_unit(IecType t, std::string_view unit, std::string_view text, std::string* error) {
  if (is_real(t)) {
    auto v = parse_quantity(text, unit, error);
    if (!v) return std::nullopt;
    return real_cell(t, *v, text, error);
  }
  return parse_value(t, text, error);
}

std::optional<double> parse_quantity(std::string_view text, std::string_view target, std::string* error) {
  std::string num, unit;
  split_quantity(text, num, unit);
  std::string clean;
  for (char c : num)
    if (c != '_') clean += c;
  double v = 0;
  const char* b = clean.data();
  if (!clean.empty() && *b == '+') ++b;
  auto [p, ec] = std::from_chars(b, clean.data() + clean.size(), v);
  if (clean.empty() || ec != std::errc() || p != clean.data() + clean.size() || !std::isfinite(v)) {
    if (error) *error = "'" + std::string(text) + "' is not a number";
    return std::nullopt;
  }
  if (unit.empty()) return v;
  auto given = parse_unit(unit, error);
  if (!given) return std::nullopt;
  auto want = parse_unit(target, error);
  if (!want) return std::nullopt;
  if (!given->same_dimension(*want)) {
    if (error)
      *error = target.empty() ? "'" + std::string(text) + "' has a unit but the value is dimensionless"
                              : "unit '" + unit + "' is not compatible with '" + std::string(target) + "'";
    return std::nullopt;
  }
  return v * given->scale / want->scale;
}

UnitCopy unit_copy(std::string_view a, std::string_view b) {
  if (a.empty() || b.empty() || a == b) return UnitCopy::Fits;
  auto ua = parse_unit(a, nullptr), ub = parse_unit(b, nullptr);
  if (!ua || !ub) return UnitCopy::Fits;
  if (!ua->same_dimension(*ub)) return UnitCopy::OtherDimension;
  if (std::fabs(ua->scale - ub->scale) <= 1e-12 * std::fabs(ub->scale)) return UnitCopy::Fits;
  return UnitCopy::OtherScale;
}

}  // namespace syncplc
