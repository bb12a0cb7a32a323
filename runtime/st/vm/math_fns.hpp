// The library functions the VM calls through MATH1/MATH2 (code.hpp): the
// IEC 61131-3 numeric functions on REAL (computed in float) and LREAL, and
// the duration arithmetic with a real factor. IEC 60559 results (a NaN for
// SQRT(-1), an infinity for LN(0)), which the graph's finite-input rule
// stops at the next block (finite_guard.hpp).
#pragma once

#include <string_view>

#include "runtime/st/vm/code.hpp"

namespace syncplc::st::vm {

// The function named `name` (SQRT, LN, LOG, EXP, SIN, COS, TAN, ASIN, ACOS,
// ATAN) of one argument for REAL (wide false) or LREAL, or nullptr.
Math1Fn math1_fn(std::string_view name, bool lreal);
// ATAN2(Y, X) and EXPT(IN1, IN2) (both arguments of the base's type).
Math2Fn math2_fn(std::string_view name, bool lreal);
// TIME * LREAL and TIME / LREAL: the product rounded to the nearest
// nanosecond, saturated to the range of TIME (a division by zero saturates
// toward the sign of the duration; 0 / 0 gives 0).
Cell time_mul_real(Cell ns, Cell factor) noexcept;
Cell time_div_real(Cell ns, Cell divisor) noexcept;

}  // namespace syncplc::st::vm
