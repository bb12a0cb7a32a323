#include "runtime/project/yaml_tree.hpp"

#include <yaml-cpp/eventhandler.h>
#include <yaml-cpp/exceptions.h>
#include <yaml-cpp/mark.h>
#include <yaml-cpp/parser.h>

#include <algorithm>
#include <fstream>
#include <functional>
#include <iterator>
#include <map>
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

SourceLoc loc_of(const YAML::Mark& m, const SourceFile& file) {
  return SourceLoc{file, m.line + 1, m.column + 1};
}

// Builds the ConfigNode tree straight from the parser's events: no yaml-cpp
// node tree in between, which for a large project took several times the
// memory of the tree kept (issue 11: 100,000 blocks in under 300 MB).
class TreeBuilder final : public YAML::EventHandler {
 public:
  TreeBuilder(const std::string& file, Diagnostics& diags) : file_(file), diags_(diags) {}
  ConfigNode root;

  void OnDocumentStart(const YAML::Mark&) override {}
  void OnDocumentEnd() override {}
  void OnNull(const YAML::Mark& m, YAML::anchor_t anchor) override {
    ConfigNode c;
    c.loc = loc_of(m, file_);
    done(std::move(c), anchor);
  }
  void OnAlias(const YAML::Mark& m, YAML::anchor_t anchor) override {
    auto it = anchors_.find(anchor);
    if (it == anchors_.end()) {
      diags_.error(loc_of(m, file_), "an alias inside the node it names");
      done(ConfigNode{ConfigNode::Kind::Null, "", {}, {}, loc_of(m, file_)}, 0);
      return;
    }
    done(ConfigNode(it->second), 0);  // a copy, with the anchored node's places
  }
  void OnScalar(const YAML::Mark& m, const std::string&, YAML::anchor_t anchor, const std::string& value) override {
    ConfigNode c;
    c.kind = ConfigNode::Kind::Scalar;
    c.scalar = value;
    c.loc = loc_of(m, file_);
    done(std::move(c), anchor);
  }
  void OnSequenceStart(const YAML::Mark& m, const std::string&, YAML::anchor_t anchor, YAML::EmitterStyle::value) override {
    open(ConfigNode::Kind::List, m, anchor);
  }
  void OnSequenceEnd() override { close(); }
  void OnMapStart(const YAML::Mark& m, const std::string&, YAML::anchor_t anchor, YAML::EmitterStyle::value) override {
    open(ConfigNode::Kind::Map, m, anchor);
  }
  void OnMapEnd() override { close(); }

 private:
  struct Frame {
    ConfigNode node;
    YAML::anchor_t anchor = 0;
    bool have_key = false;  // maps: the next node is the value of `key`
    bool key_ok = false;
    std::string key;
    SourceLoc key_loc;
  };

  void open(ConfigNode::Kind kind, const YAML::Mark& m, YAML::anchor_t anchor) {
    Frame f;
    f.node.kind = kind;
    f.node.loc = loc_of(m, file_);
    f.anchor = anchor;
    stack_.push_back(std::move(f));
  }
  void close() {
    Frame f = std::move(stack_.back());
    stack_.pop_back();
    f.node.map.shrink_to_fit();  // kept for the whole load: no doubling slack
    f.node.items.shrink_to_fit();
    done(std::move(f.node), f.anchor);
  }
  // A complete node: the root, an item of a list, or a key or value of a map.
  void done(ConfigNode c, YAML::anchor_t anchor) {
    if (anchor) anchors_[anchor] = c;
    if (stack_.empty()) {
      root = std::move(c);
      return;
    }
    Frame& f = stack_.back();
    if (f.node.is_list()) {
      f.node.items.push_back(std::move(c));
      return;
    }
    if (!f.have_key) {
      f.have_key = true;
      f.key_ok = c.is_scalar();
      f.key_loc = c.loc;
      if (f.key_ok) f.key = std::move(c.scalar);
      else diags_.error(c.loc, "map keys must be plain names");
      return;
    }
    f.have_key = false;
    if (!f.key_ok) return;
    if (f.node.find(f.key)) {
      diags_.error(f.key_loc, "duplicate key '" + f.key + "'");
      return;
    }
    // A key with an empty value has no mark of its own: use the key's place.
    if (c.kind == ConfigNode::Kind::Null) c.loc = f.key_loc;
    f.node.map.emplace_back(std::move(f.key), std::move(c));
  }

  const SourceFile file_;  // one name shared by every node
  Diagnostics& diags_;
  std::vector<Frame> stack_;
  std::map<YAML::anchor_t, ConfigNode> anchors_;
};

// What usually causes a syntax error on this line, for the two mistakes
// yaml-cpp's own messages do not explain.
std::string syntax_hint(const std::string& line) {
  if (line.find('\t') != std::string::npos) return " (the line has a tab: YAML indents with spaces only)";
  // A plain value cannot start with %: that is YAML's directive sign.
  bool quoted = false;
  char quote = 0, before = ' ';
  for (char c : line) {
    if (quoted) {
      if (c == quote) quoted = false;
    } else if (c == '"' || c == '\'') {
      quoted = true;
      quote = c;
    } else if (c == '%' && (before == ' ' || before == ':' || before == '[' || before == '{' || before == ',')) {
      return " (a value starting with % must be quoted, e.g. address: \"%IX0.0\")";
    }
    if (c != ' ') before = c;
  }
  return "";
}

// `line_of` gives the text of a 0-based line, for the hint.
ConfigNode read_yaml_stream(std::istream& in, const std::string& name, Diagnostics& diags,
                            const std::function<std::string(int)>& line_of) {
  TreeBuilder b(name, diags);
  b.root.loc = SourceLoc{name, 0, 0};
  try {
    YAML::Parser parser(in);
    parser.HandleNextDocument(b);  // the first document, as YAML::Load reads
  } catch (const YAML::Exception& e) {
    diags.error(loc_of(e.mark, name), "YAML syntax error: " + e.msg + syntax_hint(line_of(e.mark.line)));
    return ConfigNode{};
  }
  return std::move(b.root);
}

// Line `n` (0-based) of a text; "" past its end.
std::string nth_line(std::istream& in, int n) {
  std::string line;
  for (int i = 0; i <= n && std::getline(in, line); ++i)
    if (i == n) return line;
  return "";
}

}  // namespace

ConfigNode read_yaml_string(const std::string& text, const std::string& name, Diagnostics& diags) {
  std::istringstream in(text);
  return read_yaml_stream(in, name, diags, [&](int n) {
    std::istringstream again(text);
    return nth_line(again, n);
  });
}

ConfigNode read_yaml_file(const std::string& path, Diagnostics& diags, std::vector<store::SourceFile>* read) {
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    diags.error(SourceLoc{path, 0, 0}, "cannot open file");
    return ConfigNode{};
  }
  std::string text{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  if (in.bad()) {
    diags.error(SourceLoc{path, 0, 0}, "cannot read file");
    return ConfigNode{};
  }
  if (read) read->push_back({path, text});
  return read_yaml_string(text, path, diags);
}

}  // namespace syncplc
