#include "runtime/project/yaml_tree.hpp"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <fstream>
#include <sstream>

namespace syncplc {

std::vector<Diagnostic> Diagnostics::sorted() const {
  std::vector<Diagnostic> v = list_;
  std::stable_sort(v.begin(), v.end(), [](const Diagnostic& a, const Diagnostic& b) {
    if (a.loc.file != b.loc.file) return a.loc.file < b.loc.file;
    if (a.loc.line != b.loc.line) return a.loc.line < b.loc.line;
    return a.loc.col < b.loc.col;
  });
  return v;
}

namespace {

SourceLoc loc_of(const YAML::Mark& m, const std::string& file) {
  return SourceLoc{file, m.line + 1, m.column + 1};
}

ConfigNode convert(const YAML::Node& n, const std::string& file, Diagnostics& diags) {
  ConfigNode c;
  c.loc = loc_of(n.Mark(), file);
  switch (n.Type()) {
    case YAML::NodeType::Null:
    case YAML::NodeType::Undefined:
      c.kind = ConfigNode::Kind::Null;
      break;
    case YAML::NodeType::Scalar:
      c.kind = ConfigNode::Kind::Scalar;
      c.scalar = n.Scalar();
      break;
    case YAML::NodeType::Sequence:
      c.kind = ConfigNode::Kind::List;
      for (const auto& item : n) c.items.push_back(convert(item, file, diags));
      break;
    case YAML::NodeType::Map:
      c.kind = ConfigNode::Kind::Map;
      for (const auto& kv : n) {
        SourceLoc kl = loc_of(kv.first.Mark(), file);
        if (!kv.first.IsScalar()) {
          diags.error(kl, "map keys must be plain names");
          continue;
        }
        std::string key = kv.first.Scalar();
        if (c.find(key)) {
          diags.error(kl, "duplicate key '" + key + "'");
          continue;
        }
        c.map.emplace_back(key, convert(kv.second, file, diags));
        // A key with an empty value has no mark of its own: use the key's place.
        if (c.map.back().second.kind == ConfigNode::Kind::Null) c.map.back().second.loc = kl;
      }
      break;
  }
  return c;
}

}  // namespace

ConfigNode read_yaml_string(const std::string& text, const std::string& name, Diagnostics& diags) {
  try {
    YAML::Node root = YAML::Load(text);
    return convert(root, name, diags);
  } catch (const YAML::Exception& e) {
    diags.error(loc_of(e.mark, name), "YAML syntax error: " + e.msg);
    return ConfigNode{};
  }
}

ConfigNode read_yaml_file(const std::string& path, Diagnostics& diags) {
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    diags.error(SourceLoc{path, 0, 0}, "cannot open file");
    return ConfigNode{};
  }
  std::stringstream ss;
  ss << in.rdbuf();
  return read_yaml_string(ss.str(), path, diags);
}

}  // namespace syncplc
