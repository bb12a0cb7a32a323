// Fixed-capacity STRING[n] and WSTRING[n] in the VM's 8-byte cells, and the
// IEC 61131-3 string functions (ed. 3, 6.6.2.5.11, Table 29) and conversions
// the VM's instruction handlers call. All of it runs on the scan path:
// noexcept, no allocation, no locks, no I/O; every input has a defined result.
//
// Layout (the code generator relies on exactly this):
//   - STRING[n] takes string_cells(n, false) = 1 + ceil((n + 1) / 8) cells,
//     WSTRING[n] string_cells(n, true) = 1 + ceil(2 (n + 1) / 8) cells.
//   - cell 0 holds the current length in characters (bytes for STRING,
//     char16_t units for WSTRING) as a uint64; the characters follow from
//     cell 1 on, as a char / char16_t array.
//   - INVARIANT: every character position from the length to the end of the
//     cells is zero: a string is NUL-terminated, equal strings are equal cell
//     by cell, and runs are reproducible bit for bit. Every function below
//     writes all string_cells(capacity) cells of its destination, so the
//     invariant holds after it whatever the destination held before.
//   - A source is trusted to keep the invariant (its length within its
//     capacity): only these functions write strings, on zeroed cells.
//   - A destination never aliases a source (the code generator gives a
//     temporary for s := CONCAT(s, 'x')); debug builds assert it.
//
// Destinations are (Cell* dst, int capacity), sources const Cell*. Each
// writing function returns a StringStatus; the VM turns a non-Ok one into a
// fault event naming the source's file:line, and the result is still defined:
//   - Truncated: the result was longer than the destination's capacity and
//     was cut there (the first `capacity` characters are kept);
//   - BadArgument: an L or P out of range, or a text that is no value of the
//     type; what the result is then is the function's rule below. It wins
//     over Truncated when both happen.
//   - A negative capacity is BadArgument and leaves the destination alone.
//
// Positions are 1-based (IEC); L and P arrive as int64 (the VM widens every
// integer type). Out-of-range rules (CODESYS documents none; these are the
// nearest defined results, as docs/st.md "Strings at run time" explains: a
// bad position removes nothing, and what is inserted goes to the nearest end):
//   LEFT/RIGHT(IN, L)   L < 0: '' (BadArgument); L > LEN(IN): all of IN (Ok).
//   MID(IN, L, P)       P in 1 .. LEN(IN)+1 and L >= 0: the L characters from
//                       P, fewer when IN ends first (Ok); L < 0 or P outside
//                       that range: '' (BadArgument).
//   INSERT(IN1, IN2, P) IN2 after the P-th character, P in 0 .. LEN(IN1);
//                       P < 0: at the front, P > LEN(IN1): at the end
//                       (BadArgument).
//   DELETE(IN, L, P)    the L characters from P, fewer when IN ends first;
//                       P outside 1 .. LEN(IN)+1: nothing deleted; L < 0:
//                       as 0 (BadArgument).
//   REPLACE(IN1, IN2, L, P)  DELETE(IN1, L, P) with IN2 put at P; a P
//                       outside 1 .. LEN(IN1)+1 deletes nothing and puts IN2
//                       at the front (P < 1) or the end; L < 0: as 0
//                       (BadArgument).
//   FIND(IN1, IN2)      the position of IN2's first occurrence in IN1, 0 when
//                       absent or when IN2 is empty.
#pragma once

#include <cstddef>
#include <cstdint>
#include <type_traits>

#include "runtime/core/iec_type.hpp"

namespace syncplc::st::vm {

enum class StringStatus : std::uint8_t { Ok, Truncated, BadArgument };

// The cells a STRING[n] (wide: WSTRING[n]) takes: the length cell and room
// for n characters and the terminating zero.
constexpr int string_cells(int n, bool wide) noexcept {
  const long long bytes = (wide ? 2LL : 1LL) * (static_cast<long long>(n) + 1);
  return bytes <= 0 ? 1 : static_cast<int>(1 + (bytes + 7) / 8);
}

// C is char (STRING) or char16_t (WSTRING).
template <class C>
concept StringChar = std::is_same_v<C, char> || std::is_same_v<C, char16_t>;

template <StringChar C>
constexpr int string_cells_of(int n) noexcept {
  return string_cells(n, sizeof(C) == 2);
}

// LEN(IN).
inline std::int64_t str_len(const Cell* s) noexcept { return static_cast<std::int64_t>(s[0].get<std::uint64_t>()); }

// The characters of a string (for reading; a WSTRING's through char16_t).
inline const char* str_chars(const Cell* s) noexcept { return reinterpret_cast<const char*>(s + 1); }

// dst := src (cut to the capacity).
template <StringChar C>
StringStatus str_assign(Cell* dst, int capacity, const Cell* src) noexcept;

// dst := a literal's characters.
StringStatus str_set(Cell* dst, int capacity, const char* text, std::size_t n) noexcept;
StringStatus str_set(Cell* dst, int capacity, const char16_t* text, std::size_t n) noexcept;
// A WSTRING from UTF-8 text (the lexer keeps "..." literals as UTF-8):
// characters beyond U+FFFF take two units (a surrogate pair, never split by a
// cut); a malformed sequence gives U+FFFD and BadArgument.
StringStatus wstr_set_utf8(Cell* dst, int capacity, const char* text, std::size_t n) noexcept;

template <StringChar C>
StringStatus str_left(Cell* dst, int capacity, const Cell* in, std::int64_t l) noexcept;
template <StringChar C>
StringStatus str_right(Cell* dst, int capacity, const Cell* in, std::int64_t l) noexcept;
template <StringChar C>
StringStatus str_mid(Cell* dst, int capacity, const Cell* in, std::int64_t l, std::int64_t p) noexcept;
// CONCAT(IN1, IN2); the VM chains it for more inputs.
template <StringChar C>
StringStatus str_concat(Cell* dst, int capacity, const Cell* in1, const Cell* in2) noexcept;
template <StringChar C>
StringStatus str_insert(Cell* dst, int capacity, const Cell* in1, const Cell* in2, std::int64_t p) noexcept;
template <StringChar C>
StringStatus str_delete(Cell* dst, int capacity, const Cell* in, std::int64_t l, std::int64_t p) noexcept;
template <StringChar C>
StringStatus str_replace(Cell* dst, int capacity, const Cell* in1, const Cell* in2, std::int64_t l,
                         std::int64_t p) noexcept;
template <StringChar C>
std::int64_t str_find(const Cell* in1, const Cell* in2) noexcept;

// <0, 0, >0 as a is before, equal to or after b, character by character
// (unsigned bytes; char16_t units); a proper prefix is before. For
// = <> < > <= >=.
template <StringChar C>
int str_compare(const Cell* a, const Cell* b) noexcept;

// x_TO_STRING / x_TO_WSTRING: the text of a value of type t, as
// format_value (runtime/core/iec_type.cpp) writes it except for the bit
// strings: BOOL TRUE/FALSE, integers and BYTE..LWORD in decimal (CODESYS:
// BYTE_TO_STRING(16#FF) = '255'; format_value writes 16#FF), REAL/LREAL the
// shortest text that reads back to the same value (1.5, 1e+30, inf, nan),
// TIME T#1s500ms (h m s ms us ns, the largest first; T#0ms).
template <StringChar C>
StringStatus to_string(IecType t, Cell value, Cell* dst, int capacity) noexcept;

// STRING_TO_x / WSTRING_TO_x: parses the forms parse_value accepts (spaces
// around, TRUE/FALSE/1/0/ON/OFF/YES/NO, 16#FF 8#17 2#1010 0x1F 0b1, 1_000, a
// type prefix INT#5, 1.5e3, T#1m30s, 250ms). A text that is no value of t
// (or longer than kMaxNumberText characters after trimming): 0 and
// BadArgument. A value out of t's range: the nearest limit and BadArgument.
inline constexpr int kMaxNumberText = 256;
template <StringChar C>
StringStatus from_string(IecType t, const Cell* src, Cell* out) noexcept;

// The text to_string writes, into buf (at least kValueTextMax chars); returns
// its length. Shared with the tests that compare it with format_value.
inline constexpr int kValueTextMax = 48;
int value_text(IecType t, Cell value, char* buf) noexcept;

}  // namespace syncplc::st::vm
