// Physical units of parameters, pins and tags: "m/s^2", "rad/min", "mm",
// "(rad/s)/PWM". A value written with a unit ("3000 mm/min") is converted to
// the unit the parameter declares ("m/s"); a unit of another dimension is an
// error. Dimensions: length, time, angle, mass, current, voltage, temperature,
// and two counted quantities of motion control, PWM duty and encoder counts.
#pragma once

#include <array>
#include <optional>
#include <string>
#include <string_view>

#include "runtime/core/iec_type.hpp"

namespace syncplc {

struct Unit {
  double scale = 1.0;            // value in SI base units = value × scale
  std::array<int, 9> dim{};      // exponents: m s rad kg A V K PWM count
  bool same_dimension(const Unit& o) const { return dim == o.dim; }
};

std::optional<Unit> parse_unit(std::string_view text, std::string* error);

// Parses "12.5", "12.5 mm/s" or "12.5mm/s" as a value in `target` unit.
// Without a unit the number is taken in `target`.
std::optional<double> parse_quantity(std::string_view text, std::string_view target, std::string* error);

// Whether a value in unit `a` may be copied as it is into unit `b` (a
// connection, a driver channel bound to a tag): Fits when the units are
// equal, either end has none, or one does not parse (that is reported where
// it is declared); otherwise another dimension, or the same one at another
// scale (mm into m: off by 1000).
enum class UnitCopy { Fits, OtherDimension, OtherScale };
UnitCopy unit_copy(std::string_view a, std::string_view b);

// A value of type t as users write it for an element whose unit is `unit`:
// REAL and LREAL as quantities ("1.5", "1500 mm" into m), every other type
// as an IEC literal (parse_value). The one parser of written values: project
// files, scan-cycle tests, forces.
std::optional<Cell> parse_value_in_unit(IecType t, std::string_view unit, std::string_view text, std::string* error);

// Splits "12.5 mm/s" into number text and unit text (either may be empty).
void split_quantity(std::string_view text, std::string& number, std::string& unit);

}  // namespace syncplc
