#include "runtime/cli/project_upload.hpp"
#include "runtime/project/inside_dir.hpp"
#include "runtime/project/yaml_tree.hpp"

#include <filesystem>
#include <fstream>
#include <sstream>
#include <vector>

namespace syncplc::cli {
namespace {

namespace fs = std::filesystem;

std::optional<std::string> read_file(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  if (!in) return std::nullopt;
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

// The files one file's text names: its include: entries (YAML, followed in
// turn) and its sources: entries (Structured Text): (entry's place, file
// name, key). A file the loader cannot read gives none: the PLC's check
// says where it is broken.
struct Named {
  SourceLoc where;
  std::string file;
  const char* key;  // "include" or "sources"
};

std::vector<Named> files_named_by(const std::string& name, const std::string& text) {
  std::vector<Named> out;
  Diagnostics diags;
  const ConfigNode root = read_yaml_string(text, name, diags);
  if (!diags.empty() || !root.is_map()) return out;
  for (const char* key : {"include", "sources"}) {
    const ConfigNode* n = root.find(key);
    if (!n) continue;
    if (n->is_scalar()) out.push_back({n->loc, n->scalar, key});
    if (n->is_list())
      for (const auto& i : n->items)
        if (i.is_scalar()) out.push_back({i.loc, i.scalar, key});
  }
  return out;
}

}  // namespace

std::optional<ProjectUpload> collect_project(const std::string& main_path, std::string* error) {
  const fs::path main(main_path);
  const fs::path root = main.parent_path();
  ProjectUpload up;
  up.main = main.filename().generic_string();
  auto text = read_file(main);
  if (!text) {
    *error = main_path + ": cannot open file";
    return std::nullopt;
  }
  // Depth first in include order; a file already taken is not read again
  // (an include cycle ends here, and the PLC's check reports it).
  fs::path root_abs = fs::absolute(root.empty() ? fs::current_path() : root).lexically_normal();
  if (!root_abs.has_filename()) root_abs = root_abs.parent_path();  // "/a/b/" -> "/a/b"
  std::vector<std::string> unread = {up.main};
  up.files[up.main] = std::move(*text);
  while (!unread.empty()) {
    const std::string name = unread.back();
    unread.pop_back();
    const fs::path dir = fs::path(name).parent_path();
    auto named = files_named_by(name, up.files[name]);
    for (auto it = named.rbegin(); it != named.rend(); ++it) {
      const auto& [where, file, key] = *it;
      const std::string entry = std::string(key) + " '" + file + "'";
      const fs::path rel = fs::path(file).is_absolute() ? fs::path(file).lexically_normal().lexically_relative(root_abs)
                                                        : (dir / file).lexically_normal();
      const std::string rel_name = rel.generic_string();
      if (rel.empty() || rel_name == ".." || rel_name.rfind("../", 0) == 0) {
        *error = where.text() + ": " + entry + " is outside the project's directory " +
                 (root.empty() ? std::string(".") : root.string()) +
                 ": only files under the main file's directory are sent to the PLC";
        return std::nullopt;
      }
      if (up.files.count(rel_name)) continue;
      // The name is inside; what it points to must be too (a symlink to a
      // file elsewhere is refused here, as the PLC refuses it in an upload).
      if (std::string target; !resolves_inside(root_abs, root_abs / rel, &target)) {
        *error = where.text() + ": " + entry + " resolves to " + target + ", outside the project's directory " +
                 root_abs.string() + " (a symbolic link): only files under the main file's directory are sent to the PLC";
        return std::nullopt;
      }
      auto sub = read_file(root / rel);
      if (!sub) {
        *error = where.text() + ": " + entry + ": cannot open file " + (root / rel).string();
        return std::nullopt;
      }
      up.files[rel_name] = std::move(*sub);
      if (std::string_view(key) == "include") unread.push_back(rel_name);  // followed in turn; an ST source names no files
    }
  }
  return up;
}

}  // namespace syncplc::cli
