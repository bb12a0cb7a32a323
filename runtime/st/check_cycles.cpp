// The checker's rules against recursion, which IEC 61131-3 forbids: no
// FUNCTION or FUNCTION_BLOCK calls itself, directly or through others, and no
// FUNCTION_BLOCK holds an instance of itself, directly or through its
// members, arrays or structures (its size would be infinite). The code
// generator relies on both: it gives every FUNCTION one static frame and lays
// out every instance at a fixed size. (A FUNCTION holds no FB instance, which
// declare_section refuses, so a cycle of calls is all FUNCTIONs or all FBs.)
//
// Each group of POUs that call one another (a strongly connected component of
// the call graph) is one error, and so is each group of FBs that hold one
// another: reported at the first POU of the group in the source, at its call
// (or declaration) that starts the shortest cycle through it, naming that
// cycle: "FUNCTION F calls itself: F -> G -> F". (A group can hold
// exponentially many cycles; one is enough to show the mistake.) Both steps
// take time linear in the POUs and calls (Tarjan's algorithm, then one
// breadth-first search per group) and neither recurses, so a generated
// program of thousands of POUs neither takes long nor exhausts the stack.
#include <algorithm>
#include <map>
#include <set>
#include <unordered_map>
#include <vector>

#include <fmt/format.h>

#include "runtime/st/check_context.hpp"

namespace syncplc::st {

namespace {

const char* cycle_pou_word(PouKind k) {
  switch (k) {
    case PouKind::Function: return "FUNCTION";
    case PouKind::FunctionBlock: return "FUNCTION_BLOCK";
    case PouKind::Program: return "PROGRAM";
  }
  return "";
}

using Edges = std::map<const PouInfo*, std::vector<Checker::CallEdge>>;

// The POUs as numbers (their order in the source) and each one's edges.
struct PouGraph {
  std::vector<const PouInfo*> pous;
  std::vector<std::vector<std::pair<int, const Checker::CallEdge*>>> out;

  PouGraph(const std::vector<std::unique_ptr<PouInfo>>& all, const Edges& edges) : out(all.size()) {
    std::unordered_map<const PouInfo*, int> number;
    for (const auto& p : all) {
      number.emplace(p.get(), static_cast<int>(pous.size()));
      pous.push_back(p.get());
    }
    for (const auto& [from, list] : edges)
      for (const auto& edge : list) out[number.at(from)].push_back({number.at(edge.callee), &edge});
  }
  int size() const { return static_cast<int>(pous.size()); }
};

// Tarjan's strongly connected components, with an explicit stack: the
// component of each POU.
std::vector<int> components(const PouGraph& g) {
  const int n = g.size();
  std::vector<int> index(n, -1), low(n, 0), component(n, -1), stack;
  std::vector<bool> on_stack(n, false);
  int next_index = 0, next_component = 0;
  struct Frame {
    int v;
    std::size_t edge;
  };
  std::vector<Frame> calls;
  auto open = [&](int v) {
    index[v] = low[v] = next_index++;
    stack.push_back(v);
    on_stack[v] = true;
    calls.push_back({v, 0});
  };
  for (int root = 0; root < n; ++root) {
    if (index[root] != -1) continue;
    open(root);
    while (!calls.empty()) {
      const int v = calls.back().v;
      if (calls.back().edge < g.out[v].size()) {
        const int w = g.out[v][calls.back().edge++].first;
        if (index[w] == -1) open(w);
        else if (on_stack[w]) low[v] = std::min(low[v], index[w]);
        continue;
      }
      calls.pop_back();
      if (!calls.empty()) low[calls.back().v] = std::min(low[calls.back().v], low[v]);
      if (low[v] != index[v]) continue;
      int w = -1;
      do {
        w = stack.back();
        stack.pop_back();
        on_stack[w] = false;
        component[w] = next_component;
      } while (w != v);
      ++next_component;
    }
  }
  return component;
}

// Reports each group (a component with a cycle: two POUs or more, or one
// with an edge to itself) at its first POU, unless `skip` says so. `report`
// gets the POU, the edge that starts the shortest cycle through it, the
// cycle's text and the group's POUs.
template <class Skip, class Report>
void report_groups(const PouGraph& g, Skip skip, Report report) {
  const int n = g.size();
  const std::vector<int> component = components(g);
  std::vector<std::vector<int>> members(n);
  for (int v = 0; v < n; ++v) members[component[v]].push_back(v);
  std::vector<bool> cyclic(n, false), reported(n, false);
  for (int v = 0; v < n; ++v) {
    if (members[component[v]].size() > 1) cyclic[component[v]] = true;
    for (const auto& [w, edge] : g.out[v])
      if (w == v) cyclic[component[v]] = true;
  }
  std::vector<const Checker::CallEdge*> reached_by(n, nullptr);
  std::vector<int> parent(n, -1);
  for (int start = 0; start < n; ++start) {
    const int c = component[start];
    if (!cyclic[c] || reported[c]) continue;
    reported[c] = true;
    const std::vector<int>& group = members[c];
    if (skip(g, group)) continue;
    // Breadth-first inside the group: the shortest way back to `start`,
    // through the earlier edges in the source among ways of one length.
    std::vector<int> queue{start};
    std::vector<const Checker::CallEdge*> path;
    for (std::size_t head = 0; head < queue.size() && path.empty(); ++head) {
      const int at = queue[head];
      for (const auto& [w, edge] : g.out[at]) {
        if (component[w] != c) continue;
        if (w == start) {
          path.push_back(edge);
          for (int p = at; p != start; p = parent[p]) path.push_back(reached_by[p]);
          std::reverse(path.begin(), path.end());
          break;
        }
        if (reached_by[w] != nullptr) continue;
        reached_by[w] = edge;
        parent[w] = at;
        queue.push_back(w);
      }
    }
    for (int v : queue) reached_by[v] = nullptr;
    if (path.empty()) continue;  // cannot be: a group with a cycle has one through each of its POUs
    std::string text = g.pous[start]->name;
    for (const auto* edge : path) text += " -> " + edge->callee->name;
    report(*g.pous[start], *path.front(), text, group);
  }
}

}  // namespace

void Checker::record_call(const PouInfo* callee, const SourceLoc& loc) {
  if (pou_) calls_[pou_].push_back({callee, loc});
}

void Checker::check_cycles() {
  // What each FB holds by value: its variables but the references
  // (VAR_IN_OUT, VAR_EXTERNAL), through arrays and structures, up to the
  // next FB instance. Memoised per type: structures may share members.
  std::map<const Type*, std::vector<const PouInfo*>> held_by_type;
  auto held = [&](const Type* root) -> const std::vector<const PouInfo*>& {
    if (auto it = held_by_type.find(root); it != held_by_type.end()) return it->second;
    std::vector<const PouInfo*> out;
    std::set<const Type*> seen;
    std::vector<const Type*> stack{root};
    while (!stack.empty()) {
      const Type* t = stack.back();
      stack.pop_back();
      if (!seen.insert(t).second) continue;
      switch (t->kind) {
        case Type::Kind::FunctionBlock:
          if (auto it = fb_pous_.find(t->fb); it != fb_pous_.end()) out.push_back(it->second);
          break;
        case Type::Kind::Array: stack.push_back(t->element); break;
        case Type::Kind::Struct:
          for (auto f = t->fields.rbegin(); f != t->fields.rend(); ++f) stack.push_back(f->type);
          break;
        default: break;
      }
    }
    return held_by_type[root] = std::move(out);
  };
  Edges holds;
  for (const auto& p : out_.pous) {
    if (!p->fb) continue;
    std::set<const PouInfo*> known;
    for (const auto& v : p->variables) {
      if (v->scope == VarScope::InOut || v->scope == VarScope::External) continue;
      for (const PouInfo* inner : held(v->type))
        if (known.insert(inner).second) holds[p.get()].push_back({inner, v->loc});
    }
  }
  // An FB in a group that holds itself is one mistake: the calls of those
  // instances are not reported again.
  std::vector<bool> holds_itself(out_.pous.size(), false);
  report_groups(
      PouGraph(out_.pous, holds), [](const PouGraph&, const std::vector<int>&) { return false; },
      [&](const PouInfo& p, const CallEdge& first, const std::string& cycle, const std::vector<int>& group) {
        error(first.loc, fmt::format("FUNCTION_BLOCK {} holds an instance of itself, so its size would be infinite: {}",
                                     p.name, cycle));
        for (int v : group) holds_itself[v] = true;
      });
  report_groups(
      PouGraph(out_.pous, calls_),
      [&](const PouGraph&, const std::vector<int>& group) {
        return std::any_of(group.begin(), group.end(), [&](int v) { return holds_itself[v]; });
      },
      [&](const PouInfo& p, const CallEdge& first, const std::string& cycle, const std::vector<int>&) {
        error(first.loc, fmt::format("{} {} calls itself: {}", cycle_pou_word(p.kind), p.name, cycle));
      });
}

}  // namespace syncplc::st
