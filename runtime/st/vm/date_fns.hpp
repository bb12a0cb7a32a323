// The date functions of IEC 61131-3 (3rd edition, table 36) the VM calls
// through DATEFN (code.hpp): a DATE, TOD or DT from its fields, and a date's
// day of the week, on the runtime's representation (signed nanoseconds since
// 1970-01-01 00:00 UTC, or since midnight), through the standard library's
// proleptic Gregorian calendar (<chrono>). Every input has a defined result:
// fields out of their range, or a date DATE does not hold (before
// 1677-09-22, after 2262-04-11), give 0 (1970-01-01, 00:00) and *fault.
#pragma once

#include <cstdint>

#include "runtime/core/iec_type.hpp"

namespace syncplc::st::vm {

enum class DateFn : std::uint8_t {
  ConcatDate,  // YEAR, MONTH, DAY -> DATE
  ConcatTod,   // HOUR, MINUTE, SECOND, MILLISECOND -> TOD
  ConcatDt,    // YEAR, MONTH, DAY, HOUR, MINUTE, SECOND, MILLISECOND -> DT
  DayOfWeek,   // DATE -> INT, 0 Sunday .. 6 Saturday
};

// `args`: the arguments as 64-bit integers (a DATE for DayOfWeek).
Cell date_fn(DateFn fn, const Cell* args, bool* fault) noexcept;

}  // namespace syncplc::st::vm
