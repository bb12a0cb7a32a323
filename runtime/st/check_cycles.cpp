// The checker's rules against recursion, which IEC 61131-3 forbids: no
// FUNCTION or FUNCTION_BLOCK calls itself, directly or through others, and no
// FUNCTION_BLOCK holds an instance of itself, directly or through its
// members, arrays or structures (its size would be infinite). The code
// generator relies on both: it gives every FUNCTION one static frame and lays
// out every instance at a fixed size. (A FUNCTION holds no FB instance, which
// declare_section refuses, so a cycle of calls is all FUNCTIONs or all FBs.)
//
// Every POU on a cycle is named in one error at least, and no more errors are
// given: in source order, a POU not yet named gets the shortest cycle through
// it, reported at its call (or declaration) that starts it: "FUNCTION F calls
// itself: F -> G -> F". (Naming every cycle could take exponentially many.)
// The searches are iterative (breadth-first), so a long chain of POUs cannot
// exhaust the stack.
#include <deque>
#include <map>
#include <set>
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

// The shortest path of edges from `start` back to `start` (its first edge
// first), or none. Among paths of one length, the one through the earlier
// edges in the source.
std::vector<const Checker::CallEdge*> shortest_cycle(const PouInfo* start, const Edges& edges) {
  std::map<const PouInfo*, const Checker::CallEdge*> reached_by;  // the edge a POU was first reached by
  std::map<const PouInfo*, const PouInfo*> parent;
  std::deque<const PouInfo*> queue{start};
  while (!queue.empty()) {
    const PouInfo* at = queue.front();
    queue.pop_front();
    auto it = edges.find(at);
    if (it == edges.end()) continue;
    for (const auto& edge : it->second) {
      if (edge.callee == start) {
        std::vector<const Checker::CallEdge*> path{&edge};
        for (const PouInfo* p = at; p != start; p = parent[p]) path.insert(path.begin(), reached_by[p]);
        return path;
      }
      if (reached_by.count(edge.callee) != 0) continue;
      reached_by[edge.callee] = &edge;
      parent[edge.callee] = at;
      queue.push_back(edge.callee);
    }
  }
  return {};
}

std::string cycle_text(const PouInfo* start, const std::vector<const Checker::CallEdge*>& path) {
  std::string text = start->name;
  for (const auto* edge : path) text += " -> " + edge->callee->name;
  return text;
}

// Reports every cycle of `edges` once; a POU in `done` (already in a reported
// cycle) starts no search. Adds the POUs of each cycle to `done`.
template <class Report>
void report_cycles(const std::vector<std::unique_ptr<PouInfo>>& pous, const Edges& edges,
                   std::set<const PouInfo*>& done, Report report) {
  for (const auto& p : pous) {
    if (done.count(p.get()) != 0) continue;
    const auto path = shortest_cycle(p.get(), edges);
    if (path.empty()) continue;
    report(*p, *path.front(), cycle_text(p.get(), path));
    for (const auto* edge : path) done.insert(edge->callee);
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
    for (const auto& v : p->variables) {
      if (v->scope == VarScope::InOut || v->scope == VarScope::External) continue;
      for (const PouInfo* inner : held(v->type)) {
        auto& list = holds[p.get()];
        bool known = false;
        for (const auto& edge : list) known = known || edge.callee == inner;
        if (!known) list.push_back({inner, v->loc});
      }
    }
  }
  std::set<const PouInfo*> done;
  report_cycles(out_.pous, holds, done, [&](const PouInfo& p, const CallEdge& first, const std::string& cycle) {
    error(first.loc, fmt::format("FUNCTION_BLOCK {} holds an instance of itself, so its size would be infinite: {}",
                                 p.name, cycle));
  });
  // An FB in a cycle of instances is one mistake: its calls of those
  // instances are not reported again.
  report_cycles(out_.pous, calls_, done, [&](const PouInfo& p, const CallEdge& first, const std::string& cycle) {
    error(first.loc, fmt::format("{} {} calls itself: {}", cycle_pou_word(p.kind), p.name, cycle));
  });
}

}  // namespace syncplc::st
