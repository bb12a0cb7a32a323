#include "runtime/project/system.hpp"

#include <filesystem>
#include <set>

#include "runtime/io/dds/virtual_bus.hpp"
#include "runtime/project/stages.hpp"
#include "runtime/project/yaml_tree.hpp"

namespace syncplc {
namespace system_impl {

void read_node(const ConfigNode& n, const std::filesystem::path& dir, Diagnostics& d, std::set<std::string>& names,
               std::vector<SystemNodeDecl>& out) {
  if (!n.is_map()) {
    d.error(n.loc, "a node is a map {name, project, set}");
    return;
  }
  SystemNodeDecl node;
  node.loc = n.loc;
  for (const auto& [k, v] : n.map) {
    if (k == "name") {
      node.name = v.scalar;
      if (!is_identifier(node.name)) d.error(v.loc, "node name '" + node.name + "' is not an identifier");
      else if (!names.insert(node.name).second) d.error(v.loc, "duplicate node '" + node.name + "'");
    } else if (k == "project") {
      if (!v.is_scalar() || v.scalar.empty()) d.error(v.loc, "project: expected a file name");
      else node.project = (dir / v.scalar).lexically_normal().string();
    } else if (k == "set") {
      if (!v.is_list()) {
        d.error(v.loc, "set: expected a list of instance.param=value");
        continue;
      }
      for (const auto& item : v.items) {
        ParamOverride o;
        if (!item.is_scalar() || !parse_override(item.scalar, o)) d.error(item.loc, "set: expected instance.param=value");
        else node.overrides.push_back(o);
      }
    } else {
      d.error(v.loc, "unknown key '" + k + "' in a node (name, project, set)");
    }
  }
  if (node.name.empty()) d.error(n.loc, "node without a name");
  if (node.project.empty()) d.error(n.loc, "node '" + node.name + "' without a project");
  out.push_back(std::move(node));
}

}  // namespace system_impl

bool is_system_file(const std::string& path) {
  Diagnostics d;
  const ConfigNode root = read_yaml_file(path, d);
  return d.empty() && root.is_map() && root.find("system") != nullptr;
}

std::optional<SystemDecl> read_system(const std::string& path, Diagnostics& d) {
  const std::size_t before = d.size();
  const ConfigNode root = read_yaml_file(path, d);
  if (d.size() != before) return std::nullopt;
  SystemDecl s;
  if (!root.is_map()) {
    d.error(root.loc, "a system file is a map {system, nodes}");
    return std::nullopt;
  }
  const std::filesystem::path dir = std::filesystem::path(path).parent_path();
  std::set<std::string> names;
  for (const auto& [k, v] : root.map) {
    if (k == "system") {
      if (!v.is_map()) {
        d.error(v.loc, "system: expected {name, seed, description}");
        continue;
      }
      for (const auto& [sk, sv] : v.map) {
        if (sk == "name") s.name = sv.scalar;
        else if (sk == "seed") {
          std::string err;
          auto seed = parse_value(IecType::ULINT, sv.scalar, &err);
          if (!seed) d.error(sv.loc, "seed: " + err);
          else s.seed = seed->get<std::uint64_t>();
        } else if (sk != "description") d.error(sv.loc, "unknown key '" + sk + "' in system (name, seed, description)");
      }
    } else if (k == "nodes") {
      if (!v.is_list() || v.items.empty()) {
        d.error(v.loc, "nodes: expected a non-empty list of {name, project}");
        continue;
      }
      for (const auto& n : v.items) system_impl::read_node(n, dir, d, names, s.nodes);
    } else if (k != "description") {
      d.error(v.loc, "unknown key '" + k + "' (system, nodes, description)");
    }
  }
  if (!root.find("nodes")) d.error(root.loc, "a system file needs 'nodes'");
  if (d.size() != before) return std::nullopt;
  return s;
}

int LoadedSystem::find(const std::string& node) const {
  for (std::size_t i = 0; i < nodes.size(); ++i)
    if (nodes[i].name == node) return static_cast<int>(i);
  return -1;
}

LoadedSystem load_system(const SystemDecl& decl, const LoadOptions& options) {
  LoadedSystem s;
  s.name = decl.name;
  s.seed = options.seed ? options.seed : decl.seed;
  s.bus = std::make_shared<VirtualBus>();
  // --set node.instance.param=value: the node's own.
  for (const auto& o : options.overrides) {
    bool known = false;
    for (const auto& n : decl.nodes) known = known || n.name == o.instance;
    if (!known) {
      std::string names;
      for (const auto& n : decl.nodes) names += (names.empty() ? "" : ", ") + n.name;
      s.diagnostics.error(SourceLoc{"command line", 0, 0},
                          "--set " + o.instance + "." + o.param + ": a system's --set starts with a node (" + names + ")");
    }
  }
  if (!s.diagnostics.empty()) return s;
  for (const auto& n : decl.nodes) {
    LoadOptions o = options;
    o.virtual_time = true;
    o.bus = s.bus;
    o.overrides = n.overrides;
    for (const auto& x : options.overrides) {
      if (x.instance != n.name) continue;
      ParamOverride inner;
      if (!parse_override(x.param + "=" + x.value, inner)) {
        s.diagnostics.error(SourceLoc{"command line", 0, 0}, "--set " + x.instance + "." + x.param + ": expected node.instance.param=value");
        continue;
      }
      o.overrides.push_back(inner);
    }
    const std::optional<std::uint64_t> seed = options.seed ? options.seed : decl.seed;
    if (seed) o.seed = mix_seed(*seed, n.name);
    SystemNode node;
    node.name = n.name;
    node.project = n.project;
    node.loaded = load_project(n.project, o);
    for (const auto& d : node.loaded.diagnostics.list()) s.diagnostics.error(d.loc, "node " + n.name + ": " + d.message);
    s.nodes.push_back(std::move(node));
  }
  return s;
}

LoadedSystem load_system_or_project(const std::string& path, const LoadOptions& options) {
  if (is_system_file(path)) {
    LoadedSystem s;
    auto decl = read_system(path, s.diagnostics);
    if (!decl) return s;
    return load_system(*decl, options);
  }
  LoadedSystem s;
  s.bus = std::make_shared<VirtualBus>();
  LoadOptions o = options;
  o.virtual_time = true;
  o.bus = s.bus;
  SystemNode node;
  node.project = path;
  node.loaded = load_project(path, o);
  s.diagnostics = node.loaded.diagnostics;
  s.name = node.loaded.ok() ? node.loaded.program->name : path;
  s.nodes.push_back(std::move(node));
  return s;
}

bool open_system(LoadedSystem& s, std::string* error, std::vector<std::string>* warnings) {
  for (std::size_t i = 0; i < s.nodes.size(); ++i) {
    std::string err;
    if (!s.nodes[i].loaded.program->open_drivers(&err)) {
      *error = (s.nodes[i].name.empty() ? "" : "node " + s.nodes[i].name + ": ") + err;
      for (std::size_t j = 0; j < i; ++j) s.nodes[j].loaded.program->close_drivers();
      return false;
    }
  }
  const auto unmatched = s.bus->unmatched();
  if (unmatched.empty()) return true;
  if (s.nodes.size() == 1 && s.nodes[0].name.empty()) {
    if (warnings) *warnings = unmatched;
    return true;
  }
  *error = "";
  for (const auto& u : unmatched) *error += (error->empty() ? "" : "\n") + u;
  close_system(s);
  return false;
}

void close_system(LoadedSystem& s) noexcept {
  for (auto& n : s.nodes)
    if (n.loaded.program) n.loaded.program->close_drivers();
}

}  // namespace syncplc
