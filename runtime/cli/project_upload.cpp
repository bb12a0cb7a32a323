#include "runtime/cli/project_upload.hpp"

#include <yaml-cpp/yaml.h>

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

// "name:line:col" of a YAML node, 1-based as the loader's messages are.
std::string where(const std::string& name, const YAML::Node& n) {
  const YAML::Mark m = n.Mark();
  return name + ":" + std::to_string(m.line + 1) + ":" + std::to_string(m.column + 1);
}

// The include entries of one file's text: (entry node, file name).
std::vector<std::pair<YAML::Node, std::string>> includes_of(const std::string& text) {
  std::vector<std::pair<YAML::Node, std::string>> out;
  YAML::Node root;
  try {
    root = YAML::Load(text);
  } catch (const YAML::Exception&) {
    return out;  // the PLC's check says where the file is broken
  }
  if (!root.IsMap() || !root["include"]) return out;
  const YAML::Node inc = root["include"];
  if (inc.IsScalar()) out.emplace_back(inc, inc.Scalar());
  if (inc.IsSequence())
    for (const auto& i : inc)
      if (i.IsScalar()) out.emplace_back(i, i.Scalar());
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
  std::vector<std::string> todo = {up.main};
  up.files[up.main] = std::move(*text);
  while (!todo.empty()) {
    const std::string name = todo.back();
    todo.pop_back();
    const fs::path dir = fs::path(name).parent_path();
    auto includes = includes_of(up.files[name]);
    for (auto it = includes.rbegin(); it != includes.rend(); ++it) {
      const auto& [node, file] = *it;
      const fs::path rel = fs::path(file).is_absolute() ? fs::path(file).lexically_normal().lexically_relative(root_abs)
                                                        : (dir / file).lexically_normal();
      const std::string rel_name = rel.generic_string();
      if (rel.empty() || rel_name == ".." || rel_name.rfind("../", 0) == 0) {
        *error = where(name, node) + ": include '" + file + "' is outside the project's directory " +
                 (root.empty() ? std::string(".") : root.string()) +
                 ": only files under the main file's directory are sent to the PLC";
        return std::nullopt;
      }
      if (up.files.count(rel_name)) continue;
      auto sub = read_file(root / rel);
      if (!sub) {
        *error = where(name, node) + ": include '" + file + "': cannot open file " + (root / rel).string();
        return std::nullopt;
      }
      up.files[rel_name] = std::move(*sub);
      todo.push_back(rel_name);
    }
  }
  return up;
}

}  // namespace syncplc::cli
