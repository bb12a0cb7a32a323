// The project loader: reads a project file into declarations, checks
// them, builds the Program (the stages: declarations.hpp, stages.hpp).
// Every stage runs whatever failed before it, so one load reports every
// error; a failed load returns no Program.
#include "runtime/project/loader.hpp"

#include "fblocks/library.hpp"
#include "runtime/io/drivers.hpp"
#include "runtime/project/modbus_settings.hpp"
#include "runtime/project/read_st.hpp"
#include "runtime/project/store_section.hpp"
#include "runtime/project/stages.hpp"
#include "runtime/project/yaml_tree.hpp"
#include "runtime/store/project_store.hpp"
#include "runtime/store/trend_series.hpp"

namespace syncplc {
namespace {

// Stage 1: the YAML tree into declarations. The tree is not used after it.
Declarations read_declarations(ConfigNode& root, const std::string& path, const LoadOptions& opts, Diagnostics& diags,
                               std::vector<store::SourceFile>& sources, YamlBudget& budget) {
  Declarations p;
  p.file = path;
  const BlockRegistry& builtin = opts.blocks ? *opts.blocks : builtin_blocks();
  const DriverRegistry& drivers = opts.drivers ? *opts.drivers : builtin_drivers();
  merge_includes(root, path, diags, &sources, budget);
  for (const auto& [k, v] : root.map)
    if (!kTopKeys.count(k))
      diags.error(v.loc, "unknown top-level key '" + k + "' (project, include, tasks, tags, blocks, programs, sources, connections, drivers, traces, watch, metrics, modbus, store)");
  // project: first (st_engine), then Structured Text: its FUNCTION_BLOCKs
  // are block types of blocks:.
  if (auto* n = root.find("project")) read_project(*n, p, diags);
  p.st = read_st_sources(root.find("sources"), builtin, p.st_native, diags, &sources);
  const BlockRegistry& blocks = *p.st->blocks;
  if (opts.seed) p.seed = *opts.seed;
  if (auto* n = root.find("tasks")) read_tasks(*n, p, diags);
  if (p.tasks.empty()) diags.error(root.loc, "the project has no tasks");
  if (auto* n = root.find("tags")) read_tags(*n, p, diags);
  if (auto* n = root.find("modbus")) read_modbus_section(*n, p.modbus, diags);
  if (auto* n = root.find("store")) read_store_section(*n, p.store, diags);
  for (auto& [k, v] : root.map)
    if (k == "blocks") read_blocks(v, blocks, p, diags);
  if (auto* n = root.find("programs")) read_programs(*n, *p.st, p, diags);
  std::set<std::string> driver_overrides;
  for (auto& [k, v] : root.map)
    if (k == "drivers") driver_overrides = override_driver_settings(v, opts, diags);
  if (auto* n = root.find("drivers")) read_drivers(*n, drivers, opts, p, diags);
  apply_overrides(opts, driver_overrides, p, diags);
  if (auto* n = root.find("connections")) read_connections(*n, p, diags);
  wire_externals(*p.st, p, diags);
  read_refs(root, "traces", p.traces, diags);
  read_refs(root, "watch", p.watch, diags);
  if (auto* n = root.find("metrics")) read_metrics(*n, p, diags);
  return p;
}

// `budget`: what reading the project file used of the load's YAML budget.
LoadResult load_tree(ConfigNode root, const std::string& path, const LoadOptions& opts, Diagnostics diags,
                     std::vector<store::SourceFile> sources, YamlBudget& budget) {
  LoadResult r;
  r.sources = std::move(sources);
  if (!diags.empty()) {
    r.diagnostics = std::move(diags);
    return r;
  }
  if (!root.is_map()) {
    diags.error(root.loc.line ? root.loc : SourceLoc{path, 1, 1}, "a project file is a map with tasks, tags, blocks, connections ...");
    r.diagnostics = std::move(diags);
    return r;
  }
  Declarations p = read_declarations(root, path, opts, diags, r.sources, budget);
  root = ConfigNode{};  // the declarations hold what is needed (a large project's tree is most of the memory)
  auto cancelled = [&] {
    if (!opts.cancel || !opts.cancel->load(std::memory_order_relaxed)) return false;
    diags.error(SourceLoc{path, 1, 1}, "the load was cancelled: the PLC is stopping");
    r.diagnostics = std::move(diags);
    return true;
  };
  if (cancelled()) return r;

  // Stage 2: checks.
  check_addresses(p, diags);
  check_modbus_places(p, diags);
  check_params(p, diags);  // before connections: parameters size the array pins
  check_links(p, diags);
  check_st_exclusive_links(p, diags);
  Wiring w = wire_connections(p, diags);
  std::vector<ConnectionText>().swap(p.connections);  // resolved into w, not needed again (100,000 connections: 14 MB)
  infer_types(p, w, diags);
  check_connections(p, w, diags);
  find_owners(p, w, diags);
  check_writes(p, diags);
  size_write_queues(p, diags);
  check_values(p, diags);
  BlockOrder o = order_blocks(p, w, diags);
  check_refs(p, diags);
  if (cancelled()) return r;

  // Retain's "changed project" (docs/store.md): hashed before the build, so
  // that the files' copies it makes are gone before the program's memory peaks.
  const std::string content_hash = diags.empty() ? store::make_content(r.sources).hash : std::string();

  // Stage 3: the Program (its blocks' factories report errors too).
  std::unique_ptr<Program> prog = build_program(p, w, o, diags);
  if (prog) r.metrics = build_metrics(p, *prog, diags);
  if (diags.empty()) {
    r.program = std::move(prog);
    r.modbus = build_modbus(p);
    r.store = build_store(p);
    r.store.content_hash = content_hash;
    store::build_trend_folds(*r.program, r.store);  // the tasks' historian buckets, sized before they run
    r.st = summarize_st(*p.st, p.st_native);
  }
  r.diagnostics = std::move(diags);
  return r;
}

}  // namespace

bool parse_override(const std::string& text, ParamOverride& out) {
  auto eq = text.find('=');
  if (eq == std::string::npos || eq == 0) return false;
  std::string lhs = text.substr(0, eq);
  out.value = text.substr(eq + 1);
  auto dot = lhs.find('.');
  if (dot == std::string::npos) {
    out.instance = lhs;  // a tag's initial value
    out.param.clear();
  } else {
    out.instance = lhs.substr(0, dot);
    out.param = lhs.substr(dot + 1);
    if (out.param.empty()) return false;
  }
  return !out.value.empty();
}

LoadResult load_project_text(const std::string& text, const std::string& name, const LoadOptions& options) {
  Diagnostics d;
  YamlBudget budget;
  ConfigNode root = read_yaml_string(text, name, d, &budget);
  return load_tree(std::move(root), name, options, std::move(d), {{name, text}}, budget);
}

LoadResult load_project(const std::string& path, const LoadOptions& options) {
  Diagnostics d;
  std::vector<store::SourceFile> sources;
  YamlBudget budget;  // the project file and every file it includes
  ConfigNode root = read_yaml_file(path, d, &sources, &budget);
  return load_tree(std::move(root), path, options, std::move(d), std::move(sources), budget);
}

}  // namespace syncplc
