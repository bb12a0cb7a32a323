// The standard functions of IEC 61131-3 that ST calls by name, as a table:
// each entry names its parameters, the class of its generic type T (shared by
// the parameters marked T) and its result. The checker reads the table; the
// code generator will map each entry to its implementation. The type
// conversions (*_TO_*, *_TRUNC_*, TO_*) are recognised by their name's form.
#pragma once

#include <optional>
#include <string_view>
#include <vector>

#include "runtime/st/types.hpp"

namespace syncplc::st {

// The class of the generic type T of an entry; None for the functions of
// the time types, whose parameters have fixed types.
enum class GenericClass { AnyNum, AnyReal, AnyInt, AnyBits, AnyElementary, AnyString, None };

enum class ParamClass {
  T,       // of the shared generic type
  AnyInt,  // any integer type, independently of T (shift counts, lengths, MUX's selector)
  AnyNum,  // any number, independently of T (EXPT's exponent)
  Bool,
  Fixed,   // of the type StdParam::elem
};

enum class ResultRule { T, Int, Dint, Fixed };

struct StdParam {
  std::string_view name;
  ParamClass cls = ParamClass::T;
  Elem elem = Elem::BOOL;  // Fixed
};

struct StdFunction {
  std::string_view name;
  GenericClass generic = GenericClass::AnyNum;
  std::vector<StdParam> params;
  // The last parameter may repeat (MIN, MAX, MUX, CONCAT): its name is then
  // numbered (IN1, IN2, …); min_args counts the fixed ones.
  bool variadic = false;
  std::size_t min_args = 0;
  ResultRule result = ResultRule::T;
  Elem result_elem = Elem::BOOL;  // ResultRule::Fixed
};

// The entry named `name` (case-insensitive), or nullptr.
const StdFunction* find_std_function(std::string_view name);
// Every name in the table (for suggestions).
std::vector<std::string_view> std_function_names();
bool in_generic_class(const Type* t, GenericClass c);
std::string_view generic_class_name(GenericClass c);

// A type conversion by name: FROM_TO_TO (INT_TO_REAL), FROM_TRUNC_TO
// (LREAL_TRUNC_DINT), TO_TO (TO_INT: from any elementary type).
struct Conversion {
  std::optional<Elem> from;  // nullopt: TO_x; or a string
  bool from_string = false;
  bool from_wstring = false;
  std::optional<Elem> to;    // nullopt: to a string
  bool to_string = false;
  bool to_wstring = false;
  bool trunc = false;
};
std::optional<Conversion> parse_conversion(std::string_view name);

}  // namespace syncplc::st
