// A distributed project: the nodes of one system, each its own project (a
// separate `syncplc run` on its own machine in real time), listed in a
// system file so that `syncplc sim` and `syncplc test` run all of them in
// one process, in virtual time, on one simulated bus (docs/dds.md, "In
// virtual time"):
//
//   system: {name: four_axis_dds, seed: 1}
//   nodes:
//     - {name: master, project: master.yaml}            # relative to this file
//     - {name: axis1, project: axis1.yaml, set: [n1_x.order=0]}
//
// The nodes run in the order listed. A node's seed is the system's seed
// (or --seed) mixed with the node's name, so every node draws its own
// numbers and the run is bit for bit the same for the same seed.
#pragma once

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "runtime/project/loader.hpp"

namespace syncplc {

struct SystemNodeDecl {
  std::string name;
  std::string project;  // path, resolved against the system file's directory
  std::vector<ParamOverride> overrides;
  SourceLoc loc;
};

struct SystemDecl {
  std::string name;
  std::optional<std::uint64_t> seed;
  std::vector<SystemNodeDecl> nodes;
};

// Whether the YAML file at `path` is a system file (its top level has `system:`).
bool is_system_file(const std::string& path);
// Reads a system file; nullopt after reporting every error to `d`.
std::optional<SystemDecl> read_system(const std::string& path, Diagnostics& d);

struct SystemNode {
  std::string name;
  std::string project;
  LoadResult loaded;
};

struct LoadedSystem {
  std::string name;
  std::optional<std::uint64_t> seed;  // the system's (or --seed); each node's is mixed from it
  std::vector<SystemNode> nodes;
  std::shared_ptr<VirtualBus> bus;
  Diagnostics diagnostics;  // every node's load errors (their own files and lines) and the system's
  bool ok() const { return diagnostics.empty() && !nodes.empty(); }
  int find(const std::string& node) const;
};

// Loads every node for virtual time on one shared bus. options.seed
// overrides the system's seed; options.overrides are "node.instance.param=v"
// (instance = the node's name, param = the rest: parse_override's split).
LoadedSystem load_system(const SystemDecl& decl, const LoadOptions& options);
// Loads `path`: a system file, or a single project as a system of one node
// named "" (its bus its own). Errors in `diagnostics`.
LoadedSystem load_system_or_project(const std::string& path, const LoadOptions& options);
// Opens every node's drivers (which registers their topics on the bus) and
// checks that every subscription has a publisher: false with *error. A
// system of one node (a project simulated on its own) may subscribe to
// what nobody publishes: `warnings` gets those lines instead.
bool open_system(LoadedSystem& s, std::string* error, std::vector<std::string>* warnings = nullptr);
void close_system(LoadedSystem& s) noexcept;

}  // namespace syncplc
