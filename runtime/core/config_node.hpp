// A parsed configuration tree with source locations, so that components
// outside the loader (I/O drivers) can read their own settings and report
// errors as file:line:col without knowing the file format.
#pragma once

#include <string>
#include <utility>
#include <vector>

namespace syncplc {

struct SourceLoc {
  std::string file;
  int line = 0;  // 1-based; 0 = unknown
  int col = 0;
  std::string text() const {
    return file + ":" + std::to_string(line) + ":" + std::to_string(col);
  }
};

struct ConfigNode {
  enum class Kind { Null, Scalar, List, Map };
  Kind kind = Kind::Null;
  std::string scalar;
  std::vector<ConfigNode> items;                         // List
  std::vector<std::pair<std::string, ConfigNode>> map;   // Map, in file order
  SourceLoc loc;

  const ConfigNode* find(const std::string& key) const {
    for (const auto& [k, v] : map)
      if (k == key) return &v;
    return nullptr;
  }
  bool is_scalar() const { return kind == Kind::Scalar; }
  bool is_list() const { return kind == Kind::List; }
  bool is_map() const { return kind == Kind::Map; }
};

}  // namespace syncplc
