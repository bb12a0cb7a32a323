#include "runtime/project/yaml_tree.hpp"

#include <yaml-cpp/eventhandler.h>
#include <yaml-cpp/exceptions.h>
#include <yaml-cpp/mark.h>
#include <yaml-cpp/parser.h>

#include <algorithm>
#include <filesystem>
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

// A file passed its budget or depth: the parse stops there.
struct Refused {
  SourceLoc loc;
  std::string message;
  bool budget = false;  // the load's budget is used up (not only this file's depth)
};

// Builds the ConfigNode tree from a parser's events: no parser's own node
// tree in between, which for a large project took several times the memory
// of the tree kept (issue 11: 100,000 blocks in under 300 MB). Counts every
// node against the load's budget, an alias as the nodes it names, before
// the alias is copied.
class TreeBuilder {
 public:
  TreeBuilder(const std::string& file, Diagnostics& diags, YamlBudget& budget)
      : file_(file), diags_(diags), budget_(budget) {}
  ConfigNode root;

  SourceLoc place(int line0, int col0) const { return SourceLoc{file_, line0 + 1, col0 + 1}; }

  void null(const SourceLoc& at, const std::string& anchor) {
    count(at, 1);
    ConfigNode c;
    c.loc = at;
    done(std::move(c), anchor, 1, 0);
  }
  void scalar(const SourceLoc& at, const std::string& anchor, std::string value) {
    count(at, 1);
    ConfigNode c;
    c.kind = ConfigNode::Kind::Scalar;
    c.scalar = std::move(value);
    c.loc = at;
    done(std::move(c), anchor, 1, 0);
  }
  void alias(const SourceLoc& at, const std::string& name) {
    auto it = anchors_.find(name);
    if (it == anchors_.end()) {
      bool open = false;
      for (const auto& f : stack_) open |= f.anchor == name;
      diags_.error(at, open ? "an alias inside the node it names" : "alias *" + name + ": no anchor &" + name + " before it");
      done(ConfigNode{ConfigNode::Kind::Null, "", {}, {}, at}, "", 0, 0);
      return;
    }
    const Anchored& a = it->second;
    if (stack_.size() + a.height > YamlBudget::kMaxDepth)
      throw Refused{at, "alias *" + name + " nests the file deeper than " + std::to_string(YamlBudget::kMaxDepth) + " levels"};
    if (a.nodes > budget_.limit() - budget_.used)
      throw Refused{at,
                    "alias *" + name + " expands the file past its limit of " + std::to_string(budget_.limit()) +
                        " YAML nodes (one per byte of the project's files, at least " +
                        std::to_string(YamlBudget::kMinNodes) + "): aliases are not expanded that far",
                    true};
    budget_.used += a.nodes;
    done(ConfigNode(a.node), "", a.nodes, a.height);  // a copy, with the anchored node's places
  }
  void open(ConfigNode::Kind kind, const SourceLoc& at, const std::string& anchor) {
    if (stack_.size() + 1 > YamlBudget::kMaxDepth)
      throw Refused{at, "YAML nested deeper than " + std::to_string(YamlBudget::kMaxDepth) + " levels"};
    count(at, 1);
    Frame f;
    f.node.kind = kind;
    f.node.loc = at;
    f.anchor = anchor;
    f.first = budget_.used - 1;
    stack_.push_back(std::move(f));
  }
  void close() {
    Frame f = std::move(stack_.back());
    stack_.pop_back();
    f.node.map.shrink_to_fit();  // kept for the whole load: no doubling slack
    f.node.items.shrink_to_fit();
    done(std::move(f.node), f.anchor, budget_.used - f.first, f.height);
  }

 private:
  struct Frame {
    ConfigNode node;
    std::string anchor;
    std::size_t first = 0;  // the budget's count before this node
    std::size_t height = 1;  // lists and maps nested in it, itself included
    bool have_key = false;  // maps: the next node is the value of `key`
    bool key_ok = false;
    std::string key;
    SourceLoc key_loc;
  };
  struct Anchored {
    ConfigNode node;
    std::size_t nodes = 0;   // what an alias of it adds to the budget
    std::size_t height = 0;  // what it adds to the depth
  };

  void count(const SourceLoc& at, std::size_t n) {
    if (n > budget_.limit() - budget_.used)
      throw Refused{at,
                    "the project's files pass their limit of " + std::to_string(budget_.limit()) +
                        " YAML nodes (one per byte of the project's files, at least " +
                        std::to_string(YamlBudget::kMinNodes) + "; a file included more than once counts each time)",
                    true};
    budget_.used += n;
  }

  // A complete node: the root, an item of a list, or a key or value of a map.
  void done(ConfigNode c, const std::string& anchor, std::size_t nodes, std::size_t height) {
    if (!anchor.empty()) anchors_[anchor] = Anchored{c, nodes, height};
    if (stack_.empty()) {
      root = std::move(c);
      return;
    }
    Frame& f = stack_.back();
    if (height + 1 > f.height) f.height = height + 1;
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
  YamlBudget& budget_;
  std::vector<Frame> stack_;
  std::map<std::string, Anchored> anchors_;
};

// yaml-cpp's parser events into the TreeBuilder.
class YamlCppEvents final : public YAML::EventHandler {
 public:
  explicit YamlCppEvents(TreeBuilder& b) : b_(b) {}
  void OnDocumentStart(const YAML::Mark&) override {}
  void OnDocumentEnd() override {}
  void OnAnchor(const YAML::Mark&, const std::string& name) override { next_anchor_ = name; }
  void OnNull(const YAML::Mark& m, YAML::anchor_t anchor) override { b_.null(at(m), take(anchor)); }
  void OnAlias(const YAML::Mark& m, YAML::anchor_t anchor) override {
    auto it = names_.find(anchor);
    b_.alias(at(m), it == names_.end() ? "?" : it->second);
  }
  void OnScalar(const YAML::Mark& m, const std::string&, YAML::anchor_t anchor, const std::string& value) override {
    b_.scalar(at(m), take(anchor), value);
  }
  void OnSequenceStart(const YAML::Mark& m, const std::string&, YAML::anchor_t anchor, YAML::EmitterStyle::value) override {
    b_.open(ConfigNode::Kind::List, at(m), take(anchor));
  }
  void OnSequenceEnd() override { b_.close(); }
  void OnMapStart(const YAML::Mark& m, const std::string&, YAML::anchor_t anchor, YAML::EmitterStyle::value) override {
    b_.open(ConfigNode::Kind::Map, at(m), take(anchor));
  }
  void OnMapEnd() override { b_.close(); }

 private:
  SourceLoc at(const YAML::Mark& m) const { return b_.place(m.line, m.column); }
  // The name OnAnchor gave for the node that now carries the anchor's number.
  std::string take(YAML::anchor_t anchor) {
    if (!anchor) return "";
    names_[anchor] = next_anchor_;
    return next_anchor_;
  }
  TreeBuilder& b_;
  std::string next_anchor_;
  std::map<YAML::anchor_t, std::string> names_;
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
ConfigNode read_yaml_stream(std::istream& in, const std::string& name, Diagnostics& diags, YamlBudget& budget,
                            const std::function<std::string(int)>& line_of) {
  TreeBuilder b(name, diags, budget);
  b.root.loc = SourceLoc{name, 0, 0};
  try {
    YamlCppEvents events(b);
    YAML::Parser parser(in);
    parser.HandleNextDocument(events);  // the first document, as YAML::Load reads
  } catch (const YAML::Exception& e) {
    diags.error(loc_of(e.mark, name), "YAML syntax error: " + e.msg + syntax_hint(line_of(e.mark.line)));
    return ConfigNode{};
  } catch (const Refused& r) {
    diags.error(r.loc, r.message);
    if (r.budget) budget.exhausted = true;
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

// `key` names the file in the budget.
ConfigNode read_text(const std::string& text, const std::string& name, const std::string& key, Diagnostics& diags,
                     YamlBudget* budget) {
  YamlBudget own;
  YamlBudget& b = budget ? *budget : own;
  b.add_file(key, text.size());
  std::istringstream in(text);
  return read_yaml_stream(in, name, diags, b, [&](int n) {
    std::istringstream again(text);
    return nth_line(again, n);
  });
}

}  // namespace

ConfigNode read_yaml_string(const std::string& text, const std::string& name, Diagnostics& diags, YamlBudget* budget) {
  return read_text(text, name, name, diags, budget);
}

ConfigNode read_yaml_file(const std::string& path, Diagnostics& diags, std::vector<store::SourceFile>* read,
                          YamlBudget* budget) {
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
  std::error_code ec;
  const std::string key = std::filesystem::weakly_canonical(path, ec).string();
  return read_text(text, path, key.empty() ? path : key, diags, budget);
}

}  // namespace syncplc
