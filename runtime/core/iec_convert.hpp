// The IEC 61131-3 type conversions *_TO_** between every pair of elementary
// types and the truncations *_TRUNC_** (IEC 61131-3 ed. 2, 2.5.1.5.1,
// Table 22), one implementation for the graph's conversion blocks
// (fblocks/iec/conversion.cpp) and the Structured Text VM.
//
// The rules (the standard leaves out-of-range results implementation-defined;
// syncplc saturates and reports it, so a wrapped value never reaches an
// actuator unnoticed):
//   - REAL/LREAL to an integer: round to nearest, ties to even (IEC 60559, as
//     Table 22 note b prescribes: 2.5 -> 2, -1.5 -> -2); TRUNC rounds toward
//     zero (note c).
//   - to an integer (SINT..ULINT) or REAL: a value outside the target's range
//     gives the nearest representable value (the minimum or maximum) and sets
//     *out_of_range.
//   - to a bit string (BYTE..LWORD): the low bits of the value's two's-
//     complement pattern (INT_TO_WORD(-1) = 16#FFFF, DWORD_TO_BYTE(16#1234)
//     = 16#34), not out of range; from a real, the rounded value must fit
//     0 .. 2^N - 1 (else saturated, out of range).
//   - a bit string to a signed integer of the same width is a reinterpretation
//     of the bits (WORD_TO_INT(16#FFFF) = -1); otherwise bit strings count as
//     unsigned numbers.
//   - BOOL: FALSE -> 0, TRUE -> 1; to BOOL: TRUE when the value is not 0.
//   - TIME: counted in milliseconds against numbers and bit strings (as
//     CODESYS TIME_TO_DINT); TIME_TO_LREAL(T#1.5ms) = 1.5; to an integer a
//     fraction of a millisecond rounds like a real. BOOL_TO_TIME(TRUE) = T#1ms.
//   - a NaN real (the blocks never see one: finite_guard.hpp; the VM may) gives
//     0 and out of range for an integer, bit string or TIME; TRUE for BOOL;
//     NaN for a real. An infinite real saturates like any large value.
// Everything here runs on the scan path: noexcept, no allocation.
#pragma once

#include "runtime/core/iec_type.hpp"

namespace syncplc {

// A conversion of one cell: sets *out_of_range (never clears it) when the
// result was saturated.
using ConvertFn = Cell (*)(Cell in, bool* out_of_range) noexcept;

// The conversion from `from` to `to`, resolved once (a table of the 16 x 16
// instantiations, twice). trunc: reals round toward zero where a conversion
// rounds (REAL_TRUNC_INT); otherwise to nearest, ties to even. from == to
// gives the identity. Never nullptr.
ConvertFn conversion_fn(IecType from, IecType to, bool trunc) noexcept;

}  // namespace syncplc
