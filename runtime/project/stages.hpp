// The stages of a project load (see declarations.hpp), each a function over
// plain data that records its errors and goes on, so that one load reports
// every error of every stage.
#pragma once

#include <optional>
#include <set>
#include <string>
#include <vector>

#include "runtime/core/config_node.hpp"
#include "runtime/project/declarations.hpp"
#include "runtime/project/diagnostics.hpp"
#include "runtime/project/loader.hpp"
#include "runtime/project/yaml_tree.hpp"

namespace syncplc {

// --- shared helpers (literals.cpp) ---------------------------------------------
bool is_identifier(const std::string& s);
// The project seed mixed with a name: each block and driver its own stream.
std::uint64_t mix_seed(std::uint64_t seed, const std::string& name);
// A value of type t written in the file, converted from its unit to `unit`.
std::optional<Cell> parse_literal(IecType t, const std::string& unit, const std::string& text, const SourceLoc& loc,
                                  const std::string& what, Diagnostics& diags);
// A tag's init or safe value: one value for every element or a list.
std::vector<Cell> parse_tag_values(const Tag& t, const ConfigNode& n, const std::string& what, Diagnostics& diags);
// "LREAL", "ARRAY[0..3] OF LREAL"; bounds checked without overflow.
bool parse_tag_type(const std::string& s, IecType& t, std::uint32_t& len, std::int64_t& lower, bool& is_array,
                    std::string& err);

// --- 1. read: YAML -> Declarations -----------------------------------------------
// Top-level keys; include: files merged into the root (read_includes.cpp).
extern const std::set<std::string> kTopKeys;
// Each file read is added to `read`; every file read counts against `budget`
// (the whole load's, yaml_tree.hpp), and none is read once it is used up.
void merge_includes(ConfigNode& root, const std::string& path, Diagnostics& diags, std::vector<store::SourceFile>* read,
                    YamlBudget& budget);
void read_project(const ConfigNode& n, Declarations& p, Diagnostics& diags);  // read_sections.cpp
void read_tasks(const ConfigNode& n, Declarations& p, Diagnostics& diags);
void read_tags(const ConfigNode& n, Declarations& p, Diagnostics& diags);
void read_connections(const ConfigNode& n, Declarations& p, Diagnostics& diags);
void read_refs(const ConfigNode& root, const char* key, RefList& out, Diagnostics& diags);
void read_metrics(const ConfigNode& n, Declarations& p, Diagnostics& diags);
// read_blocks.cpp; empties each block's node once it is read (the tree is not used after stage 1).
void read_blocks(ConfigNode& n, const BlockRegistry& blocks, Declarations& p, Diagnostics& diags);
// read_drivers.cpp. --set driver.key=value rewrites the driver's settings
// before it is created; returns the drivers so changed.
std::set<std::string> override_driver_settings(ConfigNode& drivers, const LoadOptions& opts, Diagnostics& diags);
void read_drivers(const ConfigNode& n, const DriverRegistry& drivers, const LoadOptions& opts, Declarations& p,
                  Diagnostics& diags);
// --set instance.param=value and --set tag=value (check_params.cpp).
void apply_overrides(const LoadOptions& opts, const std::set<std::string>& driver_overrides, Declarations& p,
                     Diagnostics& diags);

// --- 2. check ----------------------------------------------------------------------
void check_params(Declarations& p, Diagnostics& diags);  // check_params.cpp; sizes array pins
void check_links(Declarations& p, Diagnostics& diags);   // check_links.cpp; finds each link's target
void check_st_exclusive_links(Declarations& p, Diagnostics& diags);  // check_st_links.cpp; after check_links
void check_values(Declarations& p, Diagnostics& diags);
// check_connections.cpp
bool resolve_endpoint(const std::string& text, const SourceLoc& loc, const Declarations& p, Endpoint& e,
                      Diagnostics& diags);
Wiring wire_connections(Declarations& p, Diagnostics& diags);
void infer_types(Declarations& p, const Wiring& w, Diagnostics& diags);
void check_connections(const Declarations& p, const Wiring& w, Diagnostics& diags);
void check_refs(const Declarations& p, Diagnostics& diags);
IecType endpoint_type(const Declarations& p, const Endpoint& e, std::uint32_t* length);
// check_owners.cpp
void check_addresses(const Declarations& p, Diagnostics& diags);
void check_modbus_places(const Declarations& p, Diagnostics& diags);
void find_owners(Declarations& p, const Wiring& w, Diagnostics& diags);
void check_writes(const Declarations& p, Diagnostics& diags);  // hmi: readwrite and --set on written tags
void size_write_queues(Declarations& p, Diagnostics& diags);
BlockOrder order_blocks(const Declarations& p, const Wiring& w, Diagnostics& diags);  // order_blocks.cpp

// --- 3. build (build_program.cpp) ------------------------------------------------------
// Null when it cannot be built at all; otherwise the program, which the loader keeps only if no error was reported.
std::unique_ptr<Program> build_program(Declarations& p, const Wiring& w, const BlockOrder& o, Diagnostics& diags);
// What the project says beside the program: the metrics' axis errors resolved in `prog`, the Modbus settings.
MetricsSettings build_metrics(const Declarations& p, const Program& prog, Diagnostics& diags);
ModbusSettings build_modbus(const Declarations& p);
store::StoreSettings build_store(const Declarations& p);

}  // namespace syncplc
