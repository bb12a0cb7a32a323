// The project loader. Reading order: project, include, tasks, tags (with
// their Modbus places), modbus, blocks, drivers, connections, traces, watch.
// Then: generic types are inferred, connections type-checked, tag owners
// found, images laid out, execution orders sorted, blocks created, snapshot
// channels wired.
#include "runtime/project/loader.hpp"

#include <algorithm>
#include <cmath>
#include <deque>
#include <filesystem>
#include <functional>
#include <map>
#include <queue>
#include <set>
#include <unordered_map>

#include "fblocks/library.hpp"
#include "runtime/core/units.hpp"
#include "runtime/io/drivers.hpp"
#include "runtime/project/modbus_settings.hpp"
#include "runtime/project/yaml_tree.hpp"

namespace syncplc {
namespace {

constexpr std::int64_t kMinPeriod = 100'000;          // 100 us
constexpr int kBrokenSource = -2;                     // an input wired to a declaration that failed
constexpr std::int64_t kMaxPeriod = 10'000'000'000;   // 10 s

bool is_identifier(const std::string& s) {
  if (s.empty() || !(std::isalpha(static_cast<unsigned char>(s[0])) || s[0] == '_')) return false;
  return std::all_of(s.begin(), s.end(), [](char c) { return std::isalnum(static_cast<unsigned char>(c)) || c == '_'; });
}

std::uint64_t mix_seed(std::uint64_t seed, const std::string& name) {
  // FNV-1a over the name, then a splitmix64 finaliser with the seed.
  std::uint64_t h = 1469598103934665603ULL;
  for (unsigned char c : name) h = (h ^ c) * 1099511628211ULL;
  std::uint64_t z = h + seed * 0x9E3779B97F4A7C15ULL;
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
  return z ^ (z >> 31);
}

struct TaskDecl {
  TaskConfig cfg;
  SourceLoc loc;
  std::optional<SourceLoc> write_queue_loc;  // set by the project (else the default, which may grow)
};

struct TagDecl {
  Tag tag;
  std::string task;  // explicit owner, "" if none
  SourceLoc task_loc;
  const ConfigNode* init = nullptr;
  const ConfigNode* safe = nullptr;
  std::string init_override;  // from --set tag=value
  SourceLoc modbus_loc;       // the tag's modbus: key, where its overlaps are reported
  bool modbus_failed = false;  // its modbus: key was wrong (reported): it takes no place at all
  int writer_task = -1;
  std::string writer;
  std::vector<int> reader_tasks;
};

struct InstanceDecl {
  std::string name;
  const BlockTypeInfo* type = nullptr;
  int task = -1;
  std::optional<IecType> datatype;
  bool datatype_fixed = false;
  std::vector<const ConfigNode*> params;  // by ParamDecl index, null = default
  std::vector<std::string> param_override;
  std::vector<const ConfigNode*> inputs;  // constant inputs by pin index
  std::vector<int> source;                // connection index feeding each input pin, -1 none, kBrokenSource
  std::vector<std::uint32_t> pin_length;  // elements per pin (1 for a scalar), set from parameters
  std::vector<std::vector<int>> element_source;  // array input pins: connection feeding each element, -1 none
  bool params_ok = true;                  // parameters parsed (so array pin lengths are known)
  SourceLoc loc;
  // Filled by the checking phases, used by build():
  std::vector<std::vector<Cell>> pin_values;  // constants and pin inits by pin index: none, one (every element) or one per element
  std::vector<Cell> param_cells;                // by ParamDecl index
  bool values_ok = true;
  std::unique_ptr<Block> block;
};

struct Endpoint {
  bool is_pin = false;
  int instance = -1;
  int pin = -1;
  int tag = -1;
  std::optional<std::uint32_t> element;  // 0-based
  SourceLoc loc;
  std::string text;
};

struct ConnectionDecl {
  Endpoint src, dst;
  SourceLoc loc;
};

struct DriverDecl {
  std::string name;
  std::string type;
  int task = -1;
  const ConfigNode* node = nullptr;
  std::unique_ptr<IoDriver> driver;
  std::vector<int> channel_tag;  // per channel, -1 unbound
  std::vector<SourceLoc> channel_loc;
  SourceLoc loc;
};

class Loader : public DriverSetup {
 public:
  Loader(const LoadOptions& o) : opts_(o) {
    blocks_ = o.blocks ? o.blocks : &builtin_blocks();
    drivers_ = o.drivers ? o.drivers : &builtin_drivers();
  }

  LoadResult run(ConfigNode root, const std::string& path);

  // DriverSetup
  std::int64_t task_period_ns() const override { return current_driver_period_; }
  std::uint64_t seed() const override { return current_driver_seed_; }
  void error(const SourceLoc& where, const std::string& message) override { d_.error(where, message); }

 private:
  void merge_includes(ConfigNode& root, const std::string& path, int depth);
  void read_project(const ConfigNode& n);
  void read_tasks(const ConfigNode& n);
  void read_tags(const ConfigNode& n);
  void read_blocks(const ConfigNode& n);
  void read_drivers(const ConfigNode& n);
  void override_driver_settings(ConfigNode& drivers);
  void read_connections(const ConfigNode& n);
  void read_metrics(const ConfigNode& n);
  std::vector<Tag> modbus_tags() const;
  void check_modbus_places();
  void size_write_queues();
  bool parse_endpoint(const std::string& text, const SourceLoc& loc, Endpoint& e);
  void apply_overrides();
  void check_params();
  bool pin_connected(const InstanceDecl& in, std::size_t pin) const;
  void infer_types();
  void check_connections();
  void find_owners();
  void check_values();
  void order_blocks();
  void create_blocks();
  void check_refs();
  std::unique_ptr<Program> build();
  int task_index(const std::string& name) const;
  int tag_index(const std::string& name) const;
  int instance_index(const std::string& name) const;
  IecType endpoint_type(const Endpoint& e, std::uint32_t* length) const;
  bool endpoint_type_known(const Endpoint& e) const;
  std::optional<Cell> parse_literal(IecType t, const std::string& unit, const std::string& text, const SourceLoc& loc,
                                    const std::string& what);
  std::vector<Cell> parse_tag_values(const TagDecl& td, const ConfigNode& n, const std::string& what);

  const LoadOptions& opts_;
  const BlockRegistry* blocks_;
  const DriverRegistry* drivers_;
  Diagnostics d_;
  std::string file_;
  std::string name_ = "unnamed", version_ = "0";
  std::uint64_t seed_ = 1;
  std::vector<TaskDecl> tasks_;
  std::vector<TagDecl> tags_;
  std::vector<InstanceDecl> insts_;
  std::vector<DriverDecl> drvs_;
  std::vector<ConnectionDecl> conns_;
  std::vector<std::pair<std::string, SourceLoc>> traces_, watch_;
  std::vector<std::pair<std::string, SourceLoc>> axis_errors_;  // metrics: axis_errors
  std::int64_t metrics_from_ns_ = 0;
  ModbusConfig modbus_;  // the modbus: section
  std::set<std::string> driver_overrides_;  // names of drivers whose settings --set changed
  std::vector<std::vector<int>> order_;     // per task: instance indices, unit delays first
  std::vector<std::size_t> delays_;         // per task: how many unit delays lead the order
  std::set<std::string> failed_names_;      // declarations already reported: no follow-on errors
  std::vector<std::string> include_stack_;  // files being included, outermost first
  std::unordered_map<std::string, SourceLoc> names_;  // tags, instances, drivers share one namespace
  std::unordered_map<std::string, int> task_by_name_, tag_by_name_, instance_by_name_;
  std::int64_t current_driver_period_ = 0;
  std::uint64_t current_driver_seed_ = 0;
  ConfigNode root_;
  std::vector<std::unique_ptr<ConfigNode>> included_;
};

// Hashed: a project of 100,000 blocks resolves 200,000 references.
int Loader::task_index(const std::string& name) const {
  auto it = task_by_name_.find(name);
  return it == task_by_name_.end() ? -1 : it->second;
}
int Loader::tag_index(const std::string& name) const {
  auto it = tag_by_name_.find(name);
  return it == tag_by_name_.end() ? -1 : it->second;
}
int Loader::instance_index(const std::string& name) const {
  auto it = instance_by_name_.find(name);
  return it == instance_by_name_.end() ? -1 : it->second;
}

const std::set<std::string> kTopKeys = {"project", "include", "tasks", "tags", "blocks", "connections",
                                        "drivers", "traces", "watch", "metrics", "modbus"};

void Loader::merge_includes(ConfigNode& root, const std::string& path, int depth) {
  const ConfigNode* inc = root.find("include");
  if (!inc) return;
  std::vector<const ConfigNode*> files;
  if (inc->is_scalar()) files.push_back(inc);
  else if (inc->is_list()) for (const auto& i : inc->items) files.push_back(&i);
  else { d_.error(inc->loc, "include: a file name or a list of file names"); return; }
  if (depth > 8) { d_.error(inc->loc, "includes nested deeper than 8 levels"); return; }
  for (const ConfigNode* f : files) {
    if (!f->is_scalar()) { d_.error(f->loc, "include: expected a file name"); continue; }
    std::filesystem::path p = std::filesystem::path(path).parent_path() / f->scalar;
    std::error_code ec;
    std::string canonical = std::filesystem::weakly_canonical(p, ec).string();
    if (auto it = std::find(include_stack_.begin(), include_stack_.end(), canonical); it != include_stack_.end()) {
      std::string chain;
      for (auto i = it; i != include_stack_.end(); ++i) chain += std::filesystem::path(*i).filename().string() + " -> ";
      d_.error(f->loc, "include cycle: " + chain + std::filesystem::path(canonical).filename().string());
      continue;
    }
    Diagnostics local;
    ConfigNode sub = read_yaml_file(p.string(), local);
    for (const auto& e : local.list()) {
      if (e.loc.line == 0) d_.error(f->loc, "include '" + f->scalar + "': " + e.message);
      else d_.error(e.loc, e.message);
    }
    if (!local.empty()) continue;
    if (!sub.is_map()) { d_.error(f->loc, "include '" + f->scalar + "' is not a map of sections"); continue; }
    include_stack_.push_back(canonical);
    merge_includes(sub, p.string(), depth + 1);
    include_stack_.pop_back();
    for (auto& [k, v] : sub.map) {
      if (k == "include") continue;
      if (k == "project") { d_.error(v.loc, "an included file cannot set 'project'"); continue; }
      if (!kTopKeys.count(k)) continue;  // reported when the included file is read as a map below
      ConfigNode* target = nullptr;
      for (auto& [rk, rv] : root.map)
        if (rk == k) target = &rv;
      if (k == "metrics" || k == "modbus") {
        // A map section comes from one file only.
        if (target) d_.error(v.loc, "'" + k + "' is also set at " + target->loc.text() + ": a map section may come from one file only");
        else root.map.emplace_back(k, v);
        continue;
      }
      if (!target) {
        root.map.emplace_back(k, ConfigNode{ConfigNode::Kind::List, "", {}, {}, v.loc});
        target = &root.map.back().second;
      }
      if (!v.is_list() || !target->is_list()) { d_.error(v.loc, "'" + k + "' must be a list to be included"); continue; }
      target->items.insert(target->items.end(), v.items.begin(), v.items.end());
    }
    for (const auto& [k, v] : sub.map)
      if (!kTopKeys.count(k)) d_.error(v.loc, "unknown top-level key '" + k + "'");
  }
}

LoadResult Loader::run(ConfigNode root, const std::string& path) {
  file_ = path;
  root_ = std::move(root);
  LoadResult r;
  if (!d_.empty()) {
    r.diagnostics = d_;
    return r;
  }
  if (!root_.is_map()) {
    d_.error(root_.loc.line ? root_.loc : SourceLoc{path, 1, 1}, "a project file is a map with tasks, tags, blocks, connections ...");
    r.diagnostics = d_;
    return r;
  }
  {
    std::error_code ec;
    include_stack_ = {std::filesystem::weakly_canonical(path, ec).string()};
  }
  merge_includes(root_, path, 0);
  for (const auto& [k, v] : root_.map)
    if (!kTopKeys.count(k))
      d_.error(v.loc, "unknown top-level key '" + k + "' (project, include, tasks, tags, blocks, connections, drivers, traces, watch, metrics, modbus)");
  if (auto* n = root_.find("project")) read_project(*n);
  if (opts_.seed) seed_ = *opts_.seed;
  if (auto* n = root_.find("tasks")) read_tasks(*n);
  if (tasks_.empty()) d_.error(root_.loc, "the project has no tasks");
  if (auto* n = root_.find("tags")) read_tags(*n);
  check_modbus_places();
  if (auto* n = root_.find("modbus")) read_modbus_section(*n, modbus_, d_);
  if (auto* n = root_.find("blocks")) read_blocks(*n);
  for (auto& [k, v] : root_.map)
    if (k == "drivers") override_driver_settings(v);
  if (auto* n = root_.find("drivers")) read_drivers(*n);
  apply_overrides();
  check_params();  // before connections: parameters size the array pins
  if (auto* n = root_.find("connections")) read_connections(*n);
  auto read_refs = [&](const char* key, std::vector<std::pair<std::string, SourceLoc>>& out) {
    const ConfigNode* n = root_.find(key);
    if (!n) return;
    if (!n->is_list()) { d_.error(n->loc, std::string(key) + ": expected a list"); return; }
    for (const auto& i : n->items) {
      if (!i.is_scalar()) d_.error(i.loc, std::string(key) + ": expected instance.pin or a tag name");
      else out.emplace_back(i.scalar, i.loc);
    }
  };
  read_refs("traces", traces_);
  read_refs("watch", watch_);
  if (auto* n = root_.find("metrics")) read_metrics(*n);
  infer_types();
  check_connections();
  find_owners();
  // Every check runs whatever failed before it, so one load reports every error.
  size_write_queues();
  check_values();
  order_blocks();
  create_blocks();
  check_refs();
  std::unique_ptr<Program> prog;
  if (d_.empty()) prog = build();
  if (d_.empty()) r.program = std::move(prog);
  r.diagnostics = d_;
  return r;
}

void Loader::read_project(const ConfigNode& n) {
  if (!n.is_map()) { d_.error(n.loc, "project: expected a map {name, version, seed}"); return; }
  for (const auto& [k, v] : n.map) {
    if (k == "name") name_ = v.scalar;
    else if (k == "version") version_ = v.scalar;
    else if (k == "description") {}
    else if (k == "seed") {
      std::string err;
      auto c = parse_value(IecType::ULINT, v.scalar, &err);
      if (!c) d_.error(v.loc, "seed: " + err);
      else seed_ = c->get<std::uint64_t>();
    } else d_.error(v.loc, "unknown key '" + k + "' in project (name, version, description, seed)");
  }
  if (name_.empty()) d_.error(n.loc, "project name is empty");
}

void Loader::read_tasks(const ConfigNode& n) {
  if (!n.is_list()) { d_.error(n.loc, "tasks: expected a list"); return; }
  for (const auto& t : n.items) {
    if (!t.is_map()) { d_.error(t.loc, "a task is a map {name, period, priority, ...}"); continue; }
    TaskDecl td;
    td.loc = t.loc;
    bool has_period = false, period_ok = false;
    for (const auto& [k, v] : t.map) {
      std::string err;
      if (k == "name") {
        td.cfg.name = v.scalar;
        if (!is_identifier(v.scalar)) d_.error(v.loc, "task name '" + v.scalar + "' is not an identifier");
        else if (task_index(v.scalar) >= 0) d_.error(v.loc, "duplicate task '" + v.scalar + "'");
      } else if (k == "period") {
        has_period = true;
        auto ns = parse_duration_ns(v.scalar, &err);
        if (!ns) d_.error(v.loc, "period: " + err);
        else if (*ns < kMinPeriod || *ns > kMaxPeriod)
          d_.error(v.loc, "period " + v.scalar + " is outside 100us .. 10s");
        else { td.cfg.period_ns = *ns; period_ok = true; }
      } else if (k == "phase") {
        auto ns = parse_duration_ns(v.scalar, &err);
        if (!ns) d_.error(v.loc, "phase: " + err);
        else if (*ns < 0) d_.error(v.loc, "phase must not be negative");
        else td.cfg.phase_ns = *ns;
      } else if (k == "priority") {
        auto c = parse_value(IecType::DINT, v.scalar, &err);
        if (!c) d_.error(v.loc, "priority: " + err);
        else if (c->get<std::int32_t>() < 1 || c->get<std::int32_t>() > 99)
          d_.error(v.loc, "priority " + v.scalar + " is outside 1..99 (SCHED_FIFO; higher runs first)");
        else td.cfg.priority = c->get<std::int32_t>();
      } else if (k == "cpu") {
        auto c = parse_value(IecType::DINT, v.scalar, &err);
        if (!c || c->get<std::int32_t>() < 0 || c->get<std::int32_t>() > 1023) d_.error(v.loc, "cpu: a CPU number 0..1023");
        else td.cfg.cpu = c->get<std::int32_t>();
      } else if (k == "missed_cycles") {
        if (v.scalar == "skip") td.cfg.missed = MissedCycles::Skip;
        else if (v.scalar == "immediate") td.cfg.missed = MissedCycles::Immediate;
        else d_.error(v.loc, "missed_cycles must be 'skip' or 'immediate', not '" + v.scalar + "'");
      } else if (k == "write_queue") {
        auto c = parse_value(IecType::UDINT, v.scalar, &err);
        if (!c || c->get<std::uint32_t>() < 16 || c->get<std::uint32_t>() > 1'000'000) d_.error(v.loc, "write_queue: 16..1000000 entries");
        else {
          td.cfg.write_queue = c->get<std::uint32_t>();
          td.write_queue_loc = v.loc;
        }
      } else if (k == "watchdog") {
        if (!v.is_map()) { d_.error(v.loc, "watchdog: expected a map {time, sensitivity, action}"); continue; }
        td.cfg.watchdog = true;
        bool has_time = false;
        for (const auto& [wk, wv] : v.map) {
          if (wk == "time") {
            has_time = true;
            auto ns = parse_duration_ns(wv.scalar, &err);
            if (!ns) d_.error(wv.loc, "watchdog time: " + err);
            else if (*ns <= 0) d_.error(wv.loc, "watchdog time must be positive");
            else td.cfg.watchdog_ns = *ns;
          } else if (wk == "sensitivity") {
            auto c = parse_value(IecType::DINT, wv.scalar, &err);
            if (!c || c->get<std::int32_t>() < 1 || c->get<std::int32_t>() > 1000)
              d_.error(wv.loc, "sensitivity must be an integer 1..1000");
            else td.cfg.sensitivity = c->get<std::int32_t>();
          } else if (wk == "action") {
            if (wv.scalar == "log") td.cfg.action = WatchdogAction::Log;
            else if (wv.scalar == "stop") td.cfg.action = WatchdogAction::Stop;
            else if (wv.scalar == "safe_stop") td.cfg.action = WatchdogAction::SafeStop;
            else d_.error(wv.loc, "watchdog action must be log, stop or safe_stop, not '" + wv.scalar + "'");
          } else d_.error(wv.loc, "unknown key '" + wk + "' in watchdog (time, sensitivity, action)");
        }
        if (!has_time) d_.error(v.loc, "watchdog needs a time");
      } else d_.error(v.loc, "unknown key '" + k + "' in a task (name, period, phase, priority, watchdog, missed_cycles, cpu, write_queue)");
    }
    if (td.cfg.name.empty()) d_.error(t.loc, "task without a name");
    if (!has_period) d_.error(t.loc, "task " + td.cfg.name + " has no period");
    if (td.cfg.phase_ns >= td.cfg.period_ns && period_ok)
      d_.error(t.find("phase") ? t.find("phase")->loc : t.loc, "phase must be shorter than the period");
    if (tasks_.size() >= 64) { d_.error(t.loc, "more than 64 tasks"); continue; }
    if (!td.cfg.name.empty()) task_by_name_.emplace(td.cfg.name, static_cast<int>(tasks_.size()));
    tasks_.push_back(std::move(td));
  }
}

std::optional<Cell> Loader::parse_literal(IecType t, const std::string& unit, const std::string& text,
                                          const SourceLoc& loc, const std::string& what) {
  std::string err;
  if (is_real(t)) {
    auto v = parse_quantity(text, unit, &err);
    std::optional<Cell> c;
    if (v) c = real_cell(t, *v, text, &err);
    if (!c) d_.error(loc, what + ": " + err);
    return c;
  }
  auto c = parse_value(t, text, &err);
  if (!c) d_.error(loc, what + ": " + err);
  return c;
}

std::vector<Cell> Loader::parse_tag_values(const TagDecl& td, const ConfigNode& n, const std::string& what) {
  const Tag& t = td.tag;
  std::vector<Cell> out;
  if (n.is_scalar()) {
    auto c = parse_literal(t.type, t.unit, n.scalar, n.loc, what + " of " + t.name);
    if (c) out.assign(t.length, *c);
  } else if (n.is_list()) {
    if (n.items.size() != t.length) {
      d_.error(n.loc, what + " of " + t.name + ": " + std::to_string(n.items.size()) + " values for " +
                          std::to_string(t.length) + " elements");
      return out;
    }
    for (const auto& i : n.items) {
      auto c = parse_literal(t.type, t.unit, i.scalar, i.loc, what + " of " + t.name);
      if (!c) return {};
      out.push_back(*c);
    }
  } else {
    d_.error(n.loc, what + " of " + t.name + ": expected a value or a list of values");
  }
  return out;
}

// "LREAL", "ARRAY[0..3] OF LREAL"
bool parse_tag_type(const std::string& s, IecType& t, std::uint32_t& len, std::int64_t& lower, bool& is_array,
                    std::string& err) {
  std::string u;
  for (char c : s) u += static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  is_array = false;
  len = 1;
  lower = 0;
  if (u.rfind("ARRAY", 0) == 0) {
    auto lb = u.find('['), dots = u.find(".."), rb = u.find(']'), of = u.find(" OF ");
    if (lb == std::string::npos || dots == std::string::npos || rb == std::string::npos || of == std::string::npos ||
        !(lb < dots && dots < rb && rb < of)) {
      err = "bad array type '" + s + "' (write ARRAY[0..3] OF LREAL)";
      return false;
    }
    try {
      long long lo = std::stoll(u.substr(lb + 1, dots - lb - 1));
      long long hi = std::stoll(u.substr(dots + 2, rb - dots - 2));
      if (hi < lo || hi - lo + 1 > 65536) {
        err = "array bounds of '" + s + "' must give 1..65536 elements";
        return false;
      }
      len = static_cast<std::uint32_t>(hi - lo + 1);
      lower = lo;
    } catch (...) {
      err = "bad array bounds in '" + s + "'";
      return false;
    }
    is_array = true;
    auto et = parse_type_name(u.substr(of + 4));
    if (!et) {
      err = "unknown element type in '" + s + "'";
      return false;
    }
    t = *et;
    return true;
  }
  auto et = parse_type_name(u);
  if (!et) {
    err = "unknown IEC type '" + s + "' (BOOL, SINT, INT, DINT, LINT, USINT, UINT, UDINT, ULINT, BYTE, WORD, DWORD, LWORD, REAL, LREAL, TIME or ARRAY[a..b] OF type)";
    return false;
  }
  t = *et;
  return true;
}

void Loader::read_tags(const ConfigNode& n) {
  if (!n.is_list()) { d_.error(n.loc, "tags: expected a list"); return; }
  tags_.reserve(tags_.size() + n.items.size());
  for (const auto& t : n.items) {
    if (!t.is_map()) { d_.error(t.loc, "a tag is a map {name, type, ...}"); continue; }
    TagDecl td;
    td.tag.loc = t.loc;
    bool ok = true, has_type = false;
    const ConfigNode *addr = nullptr, *modbus = nullptr;
    for (const auto& [k, v] : t.map) {
      if (k == "name") {
        td.tag.name = v.scalar;
        if (!is_identifier(v.scalar)) { d_.error(v.loc, "tag name '" + v.scalar + "' is not an identifier"); ok = false; }
        else if (names_.count(v.scalar)) { d_.error(v.loc, "duplicate name '" + v.scalar + "' (first defined at " + names_[v.scalar].text() + ")"); ok = false; }
        else names_[v.scalar] = v.loc;
      } else if (k == "type") {
        has_type = true;
        std::string err;
        std::int64_t lower;
        if (!parse_tag_type(v.scalar, td.tag.type, td.tag.length, lower, td.tag.is_array, err)) { d_.error(v.loc, err); ok = false; }
        td.tag.array_lower = lower;
      } else if (k == "address") addr = &v;
      else if (k == "retain") {
        std::string err;
        auto c = parse_value(IecType::BOOL, v.scalar, &err);
        if (!c) d_.error(v.loc, "retain: " + err); else td.tag.retain = c->get<bool>();
      } else if (k == "hmi") {
        if (v.scalar == "none") td.tag.hmi = HmiAccess::None;
        else if (v.scalar == "read") td.tag.hmi = HmiAccess::Read;
        else if (v.scalar == "readwrite") td.tag.hmi = HmiAccess::ReadWrite;
        else d_.error(v.loc, "hmi must be none, read or readwrite, not '" + v.scalar + "'");
      } else if (k == "unit") {
        std::string err;
        if (!parse_unit(v.scalar, &err)) d_.error(v.loc, err);
        td.tag.unit = v.scalar;
      } else if (k == "description") td.tag.description = v.scalar;
      else if (k == "init") td.init = &v;
      else if (k == "safe") td.safe = &v;
      else if (k == "task") { td.task = v.scalar; td.task_loc = v.loc; }
      else if (k == "modbus") modbus = &v;
      else d_.error(v.loc, "unknown key '" + k + "' in a tag (name, type, address, modbus, retain, hmi, unit, description, init, safe, task)");
    }
    if (td.tag.name.empty()) { d_.error(t.loc, "tag without a name"); ok = false; }
    if (!has_type) { d_.error(t.loc, "tag " + td.tag.name + " has no type"); ok = false; }
    if (!ok && !td.tag.name.empty()) failed_names_.insert(td.tag.name);
    if (ok && addr) {
      std::string err;
      auto a = parse_direct_address(addr->scalar, &err);
      if (!a) d_.error(addr->loc, err);
      else if (auto why = check_address_type(*a, td.tag.type); !why.empty()) d_.error(addr->loc, why);
      else {
        td.tag.address = *a;
        for (const auto& o : tags_)
          if (o.tag.address && overlaps(*a, td.tag.length, *o.tag.address, o.tag.length))
            d_.error(addr->loc, "address " + a->text() + " of " + td.tag.name + " overlaps " + o.tag.address->text() +
                                    " of " + o.tag.name + " (defined at " + o.tag.loc.text() + ")");
      }
    }
    if (ok && modbus) {
      // After the loop: the place is checked against the tag's type, length and hmi.
      td.modbus_loc = modbus->loc;
      td.tag.modbus = read_modbus_place(*modbus, td.tag, d_);
      td.modbus_failed = !td.tag.modbus;
    }
    if (!td.task.empty() && task_index(td.task) < 0) d_.error(td.task_loc, "unknown task '" + td.task + "'");
    if (ok) {
      td.tag.init.assign(td.tag.length, Cell{});
      if (td.init) { auto v = parse_tag_values(td, *td.init, "init"); if (!v.empty()) td.tag.init = v; }
      if (td.safe) td.tag.safe = parse_tag_values(td, *td.safe, "safe value");
      tag_by_name_.emplace(td.tag.name, static_cast<int>(tags_.size()));
      tags_.push_back(std::move(td));
    }
  }
}

void Loader::read_blocks(const ConfigNode& n) {
  if (!n.is_list()) { d_.error(n.loc, "blocks: expected a list"); return; }
  insts_.reserve(insts_.size() + n.items.size());
  for (const auto& b : n.items) {
    if (!b.is_map()) { d_.error(b.loc, "a block instance is a map {name, type, task, ...}"); continue; }
    InstanceDecl in;
    in.loc = b.loc;
    bool ok = true;
    const ConfigNode *params = nullptr, *inputs = nullptr, *dtype = nullptr, *task = nullptr;
    for (const auto& [k, v] : b.map) {
      if (k == "name") {
        in.name = v.scalar;
        if (!is_identifier(v.scalar)) { d_.error(v.loc, "instance name '" + v.scalar + "' is not an identifier"); ok = false; }
        else if (names_.count(v.scalar)) { d_.error(v.loc, "duplicate name '" + v.scalar + "' (first defined at " + names_[v.scalar].text() + ")"); ok = false; }
        else names_[v.scalar] = v.loc;
      } else if (k == "type") {
        in.type = blocks_->find(v.scalar);
        if (!in.type) { d_.error(v.loc, "unknown block type '" + v.scalar + "' (see `syncplc blocks`)"); ok = false; }
      } else if (k == "task") task = &v;
      else if (k == "params") params = &v;
      else if (k == "inputs") inputs = &v;
      else if (k == "datatype") dtype = &v;
      else if (k == "description") {}
      else d_.error(v.loc, "unknown key '" + k + "' in a block instance (name, type, task, datatype, params, inputs, description)");
    }
    if (in.name.empty()) { d_.error(b.loc, "block instance without a name"); ok = false; }
    if (!b.find("type")) { d_.error(b.loc, "block instance " + in.name + " has no type"); ok = false; }
    if (!task) { if (tasks_.size() == 1) in.task = 0; else { d_.error(b.loc, "block instance " + in.name + " has no task"); ok = false; } }
    else if ((in.task = task_index(task->scalar)) < 0) { d_.error(task->loc, "unknown task '" + task->scalar + "'"); ok = false; }
    if (!ok || !in.type) {
      if (!in.name.empty()) failed_names_.insert(in.name);
      continue;
    }
    const auto& T = *in.type;
    if (dtype) {
      auto t = parse_type_name(dtype->scalar);
      if (!T.is_generic()) d_.error(dtype->loc, T.name + " is not generic: it takes no datatype");
      else if (!t) d_.error(dtype->loc, "unknown IEC type '" + dtype->scalar + "'");
      else {
        bool fits = true;
        for (const auto& p : T.pins)
          if (p.cls != TypeClass::Exact && !in_class(*t, p.cls)) {
            d_.error(dtype->loc, T.name + " pin " + p.name + " is " + std::string(class_name(p.cls)) + ": " +
                                     dtype->scalar + " does not belong to it");
            fits = false;
            break;
          }
        if (fits) { in.datatype = *t; in.datatype_fixed = true; }
      }
    }
    in.params.assign(T.params.size(), nullptr);
    in.param_override.assign(T.params.size(), "");
    in.inputs.assign(T.pins.size(), nullptr);
    in.source.assign(T.pins.size(), -1);
    in.pin_length.assign(T.pins.size(), 1);
    in.element_source.assign(T.pins.size(), {});
    if (params) {
      if (!params->is_map()) d_.error(params->loc, "params: expected a map of parameter: value");
      else
        for (const auto& [k, v] : params->map) {
          int i = T.param_index(k);
          if (i < 0) {
            std::string names;
            for (const auto& p : T.params) names += (names.empty() ? "" : ", ") + p.name;
            d_.error(v.loc, T.name + " has no parameter '" + k + "'" + (names.empty() ? " (it has none)" : " (" + names + ")"));
          } else in.params[static_cast<std::size_t>(i)] = &v;
        }
    }
    if (inputs) {
      if (!inputs->is_map()) d_.error(inputs->loc, "inputs: expected a map of pin: constant value");
      else
        for (const auto& [k, v] : inputs->map) {
          int i = T.pin_index(k);
          if (i < 0) d_.error(v.loc, T.name + " has no pin '" + k + "'");
          else if (T.pins[static_cast<std::size_t>(i)].dir != PinDir::In) d_.error(v.loc, T.name + "." + k + " is an output: it takes no constant");
          else in.inputs[static_cast<std::size_t>(i)] = &v;
        }
    }
    for (std::size_t i = 0; i < T.params.size(); ++i)
      if (T.params[i].default_value.empty() && !in.params[i])
        d_.error(b.loc, "block instance " + in.name + " needs parameter " + T.params[i].name);
    instance_by_name_.emplace(in.name, static_cast<int>(insts_.size()));
    insts_.push_back(std::move(in));
  }
}

// --set driver.key=value and driver.key.subkey=value change a driver's settings
// before it is created, as if the project file said so (the value's errors
// are reported at "command line").
void Loader::override_driver_settings(ConfigNode& drivers) {
  if (!drivers.is_list()) return;
  for (const auto& o : opts_.overrides) {
    for (auto& dn : drivers.items) {
      const ConfigNode* nm = dn.is_map() ? dn.find("name") : nullptr;
      if (!nm || nm->scalar != o.instance || o.param.empty()) continue;
      driver_overrides_.insert(o.instance);
      ConfigNode* at = &dn;
      std::string path = o.param;
      SourceLoc cli{"command line", 0, 0};
      bool ok = true;
      while (ok) {
        auto dot = path.find('.');
        std::string key = path.substr(0, dot);
        if (key == "name" || key == "type" || key == "task") {
          d_.error(cli, "--set " + o.instance + "." + o.param + ": a driver's " + key + " cannot be overridden");
          ok = false;
          break;
        }
        ConfigNode* child = nullptr;
        for (auto& [k, v] : at->map)
          if (k == key) child = &v;
        if (!child) {
          at->map.emplace_back(key, ConfigNode{});
          child = &at->map.back().second;
        }
        if (dot == std::string::npos) {
          child->kind = ConfigNode::Kind::Scalar;
          child->scalar = o.value;
          child->items.clear();
          child->map.clear();
          child->loc = cli;
          break;
        }
        if (!child->is_map()) {
          if (child->kind != ConfigNode::Kind::Null) {
            d_.error(cli, "--set " + o.instance + "." + o.param + ": " + key + " is not a map of settings");
            ok = false;
            break;
          }
          child->kind = ConfigNode::Kind::Map;
          child->loc = cli;
        }
        at = child;
        path = path.substr(dot + 1);
      }
    }
  }
}

void Loader::read_drivers(const ConfigNode& n) {
  if (!n.is_list()) { d_.error(n.loc, "drivers: expected a list"); return; }
  for (const auto& dn : n.items) {
    if (!dn.is_map()) { d_.error(dn.loc, "a driver is a map {name, type, task, bind, ...}"); continue; }
    DriverDecl dd;
    dd.loc = dn.loc;
    dd.node = &dn;
    const ConfigNode* nm = dn.find("name");
    const ConfigNode* ty = dn.find("type");
    const ConfigNode* tk = dn.find("task");
    if (!nm || nm->scalar.empty()) { d_.error(dn.loc, "driver without a name"); continue; }
    dd.name = nm->scalar;
    if (!is_identifier(dd.name)) { d_.error(nm->loc, "driver name '" + dd.name + "' is not an identifier"); continue; }
    if (names_.count(dd.name)) { d_.error(nm->loc, "duplicate name '" + dd.name + "' (first defined at " + names_[dd.name].text() + ")"); continue; }
    names_[dd.name] = nm->loc;
    if (!ty) { d_.error(dn.loc, "driver " + dd.name + " has no type"); continue; }
    const DriverTypeInfo* info = drivers_->find(ty->scalar);
    if (!info) {
      std::string names;
      for (const auto& x : drivers_->names()) names += (names.empty() ? "" : ", ") + x;
      d_.error(ty->loc, "unknown driver type '" + ty->scalar + "' (" + names + ")");
      continue;
    }
    dd.type = ty->scalar;
    if (!tk) { if (tasks_.size() == 1) dd.task = 0; else { d_.error(dn.loc, "driver " + dd.name + " has no task"); continue; } }
    else if ((dd.task = task_index(tk->scalar)) < 0) { d_.error(tk->loc, "unknown task '" + tk->scalar + "'"); continue; }
    current_driver_period_ = tasks_[static_cast<std::size_t>(dd.task)].cfg.period_ns;
    current_driver_seed_ = mix_seed(seed_, dd.name);
    std::size_t before = d_.size();
    dd.driver = info->create(dn, *this);
    if (!dd.driver) {
      if (d_.size() == before) d_.error(dn.loc, "driver " + dd.name + " could not be created");
      continue;
    }
    dd.driver->set_name(dd.name);
    const auto& chans = dd.driver->channels();
    dd.channel_tag.assign(chans.size(), -1);
    dd.channel_loc.assign(chans.size(), dn.loc);
    if (const ConfigNode* bind = dn.find("bind")) {
      if (!bind->is_map()) d_.error(bind->loc, "bind: expected a map of channel: tag");
      else
        for (const auto& entry : bind->map) {
          // Named, not a structured binding: clang 14 cannot capture those in a lambda.
          const std::string& ch = entry.first;
          const ConfigNode& tagn = entry.second;
          auto it = std::find_if(chans.begin(), chans.end(), [&](const DriverChannel& c) { return c.name == ch; });
          if (it == chans.end()) { d_.error(tagn.loc, "driver " + dd.name + " has no channel '" + ch + "'"); continue; }
          int ti = tag_index(tagn.scalar);
          if (ti < 0 && failed_names_.count(tagn.scalar)) continue;
          if (ti < 0) { d_.error(tagn.loc, "unknown tag '" + tagn.scalar + "'"); continue; }
          const Tag& tg = tags_[static_cast<std::size_t>(ti)].tag;
          if (tg.type != it->type || tg.length != it->length)
            d_.error(tagn.loc, "type mismatch: channel " + dd.name + "." + ch + " is " + std::string(type_name(it->type)) +
                                   (it->length > 1 ? "[" + std::to_string(it->length) + "]" : "") + ", tag " + tg.name + " is " +
                                   std::string(type_name(tg.type)) + (tg.length > 1 ? "[" + std::to_string(tg.length) + "]" : ""));
          auto ci = static_cast<std::size_t>(it - chans.begin());
          dd.channel_tag[ci] = ti;
          dd.channel_loc[ci] = tagn.loc;
        }
    }
    drvs_.push_back(std::move(dd));
  }
}

bool Loader::parse_endpoint(const std::string& raw, const SourceLoc& loc, Endpoint& e) {
  std::string s = raw;
  while (!s.empty() && std::isspace(static_cast<unsigned char>(s.back()))) s.pop_back();
  while (!s.empty() && std::isspace(static_cast<unsigned char>(s.front()))) s.erase(s.begin());
  e.text = s;
  e.loc = loc;
  std::string base = s;
  std::optional<long long> idx;
  if (auto lb = s.find('['); lb != std::string::npos) {
    if (s.back() != ']') { d_.error(loc, "bad element reference '" + s + "'"); return false; }
    try {
      std::string inner = s.substr(lb + 1, s.size() - lb - 2);
      std::size_t used = 0;
      idx = std::stoll(inner, &used);
      if (used != inner.size()) throw std::invalid_argument(inner);  // arr[2x]
    } catch (...) { d_.error(loc, "bad array index in '" + s + "'"); return false; }
    base = s.substr(0, lb);
  }
  if (auto dot = base.find('.'); dot != std::string::npos) {
    std::string inst = base.substr(0, dot), pin = base.substr(dot + 1);
    e.instance = instance_index(inst);
    if (e.instance < 0) {
      if (failed_names_.count(inst)) return false;  // its declaration's error says enough
      if (names_.count(inst)) d_.error(loc, "'" + inst + "' is not a block instance (connect drivers with bind:)");
      else d_.error(loc, "unknown block instance '" + inst + "'");
      return false;
    }
    const auto& T = *insts_[static_cast<std::size_t>(e.instance)].type;
    e.pin = T.pin_index(pin);
    if (e.pin < 0) {
      std::string names;
      for (const auto& p : T.pins) names += (names.empty() ? "" : ", ") + p.name;
      d_.error(loc, "block " + inst + " (" + T.name + ") has no pin '" + pin + "' (" + names + ")");
      return false;
    }
    e.is_pin = true;
    if (idx) {
      const auto& in = insts_[static_cast<std::size_t>(e.instance)];
      const auto& decl = T.pins[static_cast<std::size_t>(e.pin)];
      if (!decl.is_array()) { d_.error(loc, "pin " + base + " is not an array"); return false; }
      if (!in.params_ok) return false;  // its length is unknown; the parameter's error says why
      std::uint32_t len = in.pin_length[static_cast<std::size_t>(e.pin)];
      if (*idx < 1 || *idx > static_cast<long long>(len)) {
        d_.error(loc, "index " + std::to_string(*idx) + " is outside " + base + "[1.." + std::to_string(len) + "]");
        return false;
      }
      e.element = static_cast<std::uint32_t>(*idx - 1);  // array pins are ARRAY[1..n]
    }
    return true;
  }
  e.tag = tag_index(base);
  if (e.tag < 0 && failed_names_.count(base)) return false;
  if (e.tag < 0) { d_.error(loc, "unknown tag or instance.pin '" + base + "'"); return false; }
  if (idx) {
    const Tag& t = tags_[static_cast<std::size_t>(e.tag)].tag;
    long long rel = *idx - t.array_lower;
    if (!t.is_array) { d_.error(loc, "tag " + base + " is not an array"); return false; }
    if (rel < 0 || rel >= t.length) {
      d_.error(loc, "index " + std::to_string(*idx) + " is outside " + base + "[" + std::to_string(t.array_lower) + ".." +
                        std::to_string(t.array_lower + t.length - 1) + "]");
      return false;
    }
    e.element = static_cast<std::uint32_t>(rel);
  }
  return true;
}

void Loader::read_connections(const ConfigNode& n) {
  if (!n.is_list()) { d_.error(n.loc, "connections: expected a list of 'source.pin -> target.pin'"); return; }
  conns_.reserve(conns_.size() + n.items.size());
  for (const auto& c : n.items) {
    std::string src, dst;
    SourceLoc sl = c.loc, dl = c.loc;
    if (c.is_scalar()) {
      auto arrow = c.scalar.find("->");
      if (arrow == std::string::npos) { d_.error(c.loc, "a connection is written 'source.pin -> target.pin'"); continue; }
      src = c.scalar.substr(0, arrow);
      dst = c.scalar.substr(arrow + 2);
      std::size_t lead = dst.find_first_not_of(' ');
      dl.col += static_cast<int>(arrow + 2 + (lead == std::string::npos ? 0 : lead));
    } else if (c.is_map() && c.find("from") && c.find("to")) {
      src = c.find("from")->scalar;
      dst = c.find("to")->scalar;
      sl = c.find("from")->loc;
      dl = c.find("to")->loc;
    } else { d_.error(c.loc, "a connection is written 'source.pin -> target.pin' or {from: , to: }"); continue; }
    ConnectionDecl cd;
    cd.loc = c.loc;
    std::size_t before = d_.size();
    bool src_ok = parse_endpoint(src, sl, cd.src);
    bool src_silent = !src_ok && d_.size() == before;  // its source's declaration failed and was reported
    bool ok = parse_endpoint(dst, dl, cd.dst) && src_ok;
    if (src_silent && cd.dst.is_pin) {
      // The input is wired, to something broken: no "must be connected" on top.
      auto& di = insts_[static_cast<std::size_t>(cd.dst.instance)];
      if (di.source[static_cast<std::size_t>(cd.dst.pin)] == -1) di.source[static_cast<std::size_t>(cd.dst.pin)] = kBrokenSource;
    }

    if (!ok) continue;
    if (cd.src.is_pin) {
      const auto& p = insts_[static_cast<std::size_t>(cd.src.instance)].type->pins[static_cast<std::size_t>(cd.src.pin)];
      if (p.dir != PinDir::Out) { d_.error(sl, cd.src.text + " is an input: a connection starts at an output or a tag"); continue; }
    }
    if (cd.dst.is_pin) {
      const auto& p = insts_[static_cast<std::size_t>(cd.dst.instance)].type->pins[static_cast<std::size_t>(cd.dst.pin)];
      if (p.dir != PinDir::In) { d_.error(dl, cd.dst.text + " is an output: a connection ends at an input or a tag"); continue; }
    }
    if (!cd.src.is_pin && !cd.dst.is_pin) { d_.error(c.loc, "tag-to-tag connection: copy a tag through a MOVE block"); continue; }
    if (cd.src.is_pin && cd.dst.is_pin &&
        insts_[static_cast<std::size_t>(cd.src.instance)].task != insts_[static_cast<std::size_t>(cd.dst.instance)].task) {
      d_.error(c.loc, "blocks in different tasks exchange data through a tag: connect " + cd.src.text + " -> a tag -> " + cd.dst.text);
      continue;
    }
    if (cd.dst.is_pin) {
      auto& di = insts_[static_cast<std::size_t>(cd.dst.instance)];
      auto pi = static_cast<std::size_t>(cd.dst.pin);
      auto already = [&](int ci) {
        const auto& o = conns_[static_cast<std::size_t>(ci)];
        d_.error(dl, cd.dst.text + " already has a source (" + o.src.text + " -> " + o.dst.text + " at " + o.loc.text() + ")");
      };
      auto& es = di.element_source[pi];
      if (di.source[pi] >= 0) { already(di.source[pi]); continue; }
      if (di.inputs[pi]) { d_.error(dl, cd.dst.text + " is connected and also given a constant in inputs:"); continue; }
      if (cd.dst.element) {
        if (es.empty()) es.assign(di.pin_length[pi], -1);
        int& slot = es[*cd.dst.element];
        if (slot >= 0) { already(slot); continue; }
        slot = static_cast<int>(conns_.size());
      } else {
        auto taken = std::find_if(es.begin(), es.end(), [](int c) { return c >= 0; });
        if (taken != es.end()) { already(*taken); continue; }
        di.source[pi] = static_cast<int>(conns_.size());
      }
    }
    conns_.push_back(std::move(cd));
  }
}

void Loader::read_metrics(const ConfigNode& n) {
  if (!n.is_map()) { d_.error(n.loc, "metrics: expected a map {axis_errors, from}"); return; }
  for (const auto& [k, v] : n.map) {
    if (k == "axis_errors") {
      if (v.is_scalar()) axis_errors_.emplace_back(v.scalar, v.loc);
      else if (v.is_list())
        for (const auto& i : v.items) {
          if (i.is_scalar()) axis_errors_.emplace_back(i.scalar, i.loc);
          else d_.error(i.loc, "metrics axis_errors: expected a tag, tag[i] or instance.pin");
        }
      else d_.error(v.loc, "metrics axis_errors: an array tag or a list of tags, in axis order");
    } else if (k == "from") {
      std::string err;
      auto ns = v.is_scalar() ? parse_duration_ns(v.scalar, &err) : std::nullopt;
      if (!ns || *ns < 0) d_.error(v.loc, "metrics from: " + (err.empty() ? "'" + v.scalar + "' must not be negative" : err));
      else metrics_from_ns_ = *ns;
    } else {
      d_.error(v.loc, "unknown key '" + k + "' in metrics (axis_errors, from)");
    }
  }
  if (axis_errors_.empty()) d_.error(n.loc, "metrics: axis_errors is missing");
}

// Two tags may not share a coil or register. Checked with the map the server
// will build, on the tags read so far; a tag whose modbus: key was wrong is
// left out so that it causes no second error.
std::vector<Tag> Loader::modbus_tags() const {
  std::vector<Tag> tags;
  for (const auto& td : tags_) {
    tags.push_back(td.tag);
    if (td.modbus_failed) tags.back().hmi = HmiAccess::None;
  }
  return tags;
}

void Loader::check_modbus_places() {
  std::vector<SourceLoc> place_loc;
  for (const auto& td : tags_) place_loc.push_back(td.modbus_loc);
  check_modbus_overlaps(modbus_tags(), place_loc, d_);
}

// A task's write queue must hold the largest write one Modbus request can
// bring it (largest_modbus_writes): the default grows to fit, a write_queue
// the project set too small is an error at that key. A read-only server
// queues nothing (and --modbus-port does not change read_only).
void Loader::size_write_queues() {
  if (modbus_.read_only) return;
  const auto most = largest_modbus_writes(modbus_tags(), tasks_.size());
  for (std::size_t i = 0; i < tasks_.size(); ++i) {
    TaskDecl& td = tasks_[i];
    if (most[i] <= td.cfg.write_queue) continue;
    if (td.write_queue_loc)
      d_.error(*td.write_queue_loc, "write_queue " + std::to_string(td.cfg.write_queue) + " of task " + td.cfg.name +
                                        " cannot hold one Modbus write to its tags: a request can queue " +
                                        std::to_string(most[i]) + " values to it at once");
    else
      td.cfg.write_queue = most[i];
  }
}

void Loader::apply_overrides() {
  SourceLoc cli{"command line", 0, 0};
  for (const auto& o : opts_.overrides) {
    if (driver_overrides_.count(o.instance)) continue;  // applied to the driver's settings
    int ii = instance_index(o.instance);
    if (ii < 0) {
      int ti = tag_index(o.instance);
      if (ti >= 0 && o.param.empty()) { tags_[static_cast<std::size_t>(ti)].init_override = o.value; continue; }
      d_.error(cli, "--set " + o.instance + "." + o.param + ": no block instance '" + o.instance + "'");
      continue;
    }
    auto& in = insts_[static_cast<std::size_t>(ii)];
    int pi = in.type->param_index(o.param);
    if (pi >= 0) { in.param_override[static_cast<std::size_t>(pi)] = o.value; continue; }
    int pin = in.type->pin_index(o.param);
    if (pin >= 0 && in.type->pins[static_cast<std::size_t>(pin)].dir == PinDir::In) {
      d_.error(cli, "--set " + o.instance + "." + o.param + ": that is a pin; --set takes parameters");
      continue;
    }
    d_.error(cli, "--set " + o.instance + "." + o.param + ": " + in.type->name + " has no parameter '" + o.param + "'");
  }
  for (auto& td : tags_)
    if (!td.init_override.empty()) {
      ConfigNode n;
      n.kind = ConfigNode::Kind::Scalar;
      n.scalar = td.init_override;
      n.loc = cli;
      auto v = parse_tag_values(td, n, "--set init");
      if (!v.empty()) td.tag.init = v;
    }
}

bool Loader::endpoint_type_known(const Endpoint& e) const {
  if (!e.is_pin) return true;
  const auto& in = insts_[static_cast<std::size_t>(e.instance)];
  const auto& p = in.type->pins[static_cast<std::size_t>(e.pin)];
  return p.cls == TypeClass::Exact || in.datatype.has_value();
}

IecType Loader::endpoint_type(const Endpoint& e, std::uint32_t* length) const {
  if (!e.is_pin) {
    const Tag& t = tags_[static_cast<std::size_t>(e.tag)].tag;
    if (length) *length = e.element ? 1 : t.length;
    return t.type;
  }
  const auto& in = insts_[static_cast<std::size_t>(e.instance)];
  const auto& p = in.type->pins[static_cast<std::size_t>(e.pin)];
  if (length) *length = e.element ? 1 : in.pin_length[static_cast<std::size_t>(e.pin)];
  return p.cls == TypeClass::Exact ? p.type : in.datatype.value_or(IecType::LREAL);
}

void Loader::infer_types() {
  // A generic instance takes the type of whatever typed end it is connected
  // to; what is still open takes the block's default. A worklist of
  // connections, so that a chain settles in linear time whichever way it
  // was written: first every connection in file order, then the connections
  // of each instance as it gets its type.
  std::vector<std::vector<std::size_t>> touching(insts_.size());
  for (std::size_t ci = 0; ci < conns_.size(); ++ci)
    for (const Endpoint* e : {&conns_[ci].src, &conns_[ci].dst})
      if (e->is_pin) touching[static_cast<std::size_t>(e->instance)].push_back(ci);
  std::deque<std::size_t> work;
  for (std::size_t ci = 0; ci < conns_.size(); ++ci) work.push_back(ci);
  auto typed = [&](std::size_t i) {
    for (std::size_t ci : touching[i]) work.push_back(ci);
  };
  auto settle = [&](const Endpoint& a, const Endpoint& b) {
    if (!a.is_pin) return;
    auto& in = insts_[static_cast<std::size_t>(a.instance)];
    const auto& p = in.type->pins[static_cast<std::size_t>(a.pin)];
    if (p.cls == TypeClass::Exact || in.datatype || !endpoint_type_known(b)) return;
    IecType t = endpoint_type(b, nullptr);
    if (!in_class(t, p.cls)) return;  // reported as a mismatch later
    in.datatype = t;
    typed(static_cast<std::size_t>(a.instance));
  };
  // Defaults one instance at a time, so its neighbours can infer from it: the
  // first (in declaration order) whose default belongs to the class of every
  // still-open generic pin it is connected to (so MOVE before CTU, CTU.CV ->
  // MOVE.IN gives MOVE<INT>, not a clash with LREAL), else the first.
  auto suits_neighbours = [&](std::size_t i) {
    IecType t = *insts_[i].type->default_datatype;
    for (std::size_t ci : touching[i]) {
      const auto& c = conns_[ci];
      for (const auto& [mine, other] : {std::pair{&c.src, &c.dst}, std::pair{&c.dst, &c.src}}) {
        if (!mine->is_pin || static_cast<std::size_t>(mine->instance) != i || !other->is_pin) continue;
        const auto& o = insts_[static_cast<std::size_t>(other->instance)];
        const auto& op = o.type->pins[static_cast<std::size_t>(other->pin)];
        if (op.cls != TypeClass::Exact && !o.datatype && !in_class(t, op.cls)) return false;
      }
    }
    return true;
  };
  auto open = [&](std::size_t i) {
    const auto& in = insts_[i];
    return in.type->is_generic() && !in.datatype && in.type->default_datatype;
  };
  std::size_t first_open = 0;  // instances before it all have their type
  for (;;) {
    while (!work.empty()) {
      const auto& c = conns_[work.front()];
      work.pop_front();
      settle(c.src, c.dst);
      settle(c.dst, c.src);
    }
    while (first_open < insts_.size() && !open(first_open)) ++first_open;
    if (first_open == insts_.size()) break;
    std::size_t pick = first_open;
    for (std::size_t i = first_open; i < insts_.size(); ++i)
      if (open(i) && suits_neighbours(i)) { pick = i; break; }
    insts_[pick].datatype = insts_[pick].type->default_datatype;
    typed(pick);
  }
  for (auto& in : insts_)
    if (in.type->is_generic() && !in.datatype)
      d_.error(in.loc, "cannot infer the data type of " + in.name + " (" + in.type->name + "): set datatype:");
}

void Loader::check_connections() {
  for (const auto& c : conns_) {
    std::uint32_t ls = 1, ld = 1;
    IecType ts = endpoint_type(c.src, &ls), td = endpoint_type(c.dst, &ld);
    auto show = [&](IecType t, std::uint32_t l) {
      return std::string(type_name(t)) + (l > 1 ? "[" + std::to_string(l) + "]" : "");
    };
    auto lengths_known = [&](const Endpoint& e) {
      return !e.is_pin || insts_[static_cast<std::size_t>(e.instance)].params_ok;
    };
    if (ts == td && ls != ld && (!lengths_known(c.src) || !lengths_known(c.dst))) continue;
    if (ts != td || ls != ld)
      d_.error(c.loc, "type mismatch: " + c.src.text + " is " + show(ts, ls) + ", " + c.dst.text + " is " + show(td, ld));
    else if (c.dst.is_pin) {
      const auto& in = insts_[static_cast<std::size_t>(c.dst.instance)];
      const auto& p = in.type->pins[static_cast<std::size_t>(c.dst.pin)];
      if (p.cls != TypeClass::Exact && !in_class(ts, p.cls))
        d_.error(c.loc, c.dst.text + " takes " + std::string(class_name(p.cls)) + ", not " + std::string(type_name(ts)));
    }
  }
  // Required inputs.
  for (const auto& in : insts_)
    for (std::size_t i = 0; i < in.type->pins.size(); ++i) {
      const auto& p = in.type->pins[i];
      if (p.dir != PinDir::In || !p.required || in.source[i] != -1 || in.inputs[i]) continue;
      const auto& es = in.element_source[i];
      if (es.empty()) {
        d_.error(in.loc, "input " + in.name + "." + p.name + " must be connected or given a value in inputs:");
      } else if (auto open = std::find(es.begin(), es.end(), -1); open != es.end()) {
        d_.error(in.loc, "input " + in.name + "." + p.name + "[" + std::to_string(open - es.begin() + 1) +
                             "] must be connected: connect every element of a required array input, or the whole array");
      }
    }
}

void Loader::find_owners() {
  auto note_writer = [&](int ti, int task, const std::string& who, const SourceLoc& loc) {
    auto& td = tags_[static_cast<std::size_t>(ti)];
    if (td.writer_task >= 0) {
      d_.error(loc, "tag " + td.tag.name + " has two writers: " + td.writer + " and " + who);
      return;
    }
    td.writer_task = task;
    td.writer = who;
  };
  std::map<std::pair<int, std::uint32_t>, bool> seen_element;
  for (const auto& c : conns_) {
    if (!c.dst.is_pin) {
      auto& td = tags_[static_cast<std::size_t>(c.dst.tag)];
      // Different elements of one array tag may come from different blocks of one task.
      if (c.dst.element) {
        auto key = std::make_pair(c.dst.tag, *c.dst.element);
        if (seen_element[key]) { d_.error(c.loc, "tag element " + c.dst.text + " has two writers"); continue; }
        seen_element[key] = true;
        int task = insts_[static_cast<std::size_t>(c.src.instance)].task;
        if (td.writer_task >= 0 && td.writer_task != task)
          d_.error(c.loc, "tag " + td.tag.name + " is written from two tasks (" + td.writer + " and block " + c.src.text + ")");
        else if (td.writer_task < 0) { td.writer_task = task; td.writer = "block " + c.src.text; }
        continue;
      }
      note_writer(c.dst.tag, insts_[static_cast<std::size_t>(c.src.instance)].task, "block " + c.src.text, c.loc);
    } else if (!c.src.is_pin) {
      tags_[static_cast<std::size_t>(c.src.tag)].reader_tasks.push_back(insts_[static_cast<std::size_t>(c.dst.instance)].task);
    }
  }
  for (const auto& dd : drvs_) {
    const auto& chans = dd.driver->channels();
    for (std::size_t i = 0; i < chans.size(); ++i) {
      int ti = dd.channel_tag[i];
      if (ti < 0) continue;
      if (chans[i].dir == PinDir::In) note_writer(ti, dd.task, "driver " + dd.name + "." + chans[i].name, dd.channel_loc[i]);
      else tags_[static_cast<std::size_t>(ti)].reader_tasks.push_back(dd.task);
    }
  }
  for (auto& td : tags_) {
    int explicit_task = td.task.empty() ? -1 : task_index(td.task);
    if (td.writer_task >= 0) {
      if (explicit_task >= 0 && explicit_task != td.writer_task)
        d_.error(td.task_loc, "tag " + td.tag.name + " is written by " + td.writer + " in task " +
                                  tasks_[static_cast<std::size_t>(td.writer_task)].cfg.name + ", not in task " + td.task);
      td.tag.owner = static_cast<std::uint16_t>(td.writer_task);
    } else if (explicit_task >= 0) {
      td.tag.owner = static_cast<std::uint16_t>(explicit_task);
    } else if (!td.reader_tasks.empty()) {
      td.tag.owner = static_cast<std::uint16_t>(td.reader_tasks.front());
    } else {
      td.tag.owner = 0;
    }
    td.tag.writer = td.writer;
  }
}

class LoaderBlockSetup final : public BlockSetup {
 public:
  LoaderBlockSetup(const InstanceDecl& in, std::vector<Cell> params, std::vector<bool> connected, std::int64_t period,
                   std::uint64_t seed, Diagnostics& d)
      : in_(in), params_(std::move(params)), connected_(std::move(connected)), period_(period), seed_(seed), d_(d) {}
  const std::string& instance_name() const override { return in_.name; }
  const BlockTypeInfo& type() const override { return *in_.type; }
  IecType datatype() const override { return in_.datatype.value_or(IecType::LREAL); }
  Cell param_cell(int index) const override {
    if (index < 0 || static_cast<std::size_t>(index) >= params_.size())
      throw std::out_of_range(in_.type->name + ": no such parameter");
    return params_[static_cast<std::size_t>(index)];
  }
  bool connected(int pin) const override { return connected_.at(static_cast<std::size_t>(pin)); }
  std::uint32_t pin_length(int pin) const override { return in_.pin_length.at(static_cast<std::size_t>(pin)); }
  std::int64_t task_period_ns() const override { return period_; }
  std::uint64_t seed() const override { return seed_; }
  void error(const std::string& message) override { d_.error(in_.loc, in_.name + " (" + in_.type->name + "): " + message); }

 private:
  const InstanceDecl& in_;
  std::vector<Cell> params_;
  std::vector<bool> connected_;
  std::int64_t period_;
  std::uint64_t seed_;
  Diagnostics& d_;
};

bool Loader::pin_connected(const InstanceDecl& in, std::size_t p) const {
  const auto& es = in.element_source[p];
  return in.source[p] >= 0 || in.source[p] == kBrokenSource || in.inputs[p] ||
         std::any_of(es.begin(), es.end(), [](int c) { return c >= 0; });
}

void Loader::check_values() {
  for (auto& in : insts_) {
    in.pin_values.assign(in.type->pins.size(), {});
    for (std::size_t p = 0; p < in.type->pins.size(); ++p) {
      const auto& decl = in.type->pins[p];
      IecType pt = decl.cls == TypeClass::Exact ? decl.type : in.datatype.value_or(IecType::LREAL);
      const std::string what = in.name + "." + decl.name;
      if (const ConfigNode* v = in.inputs[p]) {
        if (v->is_scalar()) {
          // One value: the scalar pin's value, or every element of an array pin.
          if (auto c = parse_literal(pt, decl.unit, v->scalar, v->loc, what)) in.pin_values[p].push_back(*c);
          else in.values_ok = false;
        } else if (v->is_list() && decl.is_array()) {
          if (!in.params_ok) continue;  // its length is unknown
          const std::uint32_t len = in.pin_length[p];
          if (v->items.size() != len) {
            d_.error(v->loc, what + ": " + std::to_string(v->items.size()) + " values for ARRAY[1.." + std::to_string(len) +
                                 "] (give one value for every element, or a single value for all)");
            in.values_ok = false;
            continue;
          }
          for (std::size_t k = 0; k < v->items.size(); ++k) {
            const auto& item = v->items[k];
            std::optional<Cell> c;
            if (!item.is_scalar()) d_.error(item.loc, what + "[" + std::to_string(k + 1) + "]: expected a value");
            else c = parse_literal(pt, decl.unit, item.scalar, item.loc, what + "[" + std::to_string(k + 1) + "]");
            if (c) in.pin_values[p].push_back(*c);
            else in.values_ok = false;
          }
        } else {
          d_.error(v->loc, what + (decl.is_array() ? ": expected a value or a list of values" : ": expected a value"));
          in.values_ok = false;
        }
      } else if (!decl.init.empty()) {
        std::string err;
        if (auto c = parse_value(pt, decl.init, &err)) in.pin_values[p].push_back(*c);
      }
    }
  }
}

void Loader::check_params() {
  for (auto& in : insts_) {
    for (std::size_t p = 0; p < in.type->params.size(); ++p) {
      const auto& decl = in.type->params[p];
      std::string text = decl.default_value;
      SourceLoc loc = in.loc;
      if (in.params[p]) { text = in.params[p]->scalar; loc = in.params[p]->loc; }
      if (!in.param_override[p].empty()) { text = in.param_override[p]; loc = SourceLoc{"command line", 0, 0}; }
      if (text.empty()) {  // a mandatory parameter left out: reported by read_blocks
        in.values_ok = in.params_ok = false;
        in.param_cells.emplace_back();
        continue;
      }
      auto v = parse_literal(decl.type, decl.unit, text, loc, in.name + "." + decl.name);
      if (v && (decl.min || decl.max)) {
        double x = cell_as_double(decl.type, *v);
        if ((decl.min && x < *decl.min) || (decl.max && x > *decl.max)) {
          auto fmt = [](double d) { char b[32]; std::snprintf(b, sizeof b, "%g", d); return std::string(b); };
          d_.error(loc, in.name + "." + decl.name + " = " + text + " is outside its range " +
                            (decl.min ? fmt(*decl.min) : "-inf") + " .. " + (decl.max ? fmt(*decl.max) : "inf") +
                            (decl.unit.empty() ? "" : " " + decl.unit));
          v.reset();
        }
      }
      if (!v) { in.values_ok = false; in.params_ok = false; }
      in.param_cells.push_back(v.value_or(Cell{}));
    }
    if (!in.params_ok) continue;
    for (std::size_t p = 0; p < in.type->pins.size(); ++p) {
      const auto& decl = in.type->pins[p];
      if (!decl.is_array()) continue;
      auto k = static_cast<std::size_t>(in.type->param_index(decl.length_param));
      double len = cell_as_double(in.type->params[k].type, in.param_cells[k]);
      if (len < 1 || len > kMaxPinLength) {
        SourceLoc loc = in.params[k] ? in.params[k]->loc : in.loc;
        if (!in.param_override[k].empty()) loc = SourceLoc{"command line", 0, 0};
        d_.error(loc, in.name + "." + decl.length_param + " = " + format_value(in.type->params[k].type, in.param_cells[k]) +
                          ": array pin " + decl.name + " needs 1.." + std::to_string(kMaxPinLength) + " elements");
        in.params_ok = in.values_ok = false;
        break;
      }
      in.pin_length[p] = static_cast<std::uint32_t>(len);
    }
  }
}

void Loader::order_blocks() {
  const std::size_t nt = tasks_.size();
  order_.assign(nt, {});
  delays_.assign(nt, 0);
  // Edge a -> b when b reads, in the same scan, a value a writes: directly
  // (a.out -> b.in) or through a tag of the same task (a.out -> tag -> b.in).
  std::vector<std::vector<std::pair<int, SourceLoc>>> succ(insts_.size());
  // Several writers for element-wise writes; a reader of one element depends
  // only on the writer of that element (or of the whole tag).
  std::vector<std::vector<std::pair<int, std::optional<std::uint32_t>>>> tag_writers(tags_.size());
  for (const auto& c : conns_)
    if (c.src.is_pin && !c.dst.is_pin)
      tag_writers[static_cast<std::size_t>(c.dst.tag)].emplace_back(c.src.instance, c.dst.element);
  for (const auto& c : conns_) {
    if (!c.dst.is_pin) continue;
    if (insts_[static_cast<std::size_t>(c.dst.instance)].type->unit_delay) continue;  // reads at the end of the scan
    std::vector<int> from;
    if (c.src.is_pin) from.push_back(c.src.instance);
    else
      for (const auto& [w, element] : tag_writers[static_cast<std::size_t>(c.src.tag)])
        if (insts_[static_cast<std::size_t>(w)].task == insts_[static_cast<std::size_t>(c.dst.instance)].task &&
            !(element && c.src.element && *element != *c.src.element))
          from.push_back(w);
    for (int f : from) {
      if (insts_[static_cast<std::size_t>(f)].type->unit_delay) continue;  // its output is ready at the start
      succ[static_cast<std::size_t>(f)].emplace_back(c.dst.instance, c.loc);
    }
  }
  {
    std::vector<int> indeg(insts_.size(), 0);
    for (const auto& s : succ)
      for (const auto& [to, _] : s) ++indeg[static_cast<std::size_t>(to)];
    for (std::size_t t = 0; t < nt; ++t) {
      std::priority_queue<int, std::vector<int>, std::greater<int>> ready;  // declaration order breaks ties
      std::size_t members = 0;
      for (std::size_t i = 0; i < insts_.size(); ++i)
        if (static_cast<std::size_t>(insts_[i].task) == t) {
          if (insts_[i].type->unit_delay) { order_[t].push_back(static_cast<int>(i)); continue; }
          ++members;
          if (indeg[i] == 0) ready.push(static_cast<int>(i));
        }
      std::size_t delays = order_[t].size();
      while (!ready.empty()) {
        int i = ready.top();
        ready.pop();
        order_[t].push_back(i);
        for (const auto& [to, _] : succ[static_cast<std::size_t>(i)])
          if (--indeg[static_cast<std::size_t>(to)] == 0) ready.push(to);
      }
      if (order_[t].size() - delays < members) {
        // Report one loop, found by walking edges among the unsorted blocks.
        std::vector<int> colour(insts_.size(), 0), stack;
        std::vector<SourceLoc> via;
        std::function<bool(int)> dfs = [&](int u) -> bool {
          colour[static_cast<std::size_t>(u)] = 1;
          stack.push_back(u);
          for (const auto& [v, loc] : succ[static_cast<std::size_t>(u)]) {
            if (indeg[static_cast<std::size_t>(v)] == 0) continue;
            via.push_back(loc);
            if (colour[static_cast<std::size_t>(v)] == 1) {
              auto it = std::find(stack.begin(), stack.end(), v);
              std::string path;
              for (auto p = it; p != stack.end(); ++p) path += insts_[static_cast<std::size_t>(*p)].name + " -> ";
              path += insts_[static_cast<std::size_t>(v)].name;
              d_.error(loc, "feedback loop without a one-scan delay: " + path + " (break it with a UNIT_DELAY block)");
              return true;
            }
            if (colour[static_cast<std::size_t>(v)] == 0 && dfs(v)) return true;
            via.pop_back();
          }
          stack.pop_back();
          colour[static_cast<std::size_t>(u)] = 2;
          return false;
        };
        for (std::size_t i = 0; i < insts_.size(); ++i)
          if (static_cast<std::size_t>(insts_[i].task) == t && indeg[i] > 0 && colour[i] == 0 && dfs(static_cast<int>(i)))
            break;
      }
      delays_[t] = delays;
    }
  }

}

void Loader::create_blocks() {
  for (auto& in : insts_) {
    if (!in.values_ok || (in.type->is_generic() && !in.datatype)) continue;  // already reported
    std::vector<bool> connected;
    for (std::size_t p = 0; p < in.type->pins.size(); ++p) connected.push_back(pin_connected(in, p));
    LoaderBlockSetup setup(in, in.param_cells, connected, tasks_[static_cast<std::size_t>(in.task)].cfg.period_ns,
                           mix_seed(seed_, in.name), d_);
    std::size_t before = d_.size();
    try {
      in.block = in.type->create(setup);
    } catch (const std::exception& e) {
      d_.error(in.loc, in.name + " (" + in.type->name + "): " + e.what());
    }
    if (!in.block && d_.size() == before) d_.error(in.loc, in.name + " (" + in.type->name + ") could not be created");
  }
}

void Loader::check_refs() {
  for (const auto& [ref, loc] : traces_) {
    Endpoint e;
    std::size_t before = d_.size();
    if (!parse_endpoint(ref, loc, e)) {
      for (std::size_t k = before; k < d_.size(); ++k) d_.prefix_message(k, "trace: ");
      continue;
    }
    bool array = e.is_pin ? insts_[static_cast<std::size_t>(e.instance)].type->pins[static_cast<std::size_t>(e.pin)].is_array()
                          : tags_[static_cast<std::size_t>(e.tag)].tag.is_array;
    if (array && !e.element) d_.error(loc, "trace: " + ref + " is an array; trace its elements (" + ref + "[i])");
  }
  for (const auto& [ref, loc] : watch_)
    if (tag_index(ref) < 0 && !failed_names_.count(ref)) d_.error(loc, "watch: unknown tag '" + ref + "'");
  for (const auto& [ref, loc] : axis_errors_) {
    Endpoint e;
    std::size_t before = d_.size();
    if (!parse_endpoint(ref, loc, e))
      for (std::size_t k = before; k < d_.size(); ++k) d_.prefix_message(k, "metrics: ");
  }
}

std::unique_ptr<Program> Loader::build() {
  auto prog = std::make_unique<Program>();
  prog->name = name_;
  prog->version = version_;
  prog->file = file_;
  prog->seed = seed_;
  const std::size_t nt = tasks_.size();
  for (std::size_t i = 0; i < nt; ++i) prog->tasks.push_back(std::make_unique<Task>(static_cast<std::uint16_t>(i), tasks_[i].cfg));

  // --- image layout: owned tags, foreign copies, pins -------------------------
  std::vector<std::uint32_t> next(nt, 0);
  for (auto& td : tags_) {
    td.tag.cell = next[td.tag.owner];
    next[td.tag.owner] += td.tag.length;
  }
  for (std::size_t t = 0; t < nt; ++t) prog->tasks[t]->owned_cells = next[t];
  std::vector<std::map<int, std::uint32_t>> foreign(nt);  // task -> tag -> local cell
  auto local_cell = [&](int tag, std::size_t task) -> std::uint32_t {
    const auto& tg = tags_[static_cast<std::size_t>(tag)].tag;
    if (tg.owner == task) return tg.cell;
    auto& f = foreign[task];
    auto it = f.find(tag);
    if (it != f.end()) return it->second;
    std::uint32_t c = next[task];
    next[task] += tg.length;
    f[tag] = c;
    return c;
  };
  // Foreign copies are assigned in a fixed order: connections, then drivers.
  for (const auto& c : conns_)
    if (!c.src.is_pin) local_cell(c.src.tag, static_cast<std::size_t>(insts_[static_cast<std::size_t>(c.dst.instance)].task));
  for (const auto& dd : drvs_)
    for (std::size_t i = 0; i < dd.channel_tag.size(); ++i)
      if (dd.channel_tag[i] >= 0) local_cell(dd.channel_tag[i], static_cast<std::size_t>(dd.task));
  std::vector<std::vector<std::uint32_t>> pin_cells(insts_.size());
  for (std::size_t i = 0; i < insts_.size(); ++i) {
    auto t = static_cast<std::size_t>(insts_[i].task);
    for (std::size_t p = 0; p < insts_[i].type->pins.size(); ++p) {
      pin_cells[i].push_back(next[t]);
      next[t] += insts_[i].pin_length[p];
    }
  }
  for (std::size_t t = 0; t < nt; ++t) prog->tasks[t]->image.assign(next[t], Cell{});

  // --- initial values ----------------------------------------------------------
  for (const auto& td : tags_) {
    auto& img = prog->tasks[td.tag.owner]->image;
    std::copy(td.tag.init.begin(), td.tag.init.end(), img.begin() + td.tag.cell);
  }
  for (std::size_t t = 0; t < nt; ++t)
    for (const auto& [tag, cell] : foreign[t]) {
      const auto& init = tags_[static_cast<std::size_t>(tag)].tag.init;
      std::copy(init.begin(), init.end(), prog->tasks[t]->image.begin() + cell);
    }
  for (std::size_t i = 0; i < insts_.size(); ++i) {
    auto& img = prog->tasks[static_cast<std::size_t>(insts_[i].task)]->image;
    for (std::size_t p = 0; p < insts_[i].pin_values.size(); ++p) {
      const auto& v = insts_[i].pin_values[p];
      for (std::uint32_t k = 0; !v.empty() && k < insts_[i].pin_length[p]; ++k)
        img[pin_cells[i][p] + k] = v.size() == 1 ? v[0] : v[k];
    }
  }

  for (std::size_t t = 0; t < nt; ++t) prog->tasks[t]->unit_delays = delays_[t];
  const auto& order = order_;

  // --- blocks, in execution order -------------------------------------------------
  std::vector<std::uint32_t> position(insts_.size(), 0);
  for (std::size_t t = 0; t < nt; ++t) {
    auto& task = *prog->tasks[t];
    task.blocks.reserve(order[t].size());
    for (std::size_t k = 0; k < order[t].size(); ++k) {
      auto i = static_cast<std::size_t>(order[t][k]);
      auto& in = insts_[i];
      position[i] = static_cast<std::uint32_t>(k);
      BlockInstance bi;
      bi.name = in.name;
      bi.type = in.type;
      bi.datatype = in.datatype.value_or(IecType::LREAL);
      bi.params = in.param_cells;
      bi.pin_cell = pin_cells[i];
      bi.pin_length = in.pin_length;
      bi.block = std::move(in.block);
      task.blocks.push_back(std::move(bi));
      prog->instances[in.name] = {static_cast<std::uint16_t>(t), static_cast<std::uint32_t>(k)};
    }
  }

  // --- connections as copies -----------------------------------------------------
  // A connection copies its length: 1 for scalars and elements, n for whole arrays.
  auto pin_at = [&](const Endpoint& e) {
    return pin_cells[static_cast<std::size_t>(e.instance)][static_cast<std::size_t>(e.pin)] + e.element.value_or(0);
  };
  for (const auto& c : conns_) {
    std::uint32_t n = 1;
    endpoint_type(c.dst, &n);
    if (c.dst.is_pin) {
      const auto& di = insts_[static_cast<std::size_t>(c.dst.instance)];
      auto t = static_cast<std::size_t>(di.task);
      std::uint32_t src = c.src.is_pin ? pin_at(c.src) : local_cell(c.src.tag, t) + c.src.element.value_or(0);
      auto& bi = prog->tasks[t]->blocks[position[static_cast<std::size_t>(c.dst.instance)]];
      bi.copy_in.push_back({src, pin_at(c.dst), n});
    } else {
      const auto& si = insts_[static_cast<std::size_t>(c.src.instance)];
      auto t = static_cast<std::size_t>(si.task);
      const auto& tg = tags_[static_cast<std::size_t>(c.dst.tag)].tag;
      auto& bi = prog->tasks[t]->blocks[position[static_cast<std::size_t>(c.src.instance)]];
      bi.copy_out.push_back({pin_at(c.src), tg.cell + c.dst.element.value_or(0), n});
    }
  }

  // --- snapshot channels: [0] external, then one per consuming task -------------
  for (std::size_t t = 0; t < nt; ++t) prog->tasks[t]->channels.push_back(std::make_unique<TripleBuffer>());
  for (std::size_t t = 0; t < nt; ++t) {
    std::map<std::uint16_t, Inbound> by_producer;
    for (const auto& [tag, cell] : foreign[t]) {
      const auto& tg = tags_[static_cast<std::size_t>(tag)].tag;
      auto& ib = by_producer[tg.owner];
      ib.producer = tg.owner;
      ib.copies.push_back({tg.cell, cell, tg.length});
    }
    for (auto& [producer, ib] : by_producer) {
      auto& ptask = *prog->tasks[producer];
      ptask.channels.push_back(std::make_unique<TripleBuffer>());
      ib.channel = ptask.channels.back().get();
      prog->tasks[t]->inbound.push_back(std::move(ib));
    }
  }

  // --- drivers and safe values -----------------------------------------------------
  for (auto& dd : drvs_) {
    auto t = static_cast<std::size_t>(dd.task);
    auto& task = *prog->tasks[t];
    std::vector<Cell*> cells(dd.channel_tag.size(), nullptr);
    DriverBinding b;
    b.type = dd.type;
    b.task = static_cast<std::uint16_t>(t);
    for (std::size_t i = 0; i < dd.channel_tag.size(); ++i) {
      int ti = dd.channel_tag[i];
      b.bound_tags.push_back(ti < 0 ? "" : tags_[static_cast<std::size_t>(ti)].tag.name);
      if (ti < 0) continue;
      std::uint32_t c = local_cell(ti, t);
      cells[i] = &task.image[c];
      const auto& tg = tags_[static_cast<std::size_t>(ti)].tag;
      if (dd.driver->channels()[i].dir == PinDir::Out && tg.owner != t && !tg.safe.empty())
        for (std::uint32_t k = 0; k < tg.length; ++k) task.safe_values.emplace_back(c + k, tg.safe[k]);
    }
    dd.driver->bind(cells);
    task.drivers.push_back(dd.driver.get());
    b.driver = std::move(dd.driver);
    prog->drivers.push_back(std::move(b));
  }
  for (const auto& td : tags_)
    if (!td.tag.safe.empty())
      for (std::uint32_t k = 0; k < td.tag.length; ++k)
        prog->tasks[td.tag.owner]->safe_values.emplace_back(td.tag.cell + k, td.tag.safe[k]);

  for (auto& td : tags_) prog->tags.push_back(td.tag);
  for (auto& t : prog->tasks) t->finalize();

  for (const auto& [ref, loc] : traces_) {
    std::string err;
    auto r = prog->resolve(ref, &err);
    if (!r) d_.error(loc, "trace: " + err);
    else if (r->length != 1) d_.error(loc, "trace: " + ref + " is an array; trace its elements (" + ref + "[i])");
    else prog->traces.push_back({ref, *r});
  }
  for (const auto& [ref, loc] : watch_) {
    if (!prog->find_tag(ref)) d_.error(loc, "watch: unknown tag '" + ref + "'");
    else prog->watch.push_back(ref);
  }
  for (const auto& [ref, loc] : axis_errors_) {
    std::string err;
    auto r = prog->resolve(ref, &err);
    if (!r) continue;  // reported by check_refs
    if (r->type != IecType::LREAL && r->type != IecType::REAL) {
      d_.error(loc, "metrics: " + ref + " is " + std::string(type_name(r->type)) + "; axis errors are REAL or LREAL");
      continue;
    }
    const Tag* t = prog->find_tag(ref);
    for (std::uint32_t k = 0; k < r->length; ++k) {
      CellRef one = *r;
      one.cell += k;
      one.length = 1;
      std::string label = r->length == 1 ? ref : ref + "[" + std::to_string((t ? t->array_lower : 1) + k) + "]";
      prog->axis_errors.push_back({label, one});
    }
  }
  prog->metrics_from_ns = metrics_from_ns_;
  prog->modbus = modbus_;
  if (!d_.empty()) return nullptr;
  return prog;
}

}  // namespace

bool parse_override(const std::string& text, ParamOverride& out) {
  auto eq = text.find('=');
  if (eq == std::string::npos || eq == 0) return false;
  std::string lhs = text.substr(0, eq);
  out.value = text.substr(eq + 1);
  auto dot = lhs.find('.');
  if (dot == std::string::npos) {
    out.instance = lhs;  // a tag's initial value
    out.param.clear();
  } else {
    out.instance = lhs.substr(0, dot);
    out.param = lhs.substr(dot + 1);
    if (out.param.empty()) return false;
  }
  return !out.value.empty();
}

LoadResult load_project_text(const std::string& text, const std::string& name, const LoadOptions& options) {
  Loader l(options);
  Diagnostics d;
  ConfigNode root = read_yaml_string(text, name, d);
  if (!d.empty()) {
    LoadResult r;
    r.diagnostics = d;
    return r;
  }
  return l.run(std::move(root), name);
}

LoadResult load_project(const std::string& path, const LoadOptions& options) {
  Loader l(options);
  Diagnostics d;
  ConfigNode root = read_yaml_file(path, d);
  if (!d.empty()) {
    LoadResult r;
    r.diagnostics = d;
    return r;
  }
  return l.run(std::move(root), path);
}

}  // namespace syncplc
