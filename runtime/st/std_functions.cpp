#include "runtime/st/std_functions.hpp"

namespace syncplc::st {

namespace {

using P = ParamClass;
using G = GenericClass;

// IN1 of type a, IN2 of type b, the result of type r.
StdFunction time_fn(std::string_view name, Elem a, Elem b, Elem r) {
  return {name, GenericClass::None, {{"IN1", P::Fixed, a}, {"IN2", P::Fixed, b}}, false, 2, ResultRule::Fixed, r};
}

const std::vector<StdFunction>& table() {
  static const std::vector<StdFunction> t = {
      // Numeric (3rd edition, table 22)
      {"ABS", G::AnyNum, {{"IN", P::T}}, false, 1, ResultRule::T},
      {"SQRT", G::AnyReal, {{"IN", P::T}}, false, 1, ResultRule::T},
      {"LN", G::AnyReal, {{"IN", P::T}}, false, 1, ResultRule::T},
      {"LOG", G::AnyReal, {{"IN", P::T}}, false, 1, ResultRule::T},
      {"EXP", G::AnyReal, {{"IN", P::T}}, false, 1, ResultRule::T},
      {"SIN", G::AnyReal, {{"IN", P::T}}, false, 1, ResultRule::T},
      {"COS", G::AnyReal, {{"IN", P::T}}, false, 1, ResultRule::T},
      {"TAN", G::AnyReal, {{"IN", P::T}}, false, 1, ResultRule::T},
      {"ASIN", G::AnyReal, {{"IN", P::T}}, false, 1, ResultRule::T},
      {"ACOS", G::AnyReal, {{"IN", P::T}}, false, 1, ResultRule::T},
      {"ATAN", G::AnyReal, {{"IN", P::T}}, false, 1, ResultRule::T},
      {"ATAN2", G::AnyReal, {{"Y", P::T}, {"X", P::T}}, false, 2, ResultRule::T},
      {"EXPT", G::AnyReal, {{"IN1", P::T}, {"IN2", P::AnyNum}}, false, 2, ResultRule::T},
      // TRUNC: ANY_REAL to an integer; the generic form gives DINT (as the
      // 2nd edition's usual reading); LREAL_TRUNC_LINT and kin name others.
      {"TRUNC", G::AnyReal, {{"IN", P::T}}, false, 1, ResultRule::Dint},
      // Bit shifts (table 24)
      {"SHL", G::AnyBits, {{"IN", P::T}, {"N", P::AnyInt}}, false, 2, ResultRule::T},
      {"SHR", G::AnyBits, {{"IN", P::T}, {"N", P::AnyInt}}, false, 2, ResultRule::T},
      {"ROL", G::AnyBits, {{"IN", P::T}, {"N", P::AnyInt}}, false, 2, ResultRule::T},
      {"ROR", G::AnyBits, {{"IN", P::T}, {"N", P::AnyInt}}, false, 2, ResultRule::T},
      // Selection and comparison (table 27)
      {"MIN", G::AnyElementary, {{"IN", P::T}}, true, 2, ResultRule::T},
      {"MAX", G::AnyElementary, {{"IN", P::T}}, true, 2, ResultRule::T},
      {"LIMIT", G::AnyElementary, {{"MN", P::T}, {"IN", P::T}, {"MX", P::T}}, false, 3, ResultRule::T},
      {"SEL", G::AnyElementary, {{"G", P::Bool}, {"IN0", P::T}, {"IN1", P::T}}, false, 3, ResultRule::T},
      {"MUX", G::AnyElementary, {{"K", P::AnyInt}, {"IN", P::T}}, true, 3, ResultRule::T},
      // Strings (table 29); positions and lengths are ANY_INT, results INT
      {"LEN", G::AnyString, {{"IN", P::T}}, false, 1, ResultRule::Int},
      {"LEFT", G::AnyString, {{"IN", P::T}, {"L", P::AnyInt}}, false, 2, ResultRule::T},
      {"RIGHT", G::AnyString, {{"IN", P::T}, {"L", P::AnyInt}}, false, 2, ResultRule::T},
      {"MID", G::AnyString, {{"IN", P::T}, {"L", P::AnyInt}, {"P", P::AnyInt}}, false, 3, ResultRule::T},
      {"CONCAT", G::AnyString, {{"IN", P::T}}, true, 2, ResultRule::T},
      {"INSERT", G::AnyString, {{"IN1", P::T}, {"IN2", P::T}, {"P", P::AnyInt}}, false, 3, ResultRule::T},
      {"DELETE", G::AnyString, {{"IN", P::T}, {"L", P::AnyInt}, {"P", P::AnyInt}}, false, 3, ResultRule::T},
      {"REPLACE", G::AnyString, {{"IN1", P::T}, {"IN2", P::T}, {"L", P::AnyInt}, {"P", P::AnyInt}}, false, 4,
       ResultRule::T},
      {"FIND", G::AnyString, {{"IN1", P::T}, {"IN2", P::T}}, false, 2, ResultRule::Int},
      // Time types (3rd edition, table 35): the operators by name.
      time_fn("ADD_TIME", Elem::TIME, Elem::TIME, Elem::TIME),
      time_fn("ADD_TOD_TIME", Elem::TOD, Elem::TIME, Elem::TOD),
      time_fn("ADD_DT_TIME", Elem::DT, Elem::TIME, Elem::DT),
      time_fn("SUB_TIME", Elem::TIME, Elem::TIME, Elem::TIME),
      time_fn("SUB_DATE_DATE", Elem::DATE, Elem::DATE, Elem::TIME),
      time_fn("SUB_TOD_TIME", Elem::TOD, Elem::TIME, Elem::TOD),
      time_fn("SUB_TOD_TOD", Elem::TOD, Elem::TOD, Elem::TIME),
      time_fn("SUB_DT_TIME", Elem::DT, Elem::TIME, Elem::DT),
      time_fn("SUB_DT_DT", Elem::DT, Elem::DT, Elem::TIME),
      {"MUL_TIME", G::None, {{"IN1", P::Fixed, Elem::TIME}, {"IN2", P::AnyNum}}, false, 2, ResultRule::Fixed, Elem::TIME},
      {"DIV_TIME", G::None, {{"IN1", P::Fixed, Elem::TIME}, {"IN2", P::AnyNum}}, false, 2, ResultRule::Fixed, Elem::TIME},
      time_fn("CONCAT_DATE_TOD", Elem::DATE, Elem::TOD, Elem::DT),
      // Time types (3rd edition, table 36): a date, a time of day and a
      // date and time from their fields, and a date's day of the week.
      {"CONCAT_DATE", G::None, {{"YEAR", P::AnyInt}, {"MONTH", P::AnyInt}, {"DAY", P::AnyInt}}, false, 3,
       ResultRule::Fixed, Elem::DATE},
      {"CONCAT_TOD", G::None,
       {{"HOUR", P::AnyInt}, {"MINUTE", P::AnyInt}, {"SECOND", P::AnyInt}, {"MILLISECOND", P::AnyInt}}, false, 4,
       ResultRule::Fixed, Elem::TOD},
      {"CONCAT_DT", G::None,
       {{"YEAR", P::AnyInt}, {"MONTH", P::AnyInt}, {"DAY", P::AnyInt}, {"HOUR", P::AnyInt}, {"MINUTE", P::AnyInt},
        {"SECOND", P::AnyInt}, {"MILLISECOND", P::AnyInt}},
       false, 7, ResultRule::Fixed, Elem::DT},
      {"DAY_OF_WEEK", G::None, {{"IN", P::Fixed, Elem::DATE}}, false, 1, ResultRule::Fixed, Elem::INT},
  };
  return t;
}

// "STRING", "WSTRING" or an elementary type name.
bool parse_side(std::string_view s, std::optional<Elem>& e, bool& str, bool& wstr) {
  if (same_name(s, "STRING")) return str = true;
  if (same_name(s, "WSTRING")) return wstr = true;
  e = parse_elem(s);
  return e.has_value();
}

}  // namespace

const StdFunction* find_std_function(std::string_view name) {
  for (const auto& f : table())
    if (same_name(f.name, name)) return &f;
  return nullptr;
}

std::vector<std::string_view> std_function_names() {
  std::vector<std::string_view> out;
  for (const auto& f : table()) out.push_back(f.name);
  return out;
}

bool in_generic_class(const Type* t, GenericClass c) {
  if (t->is_error()) return true;
  if (c == GenericClass::AnyString) return t->kind == Type::Kind::String;
  const auto e = t->scalar();
  switch (c) {
    case GenericClass::AnyNum: return e && is_num(*e);
    case GenericClass::AnyReal: return e && is_real(*e);
    case GenericClass::AnyInt: return e && is_int(*e);
    case GenericClass::AnyBits: return e && is_bits(*e) && *e != Elem::BOOL;
    case GenericClass::AnyElementary:
      return e.has_value() || t->kind == Type::Kind::String || t->kind == Type::Kind::Enum;
    case GenericClass::AnyString: break;
    case GenericClass::None: return false;
  }
  return false;
}

std::string_view generic_class_name(GenericClass c) {
  switch (c) {
    case GenericClass::AnyNum: return "ANY_NUM";
    case GenericClass::AnyReal: return "ANY_REAL";
    case GenericClass::AnyInt: return "ANY_INT";
    case GenericClass::AnyBits: return "ANY_BIT (not BOOL)";
    case GenericClass::AnyElementary: return "ANY_ELEMENTARY";
    case GenericClass::AnyString: return "ANY_STRING";
    case GenericClass::None: return "fixed types";
  }
  return "";
}

std::optional<Conversion> parse_conversion(std::string_view name) {
  Conversion c;
  if (name.size() > 3 && same_name(name.substr(0, 3), "TO_")) {
    if (!parse_side(name.substr(3), c.to, c.to_string, c.to_wstring)) return std::nullopt;
    return c;
  }
  for (std::string_view sep : {std::string_view("_TO_"), std::string_view("_TRUNC_")}) {
    const std::string upper = name_key(name);
    const auto at = upper.find(sep);
    if (at == std::string::npos || at == 0) continue;
    if (!parse_side(name.substr(0, at), c.from, c.from_string, c.from_wstring)) continue;
    if (!parse_side(name.substr(at + sep.size()), c.to, c.to_string, c.to_wstring)) continue;
    c.trunc = sep == "_TRUNC_";
    if (c.trunc && !(c.from && is_real(*c.from) && c.to && is_int(*c.to))) return std::nullopt;
    return c;
  }
  return std::nullopt;
}

}  // namespace syncplc::st
