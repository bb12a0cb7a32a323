#include "runtime/project/yaml_tree.hpp"

#include <yaml.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <string_view>

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

// A file passed its budget or depth: the parse stops there.
struct Refused {
  SourceLoc loc;
  std::string message;
  bool budget = false;  // the load's budget is used up (not only this file's depth)
};

// Builds the ConfigNode tree from libyaml's events: no parser's own node
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

// Line `n` (0-based) of a text; "" past its end.
std::string nth_line(const std::string& text, std::size_t n) {
  std::size_t at = 0;
  for (std::size_t i = 0; i < n; ++i) {
    at = text.find('\n', at);
    if (at == std::string::npos) return "";
    ++at;
  }
  return text.substr(at, text.find('\n', at) - at);
}

// libyaml's parser and its current event, released however the read ends.
struct Parser {
  yaml_parser_t p;
  Parser() { yaml_parser_initialize(&p); }
  ~Parser() { yaml_parser_delete(&p); }
};
struct Event {
  yaml_event_t e{};
  ~Event() { yaml_event_delete(&e); }
};

std::string text_of(const yaml_char_t* s) { return s ? reinterpret_cast<const char*>(s) : ""; }

// A plain scalar without a tag that YAML reads as null (as yaml-cpp did):
// the empty value of `key:`, `~`, `null`.
bool is_null(const yaml_event_t& e) {
  const auto& sc = e.data.scalar;
  if (sc.style != YAML_PLAIN_SCALAR_STYLE || sc.tag) return false;
  const std::string_view v(reinterpret_cast<const char*>(sc.value), sc.length);
  return v.empty() || v == "~" || v == "null" || v == "Null" || v == "NULL";
}

// A syntax error where libyaml found it, with what it was reading and from where.
void syntax_error(const yaml_parser_t& p, const std::string& text, const std::string& name, Diagnostics& diags) {
  std::size_t line = p.problem_mark.line, col = p.problem_mark.column;
  if (p.error == YAML_READER_ERROR) {  // bad bytes: only an offset
    const std::size_t at = std::min(p.problem_offset, text.size());
    line = static_cast<std::size_t>(std::count(text.begin(), text.begin() + static_cast<std::ptrdiff_t>(at), '\n'));
    col = at - (line ? text.rfind('\n', at - 1) + 1 : 0);
  }
  std::string msg = "YAML syntax error: " + std::string(p.problem ? p.problem : "the parser stopped");
  // The context's place, when it is another: the start of what was left open.
  if (p.context && (p.context_mark.line != p.problem_mark.line || p.context_mark.column != p.problem_mark.column))
    msg += " (" + std::string(p.context) + " that starts at line " + std::to_string(p.context_mark.line + 1) +
           ", column " + std::to_string(p.context_mark.column + 1) + ")";
  diags.error(SourceLoc{name, static_cast<int>(line) + 1, static_cast<int>(col) + 1}, msg + syntax_hint(nth_line(text, line)));
}

// The first document of `text` (as yaml-cpp's YAML::Load read), from
// libyaml's events: a tenth of yaml-cpp's time for a large project's flow
// maps (docs/benchmarks.md, section 6).
ConfigNode read_yaml_events(const std::string& text, const std::string& name, Diagnostics& diags, YamlBudget& budget) {
  TreeBuilder b(name, diags, budget);
  b.root.loc = SourceLoc{name, 0, 0};
  Parser parser;
  yaml_parser_set_input_string(&parser.p, reinterpret_cast<const unsigned char*>(text.data()), text.size());
  try {
    for (bool more = true; more;) {
      Event ev;
      if (!yaml_parser_parse(&parser.p, &ev.e)) {
        syntax_error(parser.p, text, name, diags);
        return ConfigNode{};
      }
      const yaml_event_t& e = ev.e;
      const SourceLoc at = b.place(static_cast<int>(e.start_mark.line), static_cast<int>(e.start_mark.column));
      switch (e.type) {
        case YAML_SCALAR_EVENT:
          if (is_null(e)) b.null(at, text_of(e.data.scalar.anchor));
          else b.scalar(at, text_of(e.data.scalar.anchor), std::string(reinterpret_cast<const char*>(e.data.scalar.value), e.data.scalar.length));
          break;
        case YAML_ALIAS_EVENT: b.alias(at, text_of(e.data.alias.anchor)); break;
        case YAML_SEQUENCE_START_EVENT: b.open(ConfigNode::Kind::List, at, text_of(e.data.sequence_start.anchor)); break;
        case YAML_MAPPING_START_EVENT: b.open(ConfigNode::Kind::Map, at, text_of(e.data.mapping_start.anchor)); break;
        case YAML_SEQUENCE_END_EVENT:
        case YAML_MAPPING_END_EVENT: b.close(); break;
        case YAML_DOCUMENT_END_EVENT:
        case YAML_STREAM_END_EVENT: more = false; break;  // the first document only
        default: break;
      }
    }
  } catch (const Refused& r) {
    diags.error(r.loc, r.message);
    if (r.budget) budget.exhausted = true;
    return ConfigNode{};
  }
  return std::move(b.root);
}

// `key` names the file in the budget.
ConfigNode read_text(const std::string& text, const std::string& name, const std::string& key, Diagnostics& diags,
                     YamlBudget* budget) {
  YamlBudget own;
  YamlBudget& b = budget ? *budget : own;
  b.add_file(key, text.size());
  return read_yaml_events(text, name, diags, b);
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
  std::error_code ec;
  std::string key = std::filesystem::weakly_canonical(path, ec).string();
  if (key.empty()) key = path;
  if (!read) return read_text(text, path, key, diags, budget);
  read->push_back({path, std::move(text)});  // parsed where it is kept: one copy of a large file, not two
  return read_text(read->back().text, path, key, diags, budget);
}

}  // namespace syncplc
