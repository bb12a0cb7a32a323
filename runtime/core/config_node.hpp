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

struct ConfigEntry;

struct ConfigNode {
  enum class Kind { Null, Scalar, List, Map };
  Kind kind = Kind::Null;
  std::string scalar;
  std::vector<ConfigNode> items;                         // List
  std::vector<ConfigEntry> map;                           // Map, in file order
  SourceLoc loc;

  const ConfigNode* find(const std::string& key) const;
  bool is_scalar() const { return kind == Kind::Scalar; }
  bool is_list() const { return kind == Kind::List; }
  bool is_map() const { return kind == Kind::Map; }
};

// A key and its value. Not a std::pair: a pair of an incomplete ConfigNode
// inside ConfigNode does not compile with clang and libstdc++ (the fuzzers
// are built with clang).
struct ConfigEntry {
  std::string first;
  ConfigNode second;
  ConfigEntry() = default;
  ConfigEntry(std::string k, ConfigNode v) : first(std::move(k)), second(std::move(v)) {}
};

// The node as text without source locations, keys in file order, `skip_key`
// left out at the top level: two entries that say the same thing compare
// equal (online change keeps a driver whose settings did not change).
inline std::string canonical_text(const ConfigNode& n, const std::string& skip_key = {}) {
  switch (n.kind) {
    case ConfigNode::Kind::Null: return "~";
    case ConfigNode::Kind::Scalar: {
      std::string s = "\"";
      for (char c : n.scalar) s += (c == '"' || c == '\\') ? std::string("\\") + c : std::string(1, c);
      return s + "\"";
    }
    case ConfigNode::Kind::List: {
      std::string s = "[";
      for (const auto& i : n.items) s += canonical_text(i) + ",";
      return s + "]";
    }
    case ConfigNode::Kind::Map: {
      std::string s = "{";
      for (const auto& e : n.map)
        if (skip_key.empty() || e.first != skip_key) s += e.first + ":" + canonical_text(e.second) + ",";
      return s + "}";
    }
  }
  return {};
}

inline const ConfigNode* ConfigNode::find(const std::string& key) const {
  for (const auto& [k, v] : map)
    if (k == key) return &v;
  return nullptr;
}

}  // namespace syncplc
