// Exclusive links (one MC_Power per axis) across YAML blocks and ST calls:
// a call that gives an MC block a VAR_EXTERNAL AXIS_REF by name
// (`pwr(Axis := x)`, st::LinkClaim) names its axis at load, so two
// instances naming one axis are a load error at the call, as two YAML
// blocks are (check_links.cpp). An AXIS_REF passed through a variable
// (an array, a VAR_IN_OUT) is known only when it runs: not checked.
#include <map>
#include <tuple>

#include "runtime/project/read_st.hpp"
#include "runtime/st/vm/st_block.hpp"
#include "runtime/project/stages.hpp"

namespace syncplc {

void check_st_exclusive_links(Declarations& p, Diagnostics& diags) {
  if (!p.st || !p.st->unit || !p.st->blocks) return;
  // (linking type, link, target) -> who names it first.
  std::map<std::tuple<const BlockTypeInfo*, int, int>, std::string> taken;
  for (const auto& in : p.instances) {
    if (!in.type) continue;
    for (const auto& l : in.links)
      if (l.instance >= 0 && !in.type->links[static_cast<std::size_t>(l.link)].exclusive.empty())
        taken.emplace(std::make_tuple(in.type, l.link, l.instance), in.name);
  }
  for (const auto& in : p.instances) {
    if (!in.type || in.type->category.rfind("Structured Text", 0) != 0) continue;
    for (const st::LinkClaim& c : p.st->unit->checked.link_claims) {
      if (!st::same_name(c.pou, in.type->name)) continue;
      const BlockTypeInfo* block = p.st->blocks->find(c.block);
      if (!block) continue;
      const int link = block->link_index(c.pin);
      if (link < 0) continue;
      const LinkDecl& decl = block->links[static_cast<std::size_t>(link)];
      if (decl.exclusive.empty()) continue;
      // The axis the instance's VAR_EXTERNAL names (check_links found it).
      int target = -1;
      for (const auto& l : in.links)
        if (st::same_name(in.type->links[static_cast<std::size_t>(l.link)].name, c.external)) target = l.instance;
      if (target < 0) continue;
      const std::string who = in.name + "." + c.instance;
      const auto [it, fresh] = taken.emplace(std::make_tuple(block, link, target), who);
      if (!fresh && it->second != who)
        diags.error(c.loc, who + "." + decl.name + ": " + p.instances[static_cast<std::size_t>(target)].name +
                               " is already named by " + it->second + " (" + decl.exclusive + ")");
    }
  }
}

}  // namespace syncplc
