// Reads a YAML file into a ConfigNode tree with file:line:col on every node.
#pragma once

#include <cstddef>
#include <set>
#include <string>
#include <vector>

#include "runtime/core/config_node.hpp"
#include "runtime/project/diagnostics.hpp"
#include "runtime/store/source_file.hpp"

namespace syncplc {

// How much YAML one load may hold (docs/project-format.md, "YAML limits"):
// one node per byte of its files, at least kMinNodes, an alias counting as
// the nodes it expands to, and kMaxDepth nested lists and maps. A project
// file and the files it includes share one budget; a file's bytes count once
// however often it is included, its nodes each time. Without it, 600 bytes of
// nested aliases expand to 10^8 nodes ("billion laughs").
class YamlBudget {
 public:
  static constexpr std::size_t kMinNodes = 10'000;
  static constexpr std::size_t kMaxDepth = 64;
  // A file read under `key` (its canonical path) for the first time adds its bytes.
  void add_file(const std::string& key, std::size_t bytes) {
    if (files_.insert(key).second) bytes_ += bytes;
  }
  std::size_t limit() const { return bytes_ > kMinNodes ? bytes_ : kMinNodes; }
  std::size_t used = 0;    // nodes read so far, aliases expanded
  bool exhausted = false;  // a file passed the limit: the load reads no more files

 private:
  std::size_t bytes_ = 0;
  std::set<std::string> files_;
};

// Returns a Null node and records a diagnostic when the file cannot be read
// or parsed, or passes the budget (refused before an alias is expanded).
// Duplicate keys in a map are errors. A file that was read is added to `read`
// (the project store keeps what the loader parsed). Without a budget, the
// file has one of its own.
ConfigNode read_yaml_file(const std::string& path, Diagnostics& diags, std::vector<store::SourceFile>* read = nullptr,
                          YamlBudget* budget = nullptr);
ConfigNode read_yaml_string(const std::string& text, const std::string& name, Diagnostics& diags,
                            YamlBudget* budget = nullptr);

}  // namespace syncplc
