// Built-in blocks as ST function block types (block_signatures.hpp).
#include "runtime/st/vm/block_signatures.hpp"

namespace syncplc::st::vm {

std::vector<BlockSignature> block_signatures(const BlockRegistry& registry) {
  std::vector<BlockSignature> out;
  for (const BlockTypeInfo* t : registry.all()) {
    if (t->category == "IEC type conversion") continue;
    // A generic block (CTU over ANY_INT) at its default type (CTU: INT, as IEC's CTU).
    bool ok = true;
    for (const PinDecl& p : t->pins)
      if ((p.cls != TypeClass::Exact && !t->default_datatype) || p.is_array()) ok = false;
    if (!ok) continue;
    BlockSignature s;
    s.name = t->name;
    s.doc = t->doc;
    for (const PinDecl& p : t->pins) {
      const IecType type = p.cls == TypeClass::Exact ? p.type : *t->default_datatype;
      s.pins.push_back({p.name, p.dir == syncplc::PinDir::Out, std::string(type_name(type))});
    }
    out.push_back(std::move(s));
  }
  return out;
}

}  // namespace syncplc::st::vm
