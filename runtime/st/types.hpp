// The type model of the Structured Text checker: what each name of a type
// means, as plain data the code generator reads next (element counts, field
// lists, enumeration values, pins). Layout in cells is the code generator's.
//
// Types live in a TypeTable (stable addresses); a `const Type*` is a type's
// identity, so two uses of one declared type compare equal by pointer. An
// alias (TYPE Distance : LREAL) is another name of the same Type, as IEC
// treats it. Elementary types and STRING[n] are interned per spelling.
#pragma once

#include <cstdint>
#include <deque>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "runtime/core/config_node.hpp"
#include "runtime/core/iec_type.hpp"

namespace syncplc::st {

// 128-bit integers: every value of LINT and ULINT, and their sums and
// products, fit (a GCC/Clang extension, so -Wpedantic stays quiet).
__extension__ typedef __int128 Wide;
__extension__ typedef unsigned __int128 UWide;

// The elementary types of ST. The first sixteen are the runtime's IecType in
// its order; LTIME is kept apart from TIME for typing (both hold signed
// nanoseconds); DATE, TOD and DT hold signed nanoseconds since 1970-01-01
// UTC (DATE at midnight) and since midnight, as the 3rd edition's LDATE,
// LTOD and LDT do, so they fit one Cell like every other value.
enum class Elem : std::uint8_t {
  BOOL, SINT, INT, DINT, LINT, USINT, UINT, UDINT, ULINT,
  BYTE, WORD, DWORD, LWORD, REAL, LREAL, TIME, LTIME, DATE, TOD, DT,
};
inline constexpr int kElemCount = 20;

std::string_view elem_name(Elem e);
std::optional<Elem> parse_elem(std::string_view name);  // case-insensitive; TIME_OF_DAY, DATE_AND_TIME too
IecType runtime_type(Elem e);  // LTIME: TIME; DATE, TOD, DT: LINT (nanoseconds)
bool is_int(Elem e);
bool is_signed_int(Elem e);
bool is_unsigned_int(Elem e);
bool is_real(Elem e);
bool is_num(Elem e);
bool is_bits(Elem e);  // BOOL, BYTE … LWORD
bool is_duration(Elem e);
int bits(Elem e);  // BOOL: 1
// The range of an integer type, as 128-bit so ULINT and LINT both fit.
Wide min_value(Elem e);
Wide max_value(Elem e);
// IEC 61131-3 (3rd edition) implicit conversion, from → to (also from == to).
bool widens_to(Elem from, Elem to);


// A folded constant: integers (also BOOL, bit strings, enumeration values)
// exactly in 128 bits, reals as double, durations in nanoseconds (in i).
struct ConstValue {
  bool is_real = false;
  Wide i = 0;
  double r = 0;
  double as_double() const { return is_real ? r : static_cast<double>(i); }
};

struct Type;

struct ArrayDim {
  std::int64_t low = 0;
  std::int64_t high = 0;
  std::int64_t count() const { return high - low + 1; }
};

struct Initializer;
struct TypeSpec;

struct Field {
  std::string name;
  const Type* type = nullptr;
  SourceLoc loc;
  const Initializer* init = nullptr;  // its initial value as declared (InitKind::None when none)
  const TypeSpec* spec = nullptr;     // its type as written (an alias's own initial value)
};

struct EnumValue {
  std::string name;
  std::int64_t value = 0;
  SourceLoc loc;
};

enum class PinDir { Input, Output, InOut, Local, Temp, External };

// One variable of a FUNCTION_BLOCK or FUNCTION as seen from the checker:
// pins (Input, Output, InOut) and, for user FBs, its other variables.
struct Pin {
  std::string name;
  PinDir dir = PinDir::Input;
  const Type* type = nullptr;
  SourceLoc loc;
};

// A built-in block's pins and parameters as the loader gives them (from the
// BlockRegistry): type names are elementary type names ("BOOL", "TIME", …).
struct BlockSignature {
  struct PinSpec {
    std::string name;
    bool output = false;
    std::string type;
    // An array pin: ARRAY[1..n] OF type, n the value of this parameter ("": a scalar pin).
    std::string length_param{};
    std::uint32_t max_length = 0;
    // A link (LinkDecl): the pin is a VAR_IN_OUT reference to an instance of
    // block type `ref_target` (MC_AXIS), whose ST type is `type` (AXIS_REF).
    std::string ref_target{};
  };
  struct ParamSpec {
    std::string name;
    std::string type;
    // Its value: the default in a signature (nullopt: none, it must be
    // given), in an instance's own FbType the one its declaration gives.
    // Durations in nanoseconds.
    std::optional<ConstValue> value{};
    std::optional<double> min{}, max{};  // its range, inclusive (durations in seconds), in `unit`
    std::string unit{};
  };
  std::string name;
  std::vector<PinSpec> pins;
  std::string doc;
  std::vector<ParamSpec> params{};
};

// A function block type: a user FUNCTION_BLOCK, or a built-in block given
// through a BlockSignature. A built-in block whose parameters are given in
// a declaration (`s : TRANSIENT_SYNC := (n := 4)`) has a type of its own
// for each set of values (its array pins sized by them): `name` is the
// block's, `params` hold the values.
struct FbType {
  std::string name;
  bool builtin = false;
  std::vector<Pin> pins;
  std::string doc;
  SourceLoc loc;
  std::vector<BlockSignature::ParamSpec> params;  // built-in: in the registry's order
  const Pin* find(std::string_view name) const;   // case-insensitive
  const BlockSignature::ParamSpec* param(std::string_view name) const;  // case-insensitive
  // A built-in block whose every parameter has a value (else it cannot be instanced as it is).
  bool complete() const;
};

struct Type {
  enum class Kind { Error, Elementary, String, Array, Struct, Enum, Subrange, FunctionBlock };
  Kind kind = Kind::Error;
  std::string name;  // as declared (or spelt: "STRING[20]", "ARRAY[1..3] OF INT")
  Elem elem = Elem::BOOL;  // Elementary; Enum and Subrange: the base type
  int length = 80;         // String: capacity in characters
  bool wide = false;       // String: WSTRING
  std::vector<ArrayDim> dims;    // Array
  const Type* element = nullptr;  // Array
  std::vector<Field> fields;      // Struct
  std::vector<EnumValue> values;  // Enum
  std::int64_t low = 0, high = 0;  // Subrange
  const FbType* fb = nullptr;      // FunctionBlock
  // Struct: a reference to a block instance of the project (AXIS_REF: an
  // MC_AXIS), the block type it names; "" for every other type. Its one
  // field, which ST cannot name, holds the instance's link number
  // (docs/st.md, "Motion control blocks").
  std::string ref_target{};
  SourceLoc loc;                   // declared types

  bool is_error() const { return kind == Kind::Error; }
  bool is_elem() const { return kind == Kind::Elementary; }
  bool is(Elem e) const { return kind == Kind::Elementary && elem == e; }
  // The elementary type a value of this type reads as: Elementary, and the
  // base of a Subrange. nullopt for others (Enum included: not a number).
  std::optional<Elem> scalar() const;
  std::int64_t element_count() const;  // Array: product of dims; others 1
  const Field* field(std::string_view name) const;
  const EnumValue* value(std::string_view name) const;
};

// Owns every type of a check; addresses are stable.
class TypeTable {
 public:
  TypeTable();
  const Type* error() const { return error_; }
  const Type* elem(Elem e) const { return elems_[static_cast<int>(e)]; }
  const Type* string(int length, bool wide);
  Type* add(Type t);
  FbType* add_fb(FbType fb);

 private:
  std::deque<Type> types_;
  std::deque<FbType> fbs_;
  const Type* error_ = nullptr;
  const Type* elems_[kElemCount] = {};
  std::map<std::pair<int, bool>, const Type*> strings_;
};

// Case-insensitive equality and key of IEC names.
bool same_name(std::string_view a, std::string_view b);
std::string name_key(std::string_view name);

// Whether a value of type `from` may be assigned to (or passed as) `to`
// without an explicit conversion.
bool assignable(const Type* from, const Type* to);
// The explicit conversion to suggest for from → to ("LREAL_TO_INT"), or "".
std::string conversion_hint(const Type* from, const Type* to);

}  // namespace syncplc::st
