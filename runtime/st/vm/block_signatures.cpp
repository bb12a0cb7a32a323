// Built-in blocks as ST function block types (block_signatures.hpp).
#include "runtime/st/vm/block_signatures.hpp"

#include <fmt/format.h>

namespace syncplc::st::vm {

Cell param_cell(IecType type, const ConstValue& v) {
  return dispatch_type(type, [&]<IecType T>() {
    using N = typename Native<T>::type;
    Cell c;
    if constexpr (std::is_floating_point_v<N>) c.set<N>(static_cast<N>(v.as_double()));
    else c.set<N>(static_cast<N>(v.i));
    return c;
  });
}

ConstValue param_value(IecType type, Cell c) {
  return dispatch_type(type, [&]<IecType T>() {
    using N = typename Native<T>::type;
    if constexpr (std::is_floating_point_v<N>) return ConstValue{true, 0, static_cast<double>(c.get<N>())};
    else return ConstValue{false, static_cast<Wide>(c.get<N>()), 0};
  });
}

namespace {

// The typed counters' suffixes (IEC 61131-3, 3rd edition, table 45).
constexpr IecType kCounterTypes[] = {IecType::INT, IecType::DINT, IecType::LINT, IecType::UDINT, IecType::ULINT};

bool counter(const BlockTypeInfo& t) { return t.category == "IEC counters" && t.default_datatype; }

BlockSignature signature(const BlockTypeInfo* t, const std::string& name, IecType datatype, const std::string& doc) {
  BlockSignature s;
  s.name = name;
  s.doc = doc;
  for (const PinDecl& p : t->pins) {
    const IecType type = p.cls == TypeClass::Exact ? p.type : datatype;
    s.pins.push_back({p.name, p.dir == syncplc::PinDir::Out, std::string(type_name(type)), p.length_param,
                      p.max_length});
  }
  for (const ParamDecl& d : t->params) {
    BlockSignature::ParamSpec p{d.name, std::string(type_name(d.type))};
    std::string why;
    if (!d.default_value.empty())
      if (const auto c = parse_value(d.type, d.default_value, &why)) p.value = param_value(d.type, *c);
    p.min = d.min;
    p.max = d.max;
    p.unit = d.unit;
    s.params.push_back(std::move(p));
  }
  // Links after the pins (an index into the registry's pins stays one into
  // these): VAR_IN_OUT Axis : AXIS_REF, a list link ARRAY[1..n] OF AXIS_REF.
  for (const LinkDecl& l : t->links) {
    BlockSignature::PinSpec p{l.name, false, ref_type_name(l.target_type), l.length_param, kMaxPinLength};
    p.ref_target = l.target_type;
    s.pins.push_back(std::move(p));
  }
  return s;
}

}  // namespace

std::vector<BlockSignature> block_signatures(const BlockRegistry& registry) {
  std::vector<BlockSignature> out;
  for (const BlockTypeInfo* t : registry.all()) {
    if (t->category == "IEC type conversion") continue;
    // A generic block (CTU over ANY_INT) at its default type (CTU: INT, as IEC's CTU).
    bool ok = true;
    for (const PinDecl& p : t->pins)
      if (p.cls != TypeClass::Exact && !t->default_datatype) ok = false;
    if (!ok) continue;
    out.push_back(signature(t, t->name, t->default_datatype.value_or(IecType::LREAL), t->doc));
    if (!counter(*t)) continue;
    for (IecType type : kCounterTypes) {
      const std::string name = t->name + "_" + std::string(type_name(type));
      out.push_back(signature(t, name, type, fmt::format("{} at {} (IEC 61131-3 table 45). {}", t->name, type_name(type), t->doc)));
    }
  }
  return out;
}

std::string ref_type_name(std::string_view target_type) {
  if (target_type == "MC_AXIS") return "AXIS_REF";  // PLCopen's name
  return std::string(target_type) + "_REF";
}

const BlockTypeInfo* builtin_block(const BlockRegistry& registry, std::string_view name, IecType* datatype) {
  if (const BlockTypeInfo* t = registry.find(std::string(name))) {
    *datatype = t->default_datatype.value_or(IecType::LREAL);
    return t;
  }
  const auto cut = name.rfind('_');
  if (cut == std::string_view::npos) return nullptr;
  const BlockTypeInfo* t = registry.find(std::string(name.substr(0, cut)));
  if (!t || !counter(*t)) return nullptr;
  for (IecType type : kCounterTypes)
    if (name.substr(cut + 1) == type_name(type)) {
      *datatype = type;
      return t;
    }
  return nullptr;
}

}  // namespace syncplc::st::vm
