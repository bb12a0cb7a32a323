#include "runtime/st/types.hpp"

#include <cctype>

namespace syncplc::st {

namespace {

constexpr std::string_view kElemNames[kElemCount] = {
    "BOOL", "SINT", "INT", "DINT", "LINT", "USINT", "UINT", "UDINT", "ULINT", "BYTE",
    "WORD", "DWORD", "LWORD", "REAL", "LREAL", "TIME", "LTIME", "DATE", "TOD", "DT"};

}  // namespace

bool same_name(std::string_view a, std::string_view b) {
  if (a.size() != b.size()) return false;
  for (std::size_t i = 0; i < a.size(); ++i)
    if (std::toupper(static_cast<unsigned char>(a[i])) != std::toupper(static_cast<unsigned char>(b[i])))
      return false;
  return true;
}

std::string name_key(std::string_view name) {
  std::string k(name);
  for (char& c : k) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  return k;
}

std::string_view elem_name(Elem e) { return kElemNames[static_cast<int>(e)]; }

std::optional<Elem> parse_elem(std::string_view name) {
  if (same_name(name, "TIME_OF_DAY")) return Elem::TOD;
  if (same_name(name, "DATE_AND_TIME")) return Elem::DT;
  for (int i = 0; i < kElemCount; ++i)
    if (same_name(name, kElemNames[i])) return static_cast<Elem>(i);
  return std::nullopt;
}

IecType runtime_type(Elem e) {
  if (e == Elem::LTIME) return IecType::TIME;
  if (e == Elem::DATE || e == Elem::TOD || e == Elem::DT) return IecType::LINT;
  return static_cast<IecType>(e);
}

bool is_signed_int(Elem e) { return e >= Elem::SINT && e <= Elem::LINT; }
bool is_unsigned_int(Elem e) { return e >= Elem::USINT && e <= Elem::ULINT; }
bool is_int(Elem e) { return is_signed_int(e) || is_unsigned_int(e); }
bool is_real(Elem e) { return e == Elem::REAL || e == Elem::LREAL; }
bool is_num(Elem e) { return is_int(e) || is_real(e); }
bool is_bits(Elem e) { return e == Elem::BOOL || (e >= Elem::BYTE && e <= Elem::LWORD); }
bool is_duration(Elem e) { return e == Elem::TIME || e == Elem::LTIME; }

int bits(Elem e) {
  switch (e) {
    case Elem::BOOL: return 1;
    case Elem::SINT: case Elem::USINT: case Elem::BYTE: return 8;
    case Elem::INT: case Elem::UINT: case Elem::WORD: return 16;
    case Elem::DINT: case Elem::UDINT: case Elem::DWORD: case Elem::REAL: return 32;
    default: return 64;
  }
}

Wide min_value(Elem e) {
  if (is_signed_int(e)) return -(static_cast<Wide>(1) << (bits(e) - 1));
  return 0;
}

Wide max_value(Elem e) {
  if (is_signed_int(e)) return (static_cast<Wide>(1) << (bits(e) - 1)) - 1;
  if (e == Elem::BOOL) return 1;
  return (static_cast<Wide>(1) << bits(e)) - 1;
}

bool widens_to(Elem from, Elem to) {
  if (from == to) return true;
  using E = Elem;
  // The 3rd edition's implicit conversions (figure 11): integers within their
  // signedness to a wider one, unsigned to a wider signed, integers to the
  // real that holds all their values exactly, REAL to LREAL, bit strings to
  // a wider one, TIME to LTIME. Never narrowing, never signed to unsigned.
  switch (from) {
    case E::SINT: return to == E::INT || to == E::DINT || to == E::LINT || to == E::REAL || to == E::LREAL;
    case E::INT: return to == E::DINT || to == E::LINT || to == E::REAL || to == E::LREAL;
    case E::DINT: return to == E::LINT || to == E::LREAL;
    case E::USINT:
      return to == E::UINT || to == E::UDINT || to == E::ULINT || to == E::INT || to == E::DINT ||
             to == E::LINT || to == E::REAL || to == E::LREAL;
    case E::UINT:
      return to == E::UDINT || to == E::ULINT || to == E::DINT || to == E::LINT || to == E::REAL ||
             to == E::LREAL;
    case E::UDINT: return to == E::ULINT || to == E::LINT || to == E::LREAL;
    case E::REAL: return to == E::LREAL;
    case E::BYTE: return to == E::WORD || to == E::DWORD || to == E::LWORD;
    case E::WORD: return to == E::DWORD || to == E::LWORD;
    case E::DWORD: return to == E::LWORD;
    case E::TIME: return to == E::LTIME;
    default: return false;
  }
}

std::optional<Elem> Type::scalar() const {
  if (kind == Kind::Elementary || kind == Kind::Subrange) return elem;
  return std::nullopt;
}

std::int64_t Type::element_count() const {
  if (kind != Kind::Array) return 1;
  std::int64_t n = 1;
  for (const auto& d : dims) n *= d.count();
  return n;
}

const Field* Type::field(std::string_view n) const {
  for (const auto& f : fields)
    if (same_name(f.name, n)) return &f;
  return nullptr;
}

const EnumValue* Type::value(std::string_view n) const {
  for (const auto& v : values)
    if (same_name(v.name, n)) return &v;
  return nullptr;
}

const Pin* FbType::find(std::string_view n) const {
  for (const auto& p : pins)
    if (same_name(p.name, n)) return &p;
  return nullptr;
}

const BlockSignature::ParamSpec* FbType::param(std::string_view n) const {
  for (const auto& p : params)
    if (same_name(p.name, n)) return &p;
  return nullptr;
}

bool FbType::complete() const {
  for (const auto& p : params)
    if (!p.value) return false;
  return true;
}

TypeTable::TypeTable() {
  Type err;
  err.kind = Type::Kind::Error;
  err.name = "<error>";
  error_ = add(std::move(err));
  for (int i = 0; i < kElemCount; ++i) {
    Type t;
    t.kind = Type::Kind::Elementary;
    t.elem = static_cast<Elem>(i);
    t.name = std::string(kElemNames[i]);
    elems_[i] = add(std::move(t));
  }
}

const Type* TypeTable::string(int length, bool wide) {
  auto it = strings_.find({length, wide});
  if (it != strings_.end()) return it->second;
  Type t;
  t.kind = Type::Kind::String;
  t.length = length;
  t.wide = wide;
  t.name = std::string(wide ? "WSTRING" : "STRING") + "[" + std::to_string(length) + "]";
  const Type* p = add(std::move(t));
  strings_[{length, wide}] = p;
  return p;
}

Type* TypeTable::add(Type t) { return &types_.emplace_back(std::move(t)); }
FbType* TypeTable::add_fb(FbType fb) { return &fbs_.emplace_back(std::move(fb)); }

bool assignable(const Type* from, const Type* to) {
  if (from->is_error() || to->is_error()) return true;  // already reported
  if (from == to) return true;
  // A string of any capacity to another of the same width: the value is cut
  // at the target's capacity, as IEC says.
  if (from->kind == Type::Kind::String && to->kind == Type::Kind::String) return from->wide == to->wide;
  // Subranges read as their base type; a write into one is range-checked
  // (constants here, variables at run time).
  const auto f = from->scalar(), t = to->scalar();
  if (f && t) return widens_to(*f, *t);
  // Two arrays spelt alike (each declaration makes its own type) are one type.
  if (from->kind == Type::Kind::Array && to->kind == Type::Kind::Array) {
    if (from->dims.size() != to->dims.size()) return false;
    for (std::size_t i = 0; i < from->dims.size(); ++i)
      if (from->dims[i].low != to->dims[i].low || from->dims[i].high != to->dims[i].high) return false;
    const Type* a = from->element;
    const Type* b = to->element;
    return a == b || (a->kind == b->kind && (a->kind == Type::Kind::Array || a->kind == Type::Kind::String) &&
                      assignable(a, b) && assignable(b, a) && (a->kind != Type::Kind::String || a->length == b->length));
  }
  return false;  // structs, enums and FBs: the same type only
}

std::string conversion_hint(const Type* from, const Type* to) {
  const auto f = from->scalar(), t = to->scalar();
  // Of the date types only a DT converts (to its DATE and its TOD); no hint
  // names a conversion the checker refuses (check_call.cpp).
  const bool dates = (f && *f >= Elem::DATE) || (t && *t >= Elem::DATE);
  if (dates && !(f == Elem::DT && (t == Elem::DATE || t == Elem::TOD))) return "";
  if (f && t) return std::string(elem_name(*f)) + "_TO_" + std::string(elem_name(*t));
  if (f && to->kind == Type::Kind::String)
    return std::string(elem_name(*f)) + (to->wide ? "_TO_WSTRING" : "_TO_STRING");
  if (from->kind == Type::Kind::String && t)
    return std::string(from->wide ? "WSTRING_TO_" : "STRING_TO_") + std::string(elem_name(*t));
  return "";
}

}  // namespace syncplc::st
