// A block parameter's value against its declared range (ParamDecl::min,
// max), and an array pin's length against its bounds: the one check and the
// one message, for the YAML loader's `params:` (runtime/project/
// check_params.cpp) and ST's built-in block declarations (runtime/st/
// check_blocks.cpp), so both say the same of the same mistake.
// Header-only: the ST front end links nothing of the core.
#pragma once

#include <cstdint>
#include <cstdio>
#include <optional>
#include <string>
#include <string_view>

namespace syncplc {

// "" when x is within [min, max] (an absent bound is open); otherwise
// "<what> = <text> is outside its range <min> .. <max> <unit>".
inline std::string param_range_error(std::string_view what, std::string_view text, double x, std::optional<double> min,
                                     std::optional<double> max, std::string_view unit) {
  if (!(min && x < *min) && !(max && x > *max)) return "";
  auto fmt = [](double d) {
    char b[32];
    std::snprintf(b, sizeof b, "%g", d);
    return std::string(b);
  };
  return std::string(what) + " = " + std::string(text) + " is outside its range " + (min ? fmt(*min) : "-inf") +
         " .. " + (max ? fmt(*max) : "inf") + (unit.empty() ? "" : " " + std::string(unit));
}

// "" when an array pin may have `len` elements (1 .. max_length); otherwise
// "<what> = <text>: array pin <pin> needs 1..<max_length> elements", what
// naming the length parameter.
inline std::string pin_length_error(std::string_view what, std::string_view text, double len, std::string_view pin,
                                    std::uint32_t max_length) {
  if (len >= 1 && len <= max_length) return "";
  return std::string(what) + " = " + std::string(text) + ": array pin " + std::string(pin) + " needs 1.." +
         std::to_string(max_length) + " elements";
}

}  // namespace syncplc
