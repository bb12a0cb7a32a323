// A parsed configuration tree with source locations, so that components
// outside the loader (I/O drivers) can read their own settings and report
// errors as file:line:col without knowing the file format.
#pragma once

#include <memory>
#include <ostream>
#include <string>
#include <utility>
#include <vector>

namespace syncplc {

// A file name shared by every place in that file: a project of 100,000
// blocks has more than a million places (issue 11: loading in under 300 MB).
class SourceFile {
 public:
  SourceFile() = default;
  SourceFile(std::string name) : name_(std::make_shared<const std::string>(std::move(name))) {}
  SourceFile(const char* name) : SourceFile(std::string(name)) {}
  const std::string& str() const { return name_ ? *name_ : empty(); }
  operator const std::string&() const { return str(); }
  bool empty_name() const { return str().empty(); }
  friend bool operator==(const SourceFile& a, const SourceFile& b) { return a.name_ == b.name_ || a.str() == b.str(); }
  friend bool operator==(const SourceFile& a, const std::string& b) { return a.str() == b; }
  friend bool operator==(const SourceFile& a, const char* b) { return a.str() == b; }
  friend bool operator<(const SourceFile& a, const SourceFile& b) { return a.str() < b.str(); }
  friend std::ostream& operator<<(std::ostream& os, const SourceFile& f) { return os << f.str(); }

 private:
  static const std::string& empty() {
    static const std::string e;
    return e;
  }
  std::shared_ptr<const std::string> name_;
};

struct SourceLoc {
  SourceFile file;
  int line = 0;  // 1-based; 0 = unknown
  int col = 0;
  std::string text() const {
    return file.str() + ":" + std::to_string(line) + ":" + std::to_string(col);
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
