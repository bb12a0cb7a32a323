#include "runtime/core/instance_signature.hpp"

#include <algorithm>

#include "runtime/core/block.hpp"
#include "runtime/core/program.hpp"

namespace syncplc {
namespace {

bool wired(const std::vector<PinFeed>& feeds, std::size_t p) {
  return p < feeds.size() && feeds[p].kind != PinFeed::Kind::None;
}

std::string feed_text(const PinFeed& f) {
  switch (f.kind) {
    case PinFeed::Kind::None: return "unwired";
    case PinFeed::Kind::Constant: return "a constant";
    case PinFeed::Kind::Wired: return f.from;
  }
  return "?";
}

void append(std::string& to, const std::string& what) {
  if (what.empty()) return;
  to += (to.empty() ? "" : ", ") + what;
}

}  // namespace

std::string InstanceSignature::state_identity() const {
  return type_name + " state " + std::to_string(state.layout) + " (" + std::to_string(state.cells) + " cells)";
}

SignatureDiff compare_signatures(const InstanceSignature& o, const InstanceSignature& n) {
  SignatureDiff d;
  d.state_matches = o.type_name == n.type_name && o.state == n.state && n.state.cells > 0;
  auto recreate = [&](std::string why) {
    d.verdict = SignatureVerdict::Recreate;
    d.detail = std::move(why);
    return d;
  };
  if (o.type_name != n.type_name) return recreate("type " + o.type_name + " -> " + n.type_name);
  const BlockTypeInfo& t = *n.type;
  if (o.pin_length != n.pin_length) {
    for (std::size_t p = 0; p < n.pin_length.size() && p < o.pin_length.size(); ++p)
      if (o.pin_length[p] != n.pin_length[p])
        return recreate("array size of " + t.pins[p].name + " " + std::to_string(o.pin_length[p]) + " -> " +
                        std::to_string(n.pin_length[p]));
    return recreate("array sizes changed");
  }
  if (o.params.size() != n.params.size()) return recreate("parameters changed");
  for (std::size_t k = 0; k < n.links.size() && k < o.links.size(); ++k)
    if (o.links[k] != n.links[k]) return recreate(t.links[k].name + " " + o.links[k] + " -> " + n.links[k]);
  if (o.links.size() != n.links.size()) return recreate("links changed");

  // Structure first: one structural parameter re-creates whatever else changed.
  std::string tuned;
  for (std::size_t k = 0; k < n.params.size(); ++k) {
    if (o.params[k].raw == n.params[k].raw) continue;
    const ParamDecl& decl = t.params[k];
    std::string change = decl.name + " " + format_value(decl.type, o.params[k]) + " -> " + format_value(decl.type, n.params[k]);
    if (!decl.tunable) return recreate(change);
    append(tuned, change);
  }

  // Wiring the factory fixed: every pin either instance's factory asked about.
  std::string rewired, unrewirable, moved;
  for (std::size_t p = 0; p < t.pins.size(); ++p) {
    const bool asked = (p < o.seen.size() && o.seen[p] != WiringSeen::NotAsked) ||
                       (p < n.seen.size() && n.seen[p] != WiringSeen::NotAsked);
    const bool was = wired(o.feeds, p), is = wired(n.feeds, p);
    const PinDecl& pin = t.pins[p];
    if (asked && was != is) {
      const std::string what = pin.name + (is ? " now fed from " + feed_text(n.feeds[p]) : " now unwired");
      append(rewired, what);
      if (pin.tunes.empty() && !t.rewire) append(unrewirable, what);
      continue;
    }
    if (p < o.feeds.size() && p < n.feeds.size() && o.feeds[p] != n.feeds[p] && pin.dir == PinDir::In)
      append(moved, pin.name + " " + feed_text(o.feeds[p]) + " -> " + feed_text(n.feeds[p]));
  }
  // The sampling time a factory fixed from the task's period.
  if ((o.period_ns != 0 || n.period_ns != 0) && o.period_ns != n.period_ns) {
    const std::string what = "task period " + format_duration(o.period_ns) + " -> " + format_duration(n.period_ns);
    append(rewired, what);
    if (!t.rewire) append(unrewirable, what);
  }
  if (!unrewirable.empty())
    return recreate(unrewirable + " (" + t.name + " fixes its behaviour from its wiring and period when created)");
  if (!rewired.empty()) {
    d.verdict = SignatureVerdict::Rewire;
    d.detail = rewired;
    append(d.detail, tuned);
    append(d.detail, moved.empty() ? "" : "inputs " + moved);
    return d;
  }
  if (!tuned.empty()) {
    d.verdict = SignatureVerdict::Retune;
    d.detail = tuned;
  }
  append(d.detail, moved.empty() ? "" : "inputs " + moved);
  return d;
}

std::string tag_identity(const Tag& t) {
  if (!t.is_array && t.length == 1) return std::string(type_name(t.type));
  return "ARRAY[" + std::to_string(t.array_lower) + ".." +
         std::to_string(t.array_lower + static_cast<std::int64_t>(t.length) - 1) + "] OF " + std::string(type_name(t.type));
}

}  // namespace syncplc
