// Connections: each end resolved to a pin or a tag (one reference parser,
// runtime/core/reference.hpp), inputs given one source each, generic types
// inferred, types checked, required inputs found connected; trace, watch
// and metrics references resolved the same way.
#include <algorithm>
#include <cctype>
#include <cmath>
#include <deque>
#include <utility>

#include "runtime/core/reference.hpp"
#include "runtime/core/units.hpp"
#include "runtime/project/stages.hpp"

namespace syncplc {
namespace {

bool endpoint_type_known(const Declarations& p, const Endpoint& e) {
  if (!e.is_pin || e.variable_type) return true;
  const auto& in = p.instances[static_cast<std::size_t>(e.instance)];
  const auto& pd = in.type->pins[static_cast<std::size_t>(e.pin)];
  return pd.cls == TypeClass::Exact || in.datatype.has_value();
}

const std::string& endpoint_unit(const Declarations& p, const Endpoint& e) {
  static const std::string none;
  if (!e.is_pin) return p.tags[static_cast<std::size_t>(e.tag)].tag.unit;
  if (e.variable_type) return none;  // ST variables carry no unit
  return p.instances[static_cast<std::size_t>(e.instance)].type->pins[static_cast<std::size_t>(e.pin)].unit;
}

// A connection copies the value as it is: both ends must mean the same unit
// (m and rad differ in dimension; mm and m in scale, and would be off by
// 1000). An end without a unit takes any, as a constant without one does.
void check_units(const Declarations& p, const ConnectionDecl& c, Diagnostics& diags) {
  const std::string& us = endpoint_unit(p, c.src);
  const std::string& ud = endpoint_unit(p, c.dst);
  const UnitCopy fit = unit_copy(us, ud);
  if (fit == UnitCopy::Fits) return;
  diags.error(c.loc, "unit mismatch: " + c.src.text + " is in " + us + ", " + c.dst.text + " in " + ud +
                         (fit == UnitCopy::OtherDimension ? " (another dimension)"
                                                          : " (a connection copies the value: scale it with a MUL block, or "
                                                            "give both ends one unit)"));
}

}  // namespace

IecType endpoint_type(const Declarations& p, const Endpoint& e, std::uint32_t* length) {
  if (!e.is_pin) {
    const Tag& t = p.tags[static_cast<std::size_t>(e.tag)].tag;
    if (length) *length = e.element ? 1 : t.length;
    return t.type;
  }
  if (e.variable_type) {
    if (length) *length = 1;
    return *e.variable_type;
  }
  const auto& in = p.instances[static_cast<std::size_t>(e.instance)];
  const auto& pd = in.type->pins[static_cast<std::size_t>(e.pin)];
  if (length) *length = e.element ? 1 : in.pin_length[static_cast<std::size_t>(e.pin)];
  return pd.cls == TypeClass::Exact ? pd.type : in.datatype.value_or(IecType::LREAL);
}

namespace {

// instance.path naming a variable of an ST instance rather than one of its
// pins: resolved to an element of its variables pin. Yes when it is one
// (`e` filled), No when the text names no such variable (a pin or a tag:
// the caller goes on), Failed when it names one wrongly (reported).
enum class VariableEnd { Yes, No, Failed };

VariableEnd resolve_variable_end(const std::string& written, const SourceLoc& loc, const Declarations& p, Endpoint& e,
                                 Diagnostics& diags) {
  std::string_view trimmed = written;
  while (!trimmed.empty() && std::isspace(static_cast<unsigned char>(trimmed.front()))) trimmed.remove_prefix(1);
  while (!trimmed.empty() && std::isspace(static_cast<unsigned char>(trimmed.back()))) trimmed.remove_suffix(1);
  const std::string text(trimmed);
  const auto dot = text.find('.');
  if (dot == std::string::npos) return VariableEnd::No;
  const int i = p.instance_index(text.substr(0, dot));
  if (i < 0) return VariableEnd::No;
  const auto& in = p.instances[static_cast<std::size_t>(i)];
  const BlockTypeInfo& T = *in.type;
  const std::string path = text.substr(dot + 1);
  // A pin of the type stays a pin (an ST FB's outputs are pins too).
  if (!T.names_variable(path) || T.pin_index(path.substr(0, path.find_first_of(".["))) >= 0) return VariableEnd::No;
  std::string why;
  const auto v = T.variable(path, &why);
  e.loc = loc;
  e.text = text;
  if (!v) {
    diags.error(loc, text + ": " + why);
    return VariableEnd::Failed;
  }
  e.is_pin = true;
  e.instance = i;
  e.pin = T.variables_pin;
  e.element = v->element;
  e.variable_type = v->type;
  return VariableEnd::Yes;
}

}  // namespace

bool resolve_endpoint(const std::string& text, const SourceLoc& loc, const Declarations& p, Endpoint& e,
                      Diagnostics& diags) {
  switch (resolve_variable_end(text, loc, p, e, diags)) {
    case VariableEnd::Yes: return true;
    case VariableEnd::Failed: return false;
    case VariableEnd::No: break;
  }
  std::string why;
  auto ref = parse_reference(text, &why);
  e.loc = loc;
  if (!ref) {
    e.text = text;
    diags.error(loc, why);
    return false;
  }
  e.text = ref->text;
  if (ref->dotted()) {
    const std::string& inst = ref->owner;
    e.instance = p.instance_index(inst);
    if (e.instance < 0) {
      if (p.failed_names.count(inst)) return false;  // its declaration's error says enough
      if (p.names.count(inst)) diags.error(loc, "'" + inst + "' is not a block instance (connect drivers with bind:)");
      else diags.error(loc, unknown_instance_message(inst));
      return false;
    }
    const auto& in = p.instances[static_cast<std::size_t>(e.instance)];
    const auto& T = *in.type;
    e.pin = T.pin_index(ref->member);
    if (e.pin < 0) {
      diags.error(loc, no_pin_message(inst, T, ref->member));
      return false;
    }
    e.is_pin = true;
    if (ref->index) {
      const auto& decl = T.pins[static_cast<std::size_t>(e.pin)];
      if (!decl.is_array()) { diags.error(loc, "pin " + ref->base + " is not an array"); return false; }
      if (!in.params_ok) return false;  // its length is unknown; the parameter's error says why
      auto el = element_of(*ref, 1, in.pin_length[static_cast<std::size_t>(e.pin)], &why);  // array pins are ARRAY[1..n]
      if (!el) { diags.error(loc, why); return false; }
      e.element = *el;
    }
    return true;
  }
  e.tag = p.tag_index(ref->base);
  if (e.tag < 0 && p.failed_names.count(ref->base)) return false;
  if (e.tag < 0) { diags.error(loc, unknown_tag_message(ref->base)); return false; }
  if (ref->index) {
    const Tag& t = p.tags[static_cast<std::size_t>(e.tag)].tag;
    if (!t.is_array) { diags.error(loc, "tag " + ref->base + " is not an array"); return false; }
    auto el = element_of(*ref, t.array_lower, t.length, &why);
    if (!el) { diags.error(loc, why); return false; }
    e.element = *el;
  }
  return true;
}

Wiring wire_connections(Declarations& p, Diagnostics& diags) {
  Wiring w;
  w.connections.reserve(p.connections.size());
  for (const auto& c : p.connections) {
    ConnectionDecl cd;
    cd.loc = c.loc;
    bool src_ok = resolve_endpoint(c.src, c.src_loc, p, cd.src, diags);
    bool ok = resolve_endpoint(c.dst, c.dst_loc, p, cd.dst, diags) && src_ok;
    if (!src_ok && cd.dst.is_pin) {
      // The input is wired, to something broken (reported): no "must be connected" on top.
      auto& di = p.instances[static_cast<std::size_t>(cd.dst.instance)];
      if (di.source[static_cast<std::size_t>(cd.dst.pin)] == -1) di.source[static_cast<std::size_t>(cd.dst.pin)] = kBrokenSource;
    }

    if (!ok) continue;
    if (cd.src.is_pin) {
      const auto& pd = p.instances[static_cast<std::size_t>(cd.src.instance)].type->pins[static_cast<std::size_t>(cd.src.pin)];
      if (pd.dir != PinDir::Out) { diags.error(c.src_loc, cd.src.text + " is an input: a connection starts at an output or a tag"); continue; }
    }
    if (cd.dst.variable_type) {
      const auto& di = p.instances[static_cast<std::size_t>(cd.dst.instance)];
      diags.error(c.dst_loc, cd.dst.text + " is a variable of ST instance " + di.name +
                                 ": a connection ends at an input or a tag (the program reads a tag through VAR_EXTERNAL)");
      continue;
    }
    if (cd.dst.is_pin) {
      const auto& pd = p.instances[static_cast<std::size_t>(cd.dst.instance)].type->pins[static_cast<std::size_t>(cd.dst.pin)];
      if (pd.dir != PinDir::In) { diags.error(c.dst_loc, cd.dst.text + " is an output: a connection ends at an input or a tag"); continue; }
    }
    if (!cd.src.is_pin && !cd.dst.is_pin) { diags.error(c.loc, "tag-to-tag connection: copy a tag through a MOVE block"); continue; }
    if (cd.src.is_pin && cd.dst.is_pin &&
        p.instances[static_cast<std::size_t>(cd.src.instance)].task != p.instances[static_cast<std::size_t>(cd.dst.instance)].task) {
      diags.error(c.loc, "blocks in different tasks exchange data through a tag: connect " + cd.src.text + " -> a tag -> " + cd.dst.text);
      continue;
    }
    if (cd.dst.is_pin) {
      auto& di = p.instances[static_cast<std::size_t>(cd.dst.instance)];
      auto pi = static_cast<std::size_t>(cd.dst.pin);
      auto already = [&](int ci) {
        const auto& o = w.connections[static_cast<std::size_t>(ci)];
        diags.error(c.dst_loc, cd.dst.text + " already has a source (" + o.src.text + " -> " + o.dst.text + " at " + o.loc.text() + ")");
      };
      if (di.source[pi] >= 0) { already(di.source[pi]); continue; }
      if (di.input(pi)) { diags.error(c.dst_loc, cd.dst.text + " is connected and also given a constant in inputs:"); continue; }
      if (cd.dst.element) {
        auto& es = di.element_source.of(pi);
        if (es.empty()) es.assign(di.pin_length[pi], -1);
        int& slot = es[*cd.dst.element];
        if (slot >= 0) { already(slot); continue; }
        slot = static_cast<int>(w.connections.size());
      } else {
        const auto& es = std::as_const(di).element_source[pi];
        auto taken = std::find_if(es.begin(), es.end(), [](int c) { return c >= 0; });
        if (taken != es.end()) { already(*taken); continue; }
        di.source[pi] = static_cast<int>(w.connections.size());
      }
    }
    w.connections.push_back(std::move(cd));
  }
  return w;
}

void infer_types(Declarations& p, const Wiring& w, Diagnostics& diags) {
  // A generic instance takes the type of whatever typed end it is connected
  // to; what is still open takes the block's default. A worklist of
  // connections, so that a chain settles in linear time whichever way it
  // was written: first every connection in file order, then the connections
  // of each instance as it gets its type.
  std::vector<std::vector<std::size_t>> touching(p.instances.size());
  for (std::size_t ci = 0; ci < w.connections.size(); ++ci)
    for (const Endpoint* e : {&w.connections[ci].src, &w.connections[ci].dst})
      if (e->is_pin) touching[static_cast<std::size_t>(e->instance)].push_back(ci);
  std::deque<std::size_t> work;
  for (std::size_t ci = 0; ci < w.connections.size(); ++ci) work.push_back(ci);
  auto typed = [&](std::size_t i) {
    for (std::size_t ci : touching[i]) work.push_back(ci);
  };
  auto settle = [&](const Endpoint& a, const Endpoint& b) {
    if (!a.is_pin) return;
    auto& in = p.instances[static_cast<std::size_t>(a.instance)];
    const auto& pd = in.type->pins[static_cast<std::size_t>(a.pin)];
    if (pd.cls == TypeClass::Exact || in.datatype || !endpoint_type_known(p, b)) return;
    IecType t = endpoint_type(p, b, nullptr);
    if (!in_class(t, pd.cls)) return;  // reported as a mismatch later
    in.datatype = t;
    typed(static_cast<std::size_t>(a.instance));
  };
  // Defaults one instance at a time, so its neighbours can infer from it: the
  // first (in declaration order) whose default belongs to the class of every
  // still-open generic pin it is connected to (so MOVE before CTU, CTU.CV ->
  // MOVE.IN gives MOVE<INT>, not a clash with LREAL), else the first.
  auto suits_neighbours = [&](std::size_t i) {
    IecType t = *p.instances[i].type->default_datatype;
    for (std::size_t ci : touching[i]) {
      const auto& c = w.connections[ci];
      for (const auto& [mine, other] : {std::pair{&c.src, &c.dst}, std::pair{&c.dst, &c.src}}) {
        if (!mine->is_pin || static_cast<std::size_t>(mine->instance) != i || !other->is_pin) continue;
        const auto& o = p.instances[static_cast<std::size_t>(other->instance)];
        const auto& op = o.type->pins[static_cast<std::size_t>(other->pin)];
        if (op.cls != TypeClass::Exact && !o.datatype && !in_class(t, op.cls)) return false;
      }
    }
    return true;
  };
  auto open = [&](std::size_t i) {
    const auto& in = p.instances[i];
    return in.type->is_generic() && !in.datatype && in.type->default_datatype;
  };
  std::size_t first_open = 0;  // instances before it all have their type
  for (;;) {
    while (!work.empty()) {
      const auto& c = w.connections[work.front()];
      work.pop_front();
      settle(c.src, c.dst);
      settle(c.dst, c.src);
    }
    while (first_open < p.instances.size() && !open(first_open)) ++first_open;
    if (first_open == p.instances.size()) break;
    std::size_t pick = first_open;
    for (std::size_t i = first_open; i < p.instances.size(); ++i)
      if (open(i) && suits_neighbours(i)) { pick = i; break; }
    p.instances[pick].datatype = p.instances[pick].type->default_datatype;
    typed(pick);
  }
  for (auto& in : p.instances)
    if (in.type->is_generic() && !in.datatype)
      diags.error(in.loc, "cannot infer the data type of " + in.name + " (" + in.type->name + "): set datatype:");
}

void check_connections(const Declarations& p, const Wiring& w, Diagnostics& diags) {
  for (const auto& c : w.connections) {
    std::uint32_t ls = 1, ld = 1;
    IecType ts = endpoint_type(p, c.src, &ls), td = endpoint_type(p, c.dst, &ld);
    auto show = [&](IecType t, std::uint32_t l) {
      return std::string(type_name(t)) + (l > 1 ? "[" + std::to_string(l) + "]" : "");
    };
    auto lengths_known = [&](const Endpoint& e) {
      return !e.is_pin || p.instances[static_cast<std::size_t>(e.instance)].params_ok;
    };
    if (ts == td && ls != ld && (!lengths_known(c.src) || !lengths_known(c.dst))) continue;
    if (ts != td || ls != ld)
      diags.error(c.loc, "type mismatch: " + c.src.text + " is " + show(ts, ls) + ", " + c.dst.text + " is " + show(td, ld));
    else if (c.dst.is_pin) {
      const auto& in = p.instances[static_cast<std::size_t>(c.dst.instance)];
      const auto& pd = in.type->pins[static_cast<std::size_t>(c.dst.pin)];
      if (pd.cls != TypeClass::Exact && !in_class(ts, pd.cls))
        diags.error(c.loc, c.dst.text + " takes " + std::string(class_name(pd.cls)) + ", not " + std::string(type_name(ts)));
    }
    check_units(p, c, diags);
  }
  // Required inputs.
  for (const auto& in : p.instances)
    for (std::size_t i = 0; i < in.type->pins.size(); ++i) {
      const auto& pd = in.type->pins[i];
      if (pd.dir != PinDir::In || !pd.required || in.source[i] != -1 || in.input(i)) continue;
      const auto& es = in.element_source[i];
      if (es.empty()) {
        diags.error(in.loc, "input " + in.name + "." + pd.name + " must be connected or given a value in inputs:");
      } else if (auto open = std::find(es.begin(), es.end(), -1); open != es.end()) {
        diags.error(in.loc, "input " + in.name + "." + pd.name + "[" + std::to_string(open - es.begin() + 1) +
                             "] must be connected: connect every element of a required array input, or the whole array");
      }
    }
}

void check_refs(const Declarations& p, Diagnostics& diags) {
  for (const auto& [ref, loc] : p.traces) {
    Endpoint e;
    std::size_t before = diags.size();
    if (!resolve_endpoint(ref, loc, p, e, diags)) {
      for (std::size_t k = before; k < diags.size(); ++k) diags.prefix_message(k, "trace: ");
      continue;
    }
    if (e.variable_type) continue;  // one element of an ST instance's variables
    bool array = e.is_pin ? p.instances[static_cast<std::size_t>(e.instance)].type->pins[static_cast<std::size_t>(e.pin)].is_array()
                          : p.tags[static_cast<std::size_t>(e.tag)].tag.is_array;
    if (array && !e.element) diags.error(loc, "trace: " + ref + " is an array; trace its elements (" + ref + "[i])");
  }
  for (const auto& [ref, loc] : p.watch)
    if (p.tag_index(ref) < 0 && !p.failed_names.count(ref)) diags.error(loc, "watch: unknown tag '" + ref + "'");
  for (const auto& [ref, loc] : p.axis_errors) {
    Endpoint e;
    std::size_t before = diags.size();
    if (!resolve_endpoint(ref, loc, p, e, diags))
      for (std::size_t k = before; k < diags.size(); ++k) diags.prefix_message(k, "metrics: ");
  }
}

}  // namespace syncplc
