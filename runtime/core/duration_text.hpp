// A duration's text, read and written without allocation: the one reading
// of "T#1m30s", "250us", "-1.5s" for project files (parse_duration_ns,
// iec_type.hpp) and for Structured Text's STRING_TO_TIME, and the one
// writing for format_duration and TIME_TO_STRING.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string_view>

namespace syncplc {

enum class DurationFault : std::uint8_t {
  None,
  Empty,          // nothing after the prefix
  MissingNumber,  // a unit (or anything) where a number belongs
  BadNumber,      // "1.5.2"
  MissingUnit,    // "10"
  SpacedUnit,     // "10 ms": the unit is there, after a space a duration may not have
  UnknownUnit,    // "5q"
  UnitOrder,      // "1s1m": units go from largest to smallest
  TooLong,        // past TIME's range
};

struct DurationScan {
  std::int64_t ns = 0;  // the duration; for TooLong the limit of its sign
  DurationFault fault = DurationFault::None;
  std::string_view number;  // the number at fault, as written (BadNumber, MissingUnit, SpacedUnit)
  std::string_view unit;    // UnknownUnit: the unit; SpacedUnit: the word after the space
};

// Reads `text`: blanks around it, an optional T#, TIME#, LT# or LTIME#
// prefix (any case), a sign, then number-unit pairs (d, h, m or min, s, ms,
// us, ns; numbers may have a fraction), largest unit first, underscores
// anywhere after the prefix ignored; rounded to the nearest nanosecond. A
// number of more than 64 characters is refused (BadNumber).
DurationScan scan_duration(std::string_view text) noexcept;

// Room write_duration needs: "-2562047h47m16s854ms775us808ns".
inline constexpr std::size_t kDurationTextMax = 32;

// Writes the shortest exact text of ns, without a prefix ("1h2m3s4ms",
// "250us", "-5s", "0ms") at p; returns the end.
char* write_duration(char* p, std::int64_t ns) noexcept;

}  // namespace syncplc
