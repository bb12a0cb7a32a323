#include "runtime/project/store_section.hpp"

#include <cctype>
#include <cmath>
#include <limits>

namespace syncplc {
namespace {

const char* const kStoreKeys =
    "path, retain_interval, events_max_count, events_max_age, trend_raw_age, trend_downsample, trend_max_age, trend_max_size";

// A positive duration setting.
void read_duration(const ConfigNode& v, const std::string& what, std::int64_t min_ns, std::int64_t& out, Diagnostics& d) {
  std::string err;
  auto ns = v.is_scalar() ? parse_duration_ns(v.scalar, &err) : std::nullopt;
  if (!ns) d.error(v.loc, "store " + what + ": " + (err.empty() ? "expected a duration such as 1s" : err));
  else if (*ns < min_ns)
    d.error(v.loc, "store " + what + " " + v.scalar + " is below its least value " + format_duration(min_ns));
  else out = *ns;
}

}  // namespace

std::optional<std::uint64_t> parse_byte_size(const std::string& text, std::string* error) {
  std::size_t i = 0;
  while (i < text.size() && std::isdigit(static_cast<unsigned char>(text[i]))) ++i;
  if (i == 0) {
    *error = "'" + text + "' is not a size (write e.g. 512MB or 1GiB)";
    return std::nullopt;
  }
  std::string unit = text.substr(i);
  while (!unit.empty() && unit.front() == ' ') unit.erase(unit.begin());
  struct U {
    const char* name;
    std::uint64_t factor;
  };
  static constexpr U kUnits[] = {{"", 1},          {"B", 1},
                                 {"kB", 1000},     {"KB", 1000},         {"MB", 1000'000},         {"GB", 1000'000'000},
                                 {"TB", 1000'000'000'000}, {"KiB", 1ULL << 10}, {"MiB", 1ULL << 20},
                                 {"GiB", 1ULL << 30},      {"TiB", 1ULL << 40}};
  for (const auto& u : kUnits) {
    if (unit != u.name) continue;
    const std::string digits = text.substr(0, i);
    if (digits.size() > 19) break;
    const std::uint64_t n = std::stoull(digits);
    if (n > std::numeric_limits<std::uint64_t>::max() / u.factor) break;
    return n * u.factor;
  }
  *error = "'" + text + "' is not a size (a whole number with B, kB, MB, GB, TB, KiB, MiB, GiB or TiB)";
  return std::nullopt;
}

void read_store_section(const ConfigNode& n, store::StoreSettings& out, Diagnostics& d) {
  out.declared = true;
  if (n.is_scalar() && n.scalar.empty()) return;  // `store:` alone: the defaults
  if (!n.is_map()) {
    d.error(n.loc, std::string("store: expected a map (") + kStoreKeys + ")");
    return;
  }
  for (const auto& [k, v] : n.map) {
    if (k == "path") {
      if (!v.is_scalar() || v.scalar.empty()) d.error(v.loc, "store path: expected a file name");
      else out.path = v.scalar;
    } else if (k == "retain_interval") {
      read_duration(v, k, 10'000'000, out.retain_interval_ns, d);  // 10 ms: each cycle is a transaction
    } else if (k == "events_max_count") {
      std::string err;
      auto c = v.is_scalar() ? parse_value(IecType::ULINT, v.scalar, &err) : std::nullopt;
      if (!c || c->get<std::uint64_t>() < 100)
        d.error(v.loc, "store events_max_count must be a whole number of at least 100" +
                           (v.is_scalar() ? ", not '" + v.scalar + "'" : std::string()));
      else out.events_max_count = c->get<std::uint64_t>();
    } else if (k == "events_max_age") {
      read_duration(v, k, 60'000'000'000, out.events_max_age_ns, d);
    } else if (k == "trend_raw_age") {
      read_duration(v, k, 1'000'000'000, out.trend_raw_age_ns, d);
    } else if (k == "trend_downsample") {
      read_duration(v, k, 1'000'000'000, out.trend_downsample_ns, d);
    } else if (k == "trend_max_age") {
      read_duration(v, k, 60'000'000'000, out.trend_max_age_ns, d);
    } else if (k == "trend_max_size") {
      std::string err;
      auto b = v.is_scalar() ? parse_byte_size(v.scalar, &err) : std::nullopt;
      if (!b) d.error(v.loc, "store trend_max_size: " + (err.empty() ? "expected a size such as 512MB" : err));
      else if (*b < (1ULL << 20)) d.error(v.loc, "store trend_max_size " + v.scalar + " is below 1MiB");
      else out.trend_max_bytes = *b;
    } else {
      d.error(v.loc, "unknown key '" + k + "' in store (" + kStoreKeys + ")");
    }
  }
  if (out.trend_raw_age_ns > out.trend_max_age_ns)
    d.error(n.loc, "store: trend_raw_age is longer than trend_max_age");
}

std::optional<store::TrendSpec> read_trend(const ConfigNode& n, const Tag& tag, Diagnostics& d) {
  const bool numeric = is_real(tag.type) || tag.type == IecType::BOOL || in_class(tag.type, TypeClass::ANY_INT) ||
                       tag.type == IecType::TIME;
  store::TrendSpec spec;
  if (n.is_scalar()) {
    std::string err;
    auto c = parse_value(IecType::BOOL, n.scalar, &err);
    if (!c) {
      d.error(n.loc, "trend: expected true, false or {rate, deadband}");
      return std::nullopt;
    }
    if (!c->get<bool>()) return std::nullopt;
  } else if (n.is_map()) {
    for (const auto& [k, v] : n.map) {
      if (k == "rate") {
        std::string err;
        auto ns = v.is_scalar() ? parse_duration_ns(v.scalar, &err) : std::nullopt;
        if (!ns || *ns < 0) d.error(v.loc, "trend rate: " + (err.empty() ? "expected a duration such as 100ms (0: every scan)" : err));
        else spec.rate_ns = *ns;
      } else if (k == "deadband") {
        std::string err;
        auto c = v.is_scalar() ? parse_value(IecType::LREAL, v.scalar, &err) : std::nullopt;
        if (!c || !std::isfinite(c->get<double>()) || c->get<double>() < 0)
          d.error(v.loc, "trend deadband: expected a number >= 0" + (v.is_scalar() ? ", not '" + v.scalar + "'" : std::string()));
        else spec.deadband = c->get<double>();
      } else {
        d.error(v.loc, "unknown key '" + k + "' in trend (rate, deadband)");
      }
    }
  } else {
    d.error(n.loc, "trend: expected true, false or {rate, deadband}");
    return std::nullopt;
  }
  if (!numeric) {
    d.error(n.loc, "tag " + tag.name + " is " + std::string(type_name(tag.type)) +
                       ": only numeric, BOOL and TIME tags can be trended");
    return std::nullopt;
  }
  return spec;
}

}  // namespace syncplc
