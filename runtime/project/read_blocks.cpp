// Reading the blocks: section: instances, their types, tasks, datatypes,
// parameters and constant inputs as written (checked by check_params.cpp).
#include <algorithm>
#include <utility>

#include "runtime/core/reference.hpp"
#include "runtime/project/read_st.hpp"
#include "runtime/project/stages.hpp"

namespace syncplc {
namespace {

// Empties a block's node once it is read: the declaration holds what is
// needed, and a large project's tree would otherwise stay whole beside the
// declarations until the end of the read (100,000 blocks: about 100 MB).
struct Consumed {
  ConfigNode& node;
  ~Consumed() { node = ConfigNode{}; }
};

}  // namespace

void read_blocks(ConfigNode& n, const BlockRegistry& blocks, Declarations& p, Diagnostics& diags) {
  if (!n.is_list()) { diags.error(n.loc, "blocks: expected a list"); return; }
  p.instances.reserve(p.instances.size() + n.items.size());
  for (auto& b : n.items) {
    Consumed consumed{b};
    if (!b.is_map()) { diags.error(b.loc, "a block instance is a map {name, type, task, ...}"); continue; }
    InstanceDecl in;
    in.loc = b.loc;
    bool ok = true;
    ConfigNode *params = nullptr, *inputs = nullptr, *dtype = nullptr, *task = nullptr;
    for (auto& [k, v] : b.map) {
      if (k == "name") {
        in.name = v.scalar;
        if (!is_identifier(v.scalar)) { diags.error(v.loc, "instance name '" + v.scalar + "' is not an identifier"); ok = false; }
        else if (p.names.count(v.scalar)) { diags.error(v.loc, "duplicate name '" + v.scalar + "' (first defined at " + p.names[v.scalar].text() + ")"); ok = false; }
        else p.names[v.scalar] = v.loc;
      } else if (k == "type") {
        in.type = blocks.find(v.scalar);
        // A FUNCTION_BLOCK of a source with errors: those errors say what is wrong.
        if (!in.type && !(p.st && p.st->declares(v.scalar)))
          diags.error(v.loc, "unknown block type '" + v.scalar + "' (see `syncplc blocks`)");
        if (in.type && !in.type->not_instanceable.empty()) {
          diags.error(v.loc, in.type->not_instanceable);
          in.type = nullptr;
        }
        if (!in.type) ok = false;
      } else if (k == "task") task = &v;
      else if (k == "params") params = &v;
      else if (k == "inputs") inputs = &v;
      else if (k == "datatype") dtype = &v;
      else if (k == "retain" || k == "persistent") {
        std::string err;
        auto c = parse_value(IecType::BOOL, v.scalar, &err);
        if (!c) diags.error(v.loc, k + ": " + err);
        else if (c->get<bool>()) {
          (k == "retain" ? in.retain : in.persistent) = true;
          in.retain_loc = v.loc;
        }
      } else if (k == "description") {}
      else diags.error(v.loc, "unknown key '" + k + "' in a block instance (name, type, task, datatype, params, inputs, retain, persistent, description)");
    }
    mark_st_retain(in);
    if (in.persistent) in.retain = true;  // PERSISTENT implies RETAIN, as for tags
    if (in.name.empty()) { diags.error(b.loc, "block instance without a name"); ok = false; }
    if (!b.find("type")) { diags.error(b.loc, "block instance " + in.name + " has no type"); ok = false; }
    if (!task) { if (p.tasks.size() == 1) in.task = 0; else { diags.error(b.loc, "block instance " + in.name + " has no task"); ok = false; } }
    else if ((in.task = p.task_index(task->scalar)) < 0) { diags.error(task->loc, "unknown task '" + task->scalar + "'"); ok = false; }
    if (!ok || !in.type) {
      if (!in.name.empty()) p.failed_names.insert(in.name);
      continue;
    }
    const auto& T = *in.type;
    if (dtype) {
      auto t = parse_type_name(dtype->scalar);
      if (!T.is_generic()) diags.error(dtype->loc, T.name + " is not generic: it takes no datatype");
      else if (!t) diags.error(dtype->loc, "unknown IEC type '" + dtype->scalar + "'");
      else {
        bool fits = true;
        for (const auto& p : T.pins)
          if (p.cls != TypeClass::Exact && !in_class(*t, p.cls)) {
            diags.error(dtype->loc, T.name + " pin " + p.name + " is " + std::string(class_name(p.cls)) + ": " +
                                     dtype->scalar + " does not belong to it");
            fits = false;
            break;
          }
        if (fits) { in.datatype = *t; in.datatype_fixed = true; }
      }
    }
    in.source.assign(T.pins.size(), -1);
    in.pin_length.assign(T.pins.size(), 1);
    if (params) {
      if (!params->is_map()) diags.error(params->loc, "params: expected a map of parameter: value");
      else
        for (auto& [k, v] : params->map) {
          int i = T.param_index(k);
          if (const int l = T.link_index(k); i < 0 && l >= 0) {
            const LinkDecl& decl = T.links[static_cast<std::size_t>(l)];
            auto named = [](const ConfigNode& n) { return n.is_scalar() && is_identifier(n.scalar); };
            if (!decl.length_param.empty()) {
              if (!v.is_list()) {
                diags.error(v.loc, T.name + "." + k + ": expected a list of names of instances of " + decl.target_type);
                in.links.push_back({l, 0, std::string{}, v.loc, -1});
              } else {
                std::uint32_t e = 0;
                for (const auto& item : v.items) {
                  if (!named(item))
                    diags.error(item.loc, T.name + "." + k + ": expected the name of an instance of " + decl.target_type);
                  in.links.push_back({l, e++, named(item) ? item.scalar : std::string{}, item.loc, -1});
                }
                if (v.items.empty()) in.links.push_back({l, 0, std::string{}, v.loc, -1});  // "given": its length is checked
              }
            } else {
              if (!named(v)) diags.error(v.loc, T.name + "." + k + ": expected the name of an instance of " + decl.target_type);
              in.links.push_back({l, 0, named(v) ? v.scalar : std::string{}, v.loc, -1});
            }
          } else if (i < 0) {
            std::string names;
            for (const auto& q : T.params) names += (names.empty() ? "" : ", ") + q.name;
            for (const auto& q : T.links) names += (names.empty() ? "" : ", ") + q.name;
            diags.error(v.loc, T.name + " has no parameter '" + k + "'" + (names.empty() ? " (it has none)" : " (" + names + ")"));
          } else in.params.emplace_back(i, std::move(v));
        }
    }
    if (inputs) {
      if (!inputs->is_map()) diags.error(inputs->loc, "inputs: expected a map of pin: constant value");
      else
        for (auto& [k, v] : inputs->map) {
          int i = T.pin_index(k);
          if (i < 0) diags.error(v.loc, no_pin_message(in.name, T, k));
          else if (T.pins[static_cast<std::size_t>(i)].dir != PinDir::In) diags.error(v.loc, T.name + "." + k + " is an output: it takes no constant");
          else in.inputs.emplace_back(i, std::move(v));
        }
    }
    for (std::size_t i = 0; i < T.params.size(); ++i)
      if (T.params[i].default_value.empty() && !in.param(i))
        diags.error(b.loc, "block instance " + in.name + " needs parameter " + T.params[i].name);
    // An ST function block's VAR_EXTERNAL X : AXIS_REF names the MC_AXIS X
    // unless params: names another.
    if (T.category.rfind("Structured Text", 0) == 0)
      for (std::size_t l = 0; l < T.links.size(); ++l)
        if (std::none_of(in.links.begin(), in.links.end(), [&](const auto& r) { return r.link == static_cast<int>(l); }))
          in.links.push_back({static_cast<int>(l), 0, T.links[l].name, b.loc, -1});
    for (std::size_t l = 0; l < T.links.size(); ++l)
      if (std::none_of(in.links.begin(), in.links.end(), [&](const auto& r) { return r.link == static_cast<int>(l); }))
        diags.error(b.loc, "block instance " + in.name + " needs parameter " + T.links[l].name + " (the " +
                               T.links[l].target_type + " instance it works on)");
    p.instance_by_name.emplace(in.name, static_cast<int>(p.instances.size()));
    p.instances.push_back(std::move(in));
  }
}

}  // namespace syncplc
