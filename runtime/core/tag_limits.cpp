#include "runtime/core/tag_limits.hpp"

#include <cmath>

#include "runtime/core/iec_type.hpp"

namespace syncplc {

bool within_limits(const Tag& t, Cell v) noexcept {
  if (!t.min && !t.max) return true;
  const double x = cell_as_double(t.type, v);
  return !std::isnan(x) && !(t.min && x < *t.min) && !(t.max && x > *t.max);
}

std::string outside_limits(const Tag& t, Cell v) {
  if (within_limits(t, v)) return "";
  const double x = cell_as_double(t.type, v);
  const std::string unit = t.unit.empty() ? "" : " " + t.unit;
  auto text = [](double d) {
    Cell c;
    c.set(d);
    return format_value(IecType::LREAL, c);
  };
  if (std::isnan(x)) return "NaN is outside " + t.name + "'s engineering limits";
  if (t.min && x < *t.min)
    return format_value(t.type, v) + unit + " is below " + t.name + "'s min " + text(*t.min) + unit + " (its engineering limit)";
  if (t.max && x > *t.max)
    return format_value(t.type, v) + unit + " is above " + t.name + "'s max " + text(*t.max) + unit + " (its engineering limit)";
  return "";
}

}  // namespace syncplc
