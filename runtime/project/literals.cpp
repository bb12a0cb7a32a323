// Helpers shared by the stages of a load: names, seeds, literal values and
// tag types as written in a project file.
#include <algorithm>
#include <cctype>
#include <charconv>

#include "runtime/core/sim_random.hpp"
#include "runtime/core/units.hpp"
#include "runtime/project/stages.hpp"

namespace syncplc {
namespace {

// A whole number, optionally signed, with spaces around it; false when it
// does not fit 64 bits.
bool parse_bound(const std::string& text, std::int64_t& out) {
  std::size_t b = text.find_first_not_of(' '), e = text.find_last_not_of(' ');
  if (b == std::string::npos) return false;
  const char* first = text.data() + b;
  const char* last = text.data() + e + 1;
  if (*first == '+') ++first;
  auto [p, ec] = std::from_chars(first, last, out);
  return ec == std::errc() && p == last;
}

}  // namespace

bool is_identifier(const std::string& s) {
  if (s.empty() || !(std::isalpha(static_cast<unsigned char>(s[0])) || s[0] == '_')) return false;
  return std::all_of(s.begin(), s.end(), [](char c) { return std::isalnum(static_cast<unsigned char>(c)) || c == '_'; });
}

std::uint64_t mix_seed(std::uint64_t seed, const std::string& name) {
  // FNV-1a over the name, then a splitmix64 finaliser with the seed.
  std::uint64_t z = fnv1a64(name) + seed * 0x9E3779B97F4A7C15ULL;
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
  return z ^ (z >> 31);
}

std::optional<Cell> parse_literal(IecType t, const std::string& unit, const std::string& text, const SourceLoc& loc,
                                  const std::string& what, Diagnostics& diags) {
  std::string err;
  if (is_real(t)) {
    auto v = parse_quantity(text, unit, &err);
    std::optional<Cell> c;
    if (v) c = real_cell(t, *v, text, &err);
    if (!c) diags.error(loc, what + ": " + err);
    return c;
  }
  auto c = parse_value(t, text, &err);
  if (!c) diags.error(loc, what + ": " + err);
  return c;
}

std::vector<Cell> parse_tag_values(const Tag& t, const ConfigNode& n, const std::string& what, Diagnostics& diags) {
  std::vector<Cell> out;
  if (n.is_scalar()) {
    auto c = parse_literal(t.type, t.unit, n.scalar, n.loc, what + " of " + t.name, diags);
    if (c) out.assign(t.length, *c);
  } else if (n.is_list()) {
    if (n.items.size() != t.length) {
      diags.error(n.loc, what + " of " + t.name + ": " + std::to_string(n.items.size()) + " values for " +
                          std::to_string(t.length) + " elements");
      return out;
    }
    for (const auto& i : n.items) {
      auto c = parse_literal(t.type, t.unit, i.scalar, i.loc, what + " of " + t.name, diags);
      if (!c) return {};
      out.push_back(*c);
    }
  } else {
    diags.error(n.loc, what + " of " + t.name + ": expected a value or a list of values");
  }
  return out;
}

bool parse_tag_type(const std::string& s, IecType& t, std::uint32_t& len, std::int64_t& lower, bool& is_array,
                    std::string& err) {
  std::string u;
  for (char c : s) u += static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  is_array = false;
  len = 1;
  lower = 0;
  if (u.rfind("ARRAY", 0) == 0) {
    auto lb = u.find('['), dots = u.find(".."), rb = u.find(']'), of = u.find(" OF ");
    if (lb == std::string::npos || dots == std::string::npos || rb == std::string::npos || of == std::string::npos ||
        !(lb < dots && dots < rb && rb < of)) {
      err = "bad array type '" + s + "' (write ARRAY[0..3] OF LREAL)";
      return false;
    }
    std::int64_t lo = 0, hi = 0, span = 0;
    if (!parse_bound(u.substr(lb + 1, dots - lb - 1), lo) || !parse_bound(u.substr(dots + 2, rb - dots - 2), hi)) {
      err = "bad array bounds in '" + s + "' (whole numbers that fit 64 bits)";
      return false;
    }
    // hi - lo overflows for bounds far apart (ARRAY[-2^63..2^63-1] once gave 0 cells).
    if (hi < lo || __builtin_sub_overflow(hi, lo, &span) || span >= 65536) {
      err = "array bounds of '" + s + "' must give 1..65536 elements";
      return false;
    }
    len = static_cast<std::uint32_t>(span + 1);
    lower = lo;
    is_array = true;
    auto et = parse_type_name(u.substr(of + 4));
    if (!et) {
      err = "unknown element type in '" + s + "'";
      return false;
    }
    t = *et;
    return true;
  }
  auto et = parse_type_name(u);
  if (!et) {
    err = "unknown IEC type '" + s + "' (BOOL, SINT, INT, DINT, LINT, USINT, UINT, UDINT, ULINT, BYTE, WORD, DWORD, LWORD, REAL, LREAL, TIME or ARRAY[a..b] OF type)";
    return false;
  }
  t = *et;
  return true;
}

}  // namespace syncplc
