#include "runtime/io/driver_config.hpp"

#include <algorithm>
#include <cmath>

#include "runtime/core/iec_type.hpp"
#include "runtime/core/units.hpp"

namespace syncplc {
namespace {

std::string fmt_num(double d) {
  char b[32];
  std::snprintf(b, sizeof b, "%g", d);
  return b;
}

}  // namespace

DriverConfig::DriverConfig(const ConfigNode& cfg, DriverSetup& setup, std::string driver_type,
                           std::vector<std::string> keys)
    : DriverConfig(cfg, setup, std::move(driver_type), keys, false) {}

DriverConfig DriverConfig::section(const ConfigNode& cfg, DriverSetup& setup, std::string section,
                                   std::vector<std::string> keys) {
  return DriverConfig(cfg, setup, std::move(section), keys, true);
}

DriverConfig::DriverConfig(const ConfigNode& cfg, DriverSetup& setup, std::string name,
                           const std::vector<std::string>& keys, bool section)
    : cfg_(cfg), setup_(setup), type_(std::move(name)) {
  for (const auto& [k, v] : cfg.map) {
    if (!section && (k == "name" || k == "type" || k == "task" || k == "bind")) continue;
    if (std::find(keys.begin(), keys.end(), k) != keys.end()) continue;
    std::string list;
    for (const auto& x : keys) list += (list.empty() ? "" : ", ") + x;
    if (section) error(v.loc, "unknown key '" + k + "' in " + type_ + " (" + list + ")");
    else error(v.loc, "unknown key '" + k + "' for a " + type_ + " driver (" + list + ", bind)");
  }
}

void DriverConfig::error(const SourceLoc& where, const std::string& message) {
  ok_ = false;
  setup_.error(where, message);
}

double DriverConfig::number_at(const ConfigNode& n, const std::string& what, const std::string& unit,
                               std::optional<double> min, std::optional<double> max) {
  if (!n.is_scalar()) {
    error(n.loc, what + ": expected a number" + (unit.empty() ? "" : " (in " + unit + " or a compatible unit)"));
    return NAN;
  }
  std::string err;
  auto v = parse_quantity(n.scalar, unit, &err);
  if (!v || !std::isfinite(*v)) {
    error(n.loc, what + ": " + (err.empty() ? "'" + n.scalar + "' is not a finite number" : err));
    return NAN;
  }
  if ((min && *v < *min) || (max && *v > *max)) {
    error(n.loc, what + " = " + n.scalar + " is outside " + (min ? fmt_num(*min) : "-inf") + " .. " +
                     (max ? fmt_num(*max) : "inf") + (unit.empty() ? "" : " " + unit));
    return NAN;
  }
  return *v;
}

double DriverConfig::number(const std::string& key, const std::string& unit, double def, std::optional<double> min,
                            std::optional<double> max) {
  const ConfigNode* n = cfg_.find(key);
  if (!n) return def;
  double v = number_at(*n, key, unit, min, max);
  return std::isnan(v) ? def : v;
}

std::vector<double> DriverConfig::numbers(const std::string& key, const std::string& unit, std::size_t count,
                                          const std::vector<double>& defs, std::optional<double> min,
                                          std::optional<double> max) {
  std::vector<double> out = defs;
  out.resize(count, defs.empty() ? 0.0 : defs.back());
  const ConfigNode* n = cfg_.find(key);
  if (!n) return out;
  if (n->is_scalar()) {
    double v = number_at(*n, key, unit, min, max);
    if (!std::isnan(v)) std::fill(out.begin(), out.end(), v);
    return out;
  }
  if (!n->is_list() || n->items.size() != count) {
    error(n->loc, key + ": expected one value for every axis or a list of " + std::to_string(count));
    return out;
  }
  for (std::size_t i = 0; i < count; ++i) {
    double v = number_at(n->items[i], key + "[" + std::to_string(i + 1) + "]", unit, min, max);
    if (!std::isnan(v)) out[i] = v;
  }
  return out;
}

std::int64_t DriverConfig::integer(const std::string& key, std::int64_t def, std::int64_t min, std::int64_t max) {
  const ConfigNode* n = cfg_.find(key);
  if (!n) return def;
  try {
    std::size_t used = 0;
    long long v = n->is_scalar() ? std::stoll(n->scalar, &used) : 0;
    if (!n->is_scalar() || used != n->scalar.size()) throw std::invalid_argument(key);
    if (v < min || v > max) throw std::out_of_range(key);
    return v;
  } catch (...) {
    error(n->loc, key + " must be an integer " + std::to_string(min) + ".." + std::to_string(max));
    return def;
  }
}

std::int64_t DriverConfig::duration_at(const ConfigNode& n, const std::string& what) {
  std::string err;
  auto v = n.is_scalar() ? parse_duration_ns(n.scalar, &err) : std::nullopt;
  if (!v) {
    error(n.loc, what + ": '" + n.scalar + "' is not a duration" + (err.empty() ? "" : " (" + err + ")"));
    return -1;
  }
  return *v;
}

std::int64_t DriverConfig::duration_ns(const std::string& key, std::int64_t def, std::int64_t min, std::int64_t max) {
  const ConfigNode* n = cfg_.find(key);
  if (!n) return def;
  // Parsed here, not by duration_at: its -1 for "not a duration" would make
  // a negative duration look like no value and pass silently.
  std::string err;
  const auto v = n->is_scalar() ? parse_duration_ns(n->scalar, &err) : std::nullopt;
  if (!v) {
    error(n->loc, key + ": '" + n->scalar + "' is not a duration" + (err.empty() ? "" : " (" + err + ")"));
    return def;
  }
  if (*v < min || *v > max) {
    error(n->loc, key + " " + n->scalar + (*v < 0 ? " is negative; it must be within " : " is outside ") +
                      format_duration(min) + " .. " + format_duration(max));
    return def;
  }
  return *v;
}

bool DriverConfig::boolean(const std::string& key, bool def) {
  const ConfigNode* n = cfg_.find(key);
  if (!n) return def;
  std::string s = n->scalar;
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return std::tolower(c); });
  if (s == "true" || s == "on" || s == "yes") return true;
  if (s == "false" || s == "off" || s == "no") return false;
  error(n->loc, key + " must be true or false, not '" + n->scalar + "'");
  return def;
}

std::string DriverConfig::choice(const std::string& key, const std::vector<std::string>& options, const std::string& def) {
  const ConfigNode* n = cfg_.find(key);
  if (!n) return def;
  if (n->is_scalar() && std::find(options.begin(), options.end(), n->scalar) != options.end()) return n->scalar;
  std::string list;
  for (const auto& o : options) list += (list.empty() ? "" : ", ") + o;
  error(n->loc, key + " must be one of " + list + ", not '" + n->scalar + "'");
  return def;
}

}  // namespace syncplc
