// Links between block instances (LinkDecl: a PLCopen motion block's axis):
// each names an instance of the declared type in the same task. The build
// orders the target first and hands it to Block::link.
#include <map>
#include <tuple>
#include <vector>

#include "runtime/core/closest_name.hpp"
#include "runtime/project/stages.hpp"

namespace syncplc {

void check_links(Declarations& p, Diagnostics& diags) {
  std::vector<std::string> candidates;  // instance names of a target type, made when a name is unknown
  // Exclusive links: (linking type, link, target) -> the first instance naming it.
  std::map<std::tuple<const BlockTypeInfo*, int, int>, const InstanceDecl*> taken;
  for (auto& in : p.instances) {
    if (!in.type) continue;
    // A list link names as many instances as its length parameter says.
    for (std::size_t l = 0; l < in.type->links.size(); ++l) {
      const LinkDecl& decl = in.type->links[l];
      if (decl.length_param.empty() || !in.params_ok) continue;
      const int k = in.type->param_index(decl.length_param);
      if (k < 0 || static_cast<std::size_t>(k) >= in.param_cells.size()) continue;
      std::size_t given = 0;
      const SourceLoc* at = nullptr;
      for (const auto& r : in.links)
        if (r.link == static_cast<int>(l)) {
          if (!at) at = &r.loc;
          if (!r.target.empty()) ++given;
        }
      const std::int64_t want = in.param_cells[static_cast<std::size_t>(k)].get<std::int32_t>();
      if (at && static_cast<std::int64_t>(given) != want)
        diags.error(*at, in.name + "." + decl.name + ": " + std::to_string(given) + " instances for " +
                             decl.length_param + " = " + std::to_string(want));
    }
    for (auto& l : in.links) {
      const LinkDecl& decl = in.type->links[static_cast<std::size_t>(l.link)];
      if (l.target.empty()) continue;  // written wrong: reported by read_blocks
      const int t = p.instance_index(l.target);
      if (t < 0) {
        if (p.failed_names.count(l.target)) continue;  // its own error says what is wrong
        candidates.clear();
        for (const auto& c : p.instances)
          if (c.type && c.type->name == decl.target_type) candidates.push_back(c.name);
        const std::string near = closest_name(l.target, candidates);
        diags.error(l.loc, in.name + "." + decl.name + ": no " + decl.target_type + " instance '" + l.target + "'" +
                               (near.empty() ? "" : " (did you mean '" + near + "'?)"));
        continue;
      }
      const InstanceDecl& target = p.instances[static_cast<std::size_t>(t)];
      if (!target.type || target.type->name != decl.target_type) {
        diags.error(l.loc, in.name + "." + decl.name + ": " + l.target + " is a " +
                               (target.type ? target.type->name : std::string("block")) + ", not an instance of " +
                               decl.target_type);
        continue;
      }
      if (target.task != in.task) {
        diags.error(l.loc, in.name + "." + decl.name + ": " + l.target + " runs in task " +
                               p.tasks[static_cast<std::size_t>(target.task)].cfg.name + ", " + in.name + " in " +
                               p.tasks[static_cast<std::size_t>(in.task)].cfg.name +
                               ": a block works only on an instance of its own task");
        continue;
      }
      l.instance = t;
      if (!decl.exclusive.empty()) {
        const auto [it, fresh] = taken.emplace(std::make_tuple(in.type, l.link, t), &in);
        if (!fresh)
          diags.error(l.loc, in.name + "." + decl.name + ": " + l.target + " is already named by " + it->second->name +
                                 " (" + decl.exclusive + ")");
      }
      for (const auto& other : in.links)
        if (&other != &l && other.link == l.link && other.element < l.element && other.target == l.target) {
          diags.error(l.loc, in.name + "." + decl.name + ": " + l.target + " is named twice");
          l.instance = -1;
          break;
        }
    }
  }
}

}  // namespace syncplc
