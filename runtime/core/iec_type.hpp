// IEC 61131-3 elementary data types and the 8-byte cell that holds one value
// in a task's process image.
#pragma once

#include <bit>
#include <cstdint>
#include <cstring>
#include <optional>
#include <string>
#include <string_view>
#include <type_traits>

namespace syncplc {

enum class IecType : std::uint8_t {
  BOOL, SINT, INT, DINT, LINT, USINT, UINT, UDINT, ULINT,
  BYTE, WORD, DWORD, LWORD, REAL, LREAL, TIME,
};
inline constexpr int kIecTypeCount = 16;
// The types' names, indexed by IecType (header-only, for code that does not
// link the core, such as the ST VM's string conversions).
inline constexpr std::string_view kIecTypeNames[kIecTypeCount] = {
    "BOOL", "SINT", "INT", "DINT", "LINT", "USINT", "UINT", "UDINT", "ULINT",
    "BYTE", "WORD", "DWORD", "LWORD", "REAL", "LREAL", "TIME"};

// Generic type classes of IEC 61131-3 (table 11), used by overloaded blocks
// such as ADD or GT whose pin type is fixed per instance at load.
enum class TypeClass : std::uint8_t {
  Exact,          // the pin has one concrete type
  ANY,            // any elementary type
  ANY_MAGNITUDE,  // numbers and TIME
  ANY_NUM,        // integers and reals
  ANY_INT,        // signed and unsigned integers
  ANY_REAL,       // REAL, LREAL
  ANY_BIT,        // BOOL, BYTE, WORD, DWORD, LWORD
};

std::string_view type_name(IecType t);
std::string_view class_name(TypeClass c);
std::optional<IecType> parse_type_name(std::string_view s);
bool in_class(IecType t, TypeClass c);
bool is_integer(IecType t);
bool is_signed_integer(IecType t);
bool is_real(IecType t);
bool is_bit_string(IecType t);   // BOOL and BYTE..LWORD
int bit_width(IecType t);        // storage width in bits (BOOL: 1)

// One process-image cell. Every elementary value fits in 8 bytes; the value
// sits in the low bytes in its native representation (BOOL as 0/1, TIME as
// signed nanoseconds, like IEC LTIME). A connection copies whole cells.
struct Cell {
  std::uint64_t raw = 0;

  template <class T>
  T get() const noexcept {
    static_assert(sizeof(T) <= 8 && std::is_trivially_copyable_v<T>);
    T v;
    std::memcpy(&v, &raw, sizeof(T));
    return v;
  }
  template <class T>
  void set(T v) noexcept {
    static_assert(sizeof(T) <= 8 && std::is_trivially_copyable_v<T>);
    // A plain integer store where the layout allows: a memcpy into raw may, to
    // the compiler, alias any object, so a block writing its outputs would
    // reload its own members after each write. The bits are those the memcpy
    // gives (whole cell, or the low bytes of a little-endian cell).
    if constexpr (sizeof(T) == 8) {
      raw = std::bit_cast<std::uint64_t>(v);
    } else if constexpr (std::endian::native == std::endian::little && sizeof(T) == 4) {
      raw = std::bit_cast<std::uint32_t>(v);
    } else if constexpr (std::endian::native == std::endian::little && sizeof(T) == 2) {
      raw = std::bit_cast<std::uint16_t>(v);
    } else if constexpr (std::endian::native == std::endian::little && sizeof(T) == 1) {
      raw = std::bit_cast<std::uint8_t>(v);
    } else {
      raw = 0;
      std::memcpy(&raw, &v, sizeof(T));
    }
  }
};
static_assert(sizeof(Cell) == 8);

// C++ representation of each IEC type.
template <IecType T> struct Native;
template <> struct Native<IecType::BOOL> { using type = bool; };
template <> struct Native<IecType::SINT> { using type = std::int8_t; };
template <> struct Native<IecType::INT> { using type = std::int16_t; };
template <> struct Native<IecType::DINT> { using type = std::int32_t; };
template <> struct Native<IecType::LINT> { using type = std::int64_t; };
template <> struct Native<IecType::USINT> { using type = std::uint8_t; };
template <> struct Native<IecType::UINT> { using type = std::uint16_t; };
template <> struct Native<IecType::UDINT> { using type = std::uint32_t; };
template <> struct Native<IecType::ULINT> { using type = std::uint64_t; };
template <> struct Native<IecType::BYTE> { using type = std::uint8_t; };
template <> struct Native<IecType::WORD> { using type = std::uint16_t; };
template <> struct Native<IecType::DWORD> { using type = std::uint32_t; };
template <> struct Native<IecType::LWORD> { using type = std::uint64_t; };
template <> struct Native<IecType::REAL> { using type = float; };
template <> struct Native<IecType::LREAL> { using type = double; };
template <> struct Native<IecType::TIME> { using type = std::int64_t; };  // ns

// Calls f.template operator()<IecType>() with the runtime type as a template
// argument, so generic blocks are instantiated once per type.
template <class F>
decltype(auto) dispatch_type(IecType t, F&& f) {
  switch (t) {
    case IecType::BOOL: return f.template operator()<IecType::BOOL>();
    case IecType::SINT: return f.template operator()<IecType::SINT>();
    case IecType::INT: return f.template operator()<IecType::INT>();
    case IecType::DINT: return f.template operator()<IecType::DINT>();
    case IecType::LINT: return f.template operator()<IecType::LINT>();
    case IecType::USINT: return f.template operator()<IecType::USINT>();
    case IecType::UINT: return f.template operator()<IecType::UINT>();
    case IecType::UDINT: return f.template operator()<IecType::UDINT>();
    case IecType::ULINT: return f.template operator()<IecType::ULINT>();
    case IecType::BYTE: return f.template operator()<IecType::BYTE>();
    case IecType::WORD: return f.template operator()<IecType::WORD>();
    case IecType::DWORD: return f.template operator()<IecType::DWORD>();
    case IecType::LWORD: return f.template operator()<IecType::LWORD>();
    case IecType::REAL: return f.template operator()<IecType::REAL>();
    case IecType::LREAL: return f.template operator()<IecType::LREAL>();
    case IecType::TIME: return f.template operator()<IecType::TIME>();
  }
  return f.template operator()<IecType::LREAL>();
}

// Value of a cell as a double (for traces, tolerances, status display).
double cell_as_double(IecType t, Cell c);
// IEC-style text of a value: TRUE, -12, 16#00FF, 1.5, T#1s500ms.
std::string format_value(IecType t, Cell c);

// Parses a literal of type t. Accepts IEC forms (TRUE/FALSE, 16#FF, 2#1010,
// 8#17, 1_000, T#1s, TIME#250ms) and plain YAML forms (true, 0x1F, 1.5e3,
// 250ms). On error returns nullopt and sets *error to the reason.
std::optional<Cell> parse_value(IecType t, std::string_view text, std::string* error);

// A REAL or LREAL cell holding v. A value that rounds to infinity as a float
// (|v| >= 2^128 - 2^103) is out of range for REAL; the largest REAL loads.
std::optional<Cell> real_cell(IecType t, double v, std::string_view text, std::string* error);

// Parses a duration: 1ms, 250us, 0.5s, 2m, 1h30m, 100ns, T#1s500ms.
std::optional<std::int64_t> parse_duration_ns(std::string_view text, std::string* error);
std::string format_duration(std::int64_t ns);  // shortest exact: 1ms, 250us, 1.5s

}  // namespace syncplc
