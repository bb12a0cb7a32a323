// Execution order of each task's blocks: a block runs after every block
// whose output it reads in the same scan (directly or through a tag of the
// task) and after the instances it is linked to; unit delays first; a loop
// without a unit delay is an error.
#include <algorithm>
#include <functional>
#include <queue>

#include "runtime/project/stages.hpp"

namespace syncplc {

BlockOrder order_blocks(const Declarations& p, const Wiring& w, Diagnostics& diags) {
  BlockOrder o;
  const std::size_t nt = p.tasks.size();
  o.order.assign(nt, {});
  o.delays.assign(nt, 0);
  // Edge a -> b when b reads, in the same scan, a value a writes: directly
  // (a.out -> b.in) or through a tag of the same task (a.out -> tag -> b.in).
  std::vector<std::vector<std::pair<int, SourceLoc>>> succ(p.instances.size());
  // Several writers for element-wise writes; a reader of one element depends
  // only on the writer of that element (or of the whole tag).
  struct TagWriter {
    int instance;
    std::optional<std::uint32_t> element;
    int pin;
  };
  std::vector<std::vector<TagWriter>> tag_writers(p.tags.size());
  for (const auto& c : w.connections)
    if (c.src.is_pin && !c.dst.is_pin)
      tag_writers[static_cast<std::size_t>(c.dst.tag)].push_back({c.src.instance, c.dst.element, c.src.pin});
  // An ST instance reads a tag it writes through its VAR_EXTERNAL's pins
  // (NAME_in at the scan's start, NAME after it, st_block.hpp): its own last
  // value, not a loop.
  auto own_external = [&](const TagWriter& wr, const ConnectionDecl& c) {
    if (wr.instance != c.dst.instance) return false;
    const BlockTypeInfo& t = *p.instances[static_cast<std::size_t>(c.dst.instance)].type;
    return t.category.rfind("Structured Text", 0) == 0 &&
           t.pins[static_cast<std::size_t>(c.dst.pin)].name == t.pins[static_cast<std::size_t>(wr.pin)].name + "_in";
  };
  for (const auto& c : w.connections) {
    if (!c.dst.is_pin) continue;
    if (p.instances[static_cast<std::size_t>(c.dst.instance)].type->unit_delay) continue;  // reads at the end of the scan
    std::vector<int> from;
    if (c.src.is_pin) from.push_back(c.src.instance);
    else
      for (const TagWriter& wr : tag_writers[static_cast<std::size_t>(c.src.tag)])
        if (p.instances[static_cast<std::size_t>(wr.instance)].task ==
                p.instances[static_cast<std::size_t>(c.dst.instance)].task &&
            !(wr.element && c.src.element && *wr.element != *c.src.element) && !own_external(wr, c))
          from.push_back(wr.instance);
    for (int f : from) {
      if (p.instances[static_cast<std::size_t>(f)].type->unit_delay) continue;  // its output is ready at the start
      succ[static_cast<std::size_t>(f)].emplace_back(c.dst.instance, c.loc);
    }
  }
  // A block linked to another (LinkDecl) runs after it: its target (an
  // axis) has made this scan's state before the blocks that work on it
  // read it or give it commands. A unit-delay target runs first anyway.
  for (std::size_t i = 0; i < p.instances.size(); ++i)
    for (const auto& l : p.instances[i].links)
      if (l.instance >= 0 && !p.instances[static_cast<std::size_t>(l.instance)].type->unit_delay &&
          !p.instances[i].type->unit_delay)
        succ[static_cast<std::size_t>(l.instance)].emplace_back(static_cast<int>(i), l.loc);
  {
    std::vector<int> indeg(p.instances.size(), 0);
    for (const auto& s : succ)
      for (const auto& [to, _] : s) ++indeg[static_cast<std::size_t>(to)];
    for (std::size_t t = 0; t < nt; ++t) {
      std::priority_queue<int, std::vector<int>, std::greater<int>> ready;  // declaration order breaks ties
      std::size_t members = 0;
      for (std::size_t i = 0; i < p.instances.size(); ++i)
        if (static_cast<std::size_t>(p.instances[i].task) == t) {
          if (p.instances[i].type->unit_delay) { o.order[t].push_back(static_cast<int>(i)); continue; }
          ++members;
          if (indeg[i] == 0) ready.push(static_cast<int>(i));
        }
      std::size_t delays = o.order[t].size();
      while (!ready.empty()) {
        int i = ready.top();
        ready.pop();
        o.order[t].push_back(i);
        for (const auto& [to, _] : succ[static_cast<std::size_t>(i)])
          if (--indeg[static_cast<std::size_t>(to)] == 0) ready.push(to);
      }
      if (o.order[t].size() - delays < members) {
        // Report one loop, found by walking edges among the unsorted blocks.
        std::vector<int> colour(p.instances.size(), 0), stack;
        std::vector<SourceLoc> via;
        std::function<bool(int)> dfs = [&](int u) -> bool {
          colour[static_cast<std::size_t>(u)] = 1;
          stack.push_back(u);
          for (const auto& [v, loc] : succ[static_cast<std::size_t>(u)]) {
            if (indeg[static_cast<std::size_t>(v)] == 0) continue;
            via.push_back(loc);
            if (colour[static_cast<std::size_t>(v)] == 1) {
              auto it = std::find(stack.begin(), stack.end(), v);
              std::string path;
              for (auto s = it; s != stack.end(); ++s) path += p.instances[static_cast<std::size_t>(*s)].name + " -> ";
              path += p.instances[static_cast<std::size_t>(v)].name;
              diags.error(loc, "feedback loop without a one-scan delay: " + path + " (break it with a UNIT_DELAY block)");
              return true;
            }
            if (colour[static_cast<std::size_t>(v)] == 0 && dfs(v)) return true;
            via.pop_back();
          }
          stack.pop_back();
          colour[static_cast<std::size_t>(u)] = 2;
          return false;
        };
        for (std::size_t i = 0; i < p.instances.size(); ++i)
          if (static_cast<std::size_t>(p.instances[i].task) == t && indeg[i] > 0 && colour[i] == 0 && dfs(static_cast<int>(i)))
            break;
      }
      o.delays[t] = delays;
    }
  }
  return o;
}

}  // namespace syncplc
