// Built-in blocks as ST function block types (block_signatures.hpp).
#include "runtime/st/vm/block_signatures.hpp"

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

std::vector<BlockSignature> block_signatures(const BlockRegistry& registry) {
  std::vector<BlockSignature> out;
  for (const BlockTypeInfo* t : registry.all()) {
    if (t->category == "IEC type conversion") continue;
    // A generic block (CTU over ANY_INT) at its default type (CTU: INT, as IEC's CTU).
    bool ok = true;
    for (const PinDecl& p : t->pins)
      if (p.cls != TypeClass::Exact && !t->default_datatype) ok = false;
    if (!ok) continue;
    BlockSignature s;
    s.name = t->name;
    s.doc = t->doc;
    for (const PinDecl& p : t->pins) {
      const IecType type = p.cls == TypeClass::Exact ? p.type : *t->default_datatype;
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
    out.push_back(std::move(s));
  }
  return out;
}

}  // namespace syncplc::st::vm
