// include: other files' sections merged into the project's root map.
#include <algorithm>
#include <filesystem>

#include "runtime/project/stages.hpp"
#include "runtime/project/yaml_tree.hpp"

namespace syncplc {

const std::set<std::string> kTopKeys = {"project", "include", "tasks", "tags", "blocks", "connections",
                                        "drivers", "traces", "watch", "metrics", "modbus", "store",
                                        "sources", "programs"};

namespace {

void merge_level(ConfigNode& root, const std::string& path, int depth, std::vector<std::string>& include_stack,
                 Diagnostics& diags, std::vector<store::SourceFile>* read, YamlBudget& budget) {
  const ConfigNode* inc = root.find("include");
  if (!inc) return;
  std::vector<const ConfigNode*> files;
  if (inc->is_scalar()) files.push_back(inc);
  else if (inc->is_list()) for (const auto& i : inc->items) files.push_back(&i);
  else { diags.error(inc->loc, "include: a file name or a list of file names"); return; }
  if (depth > 8) { diags.error(inc->loc, "includes nested deeper than 8 levels"); return; }
  for (const ConfigNode* f : files) {
    if (budget.exhausted) return;  // reported where it ran out; reading on would repeat it for every file
    if (!f->is_scalar()) { diags.error(f->loc, "include: expected a file name"); continue; }
    std::filesystem::path p = std::filesystem::path(path).parent_path() / f->scalar;
    std::error_code ec;
    std::string canonical = std::filesystem::weakly_canonical(p, ec).string();
    if (auto it = std::find(include_stack.begin(), include_stack.end(), canonical); it != include_stack.end()) {
      std::string chain;
      for (auto i = it; i != include_stack.end(); ++i) chain += std::filesystem::path(*i).filename().string() + " -> ";
      diags.error(f->loc, "include cycle: " + chain + std::filesystem::path(canonical).filename().string());
      continue;
    }
    Diagnostics local;
    ConfigNode sub = read_yaml_file(p.string(), local, read, &budget);
    for (const auto& e : local.list()) {
      if (e.loc.line == 0) diags.error(f->loc, "include '" + f->scalar + "': " + e.message);
      else diags.error(e.loc, e.message);
    }
    if (!local.empty()) continue;
    if (!sub.is_map()) { diags.error(f->loc, "include '" + f->scalar + "' is not a map of sections"); continue; }
    include_stack.push_back(canonical);
    merge_level(sub, p.string(), depth + 1, include_stack, diags, read, budget);
    include_stack.pop_back();
    for (auto& [k, v] : sub.map) {
      if (k == "include") continue;
      if (k == "project") { diags.error(v.loc, "an included file cannot set 'project'"); continue; }
      if (!kTopKeys.count(k)) continue;  // reported when the included file is read as a map below
      ConfigNode* target = nullptr;
      for (auto& [rk, rv] : root.map)
        if (rk == k) target = &rv;
      if (k == "metrics" || k == "modbus" || k == "store") {
        // A map section comes from one file only.
        if (target) diags.error(v.loc, "'" + k + "' is also set at " + target->loc.text() + ": a map section may come from one file only");
        else root.map.emplace_back(k, v);
        continue;
      }
      if (!target) {
        root.map.emplace_back(k, ConfigNode{ConfigNode::Kind::List, "", {}, {}, v.loc});
        target = &root.map.back().second;
      }
      if (!v.is_list() || !target->is_list()) { diags.error(v.loc, "'" + k + "' must be a list to be included"); continue; }
      target->items.insert(target->items.end(), v.items.begin(), v.items.end());
    }
    for (const auto& [k, v] : sub.map)
      if (!kTopKeys.count(k)) diags.error(v.loc, "unknown top-level key '" + k + "'");
  }
}

}  // namespace

void merge_includes(ConfigNode& root, const std::string& path, Diagnostics& diags, std::vector<store::SourceFile>* read,
                    YamlBudget& budget) {
  std::error_code ec;
  std::vector<std::string> include_stack = {std::filesystem::weakly_canonical(path, ec).string()};  // outermost first
  merge_level(root, path, 0, include_stack, diags, read, budget);
}

}  // namespace syncplc
