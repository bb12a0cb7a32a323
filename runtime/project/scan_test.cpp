#include "runtime/project/scan_test.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <set>

#include "runtime/core/units.hpp"
#include "runtime/core/system_clock.hpp"
#include "runtime/core/virtual_clock.hpp"
#include "runtime/project/system.hpp"
#include "runtime/project/system_run.hpp"
#include "runtime/project/metrics.hpp"
#include "runtime/project/yaml_tree.hpp"

namespace syncplc {
namespace {

struct Target {
  enum Kind { Image, DriverIn, DriverOut, Metric } kind = Image;
  std::size_t node = 0;  // in the system (0: a project tested on its own)
  enum class MetricKind { TrackRsme, SyncRsme, MaxAbsError, MaxAbsSyncError } metric = MetricKind::TrackRsme;
  std::size_t axis = 0;  // 0-based, for the per-axis metrics
  CellRef ref;
  int driver = -1;
  int channel = -1;
  IecType type = IecType::LREAL;
  std::uint32_t length = 1;
  std::string unit;
  std::string text;
  std::string local;  // text without its node
};

struct Assignment {
  Target target;
  std::vector<Cell> values;
  std::optional<double> tolerance;  // expect only; in the value's unit (TIME: seconds)
  std::optional<double> max, min;   // expect only: a bound instead of a value
  SourceLoc loc;
};

struct Action {
  std::int64_t time = 0;
  bool expect = false;
  std::size_t order = 0;
  std::string when;  // "at 500ms" / "cycle 12 of fast"
  std::vector<Assignment> items;
};

struct Case {
  std::string name;
  std::optional<std::uint64_t> seed;
  std::vector<Action> actions;
  SourceLoc loc;
};

// metrics.track_rsme, metrics.sync_rsme, metrics.max_abs_error[i],
// metrics.max_abs_sync_error[i]: the motion metrics (paper 000 eqs. 26-27)
// over the project's metrics axis_errors, from the start of the case.
std::optional<Target> resolve_metric(std::size_t axes, const std::string& text, std::string* err) {
  Target t;
  t.text = text;
  t.kind = Target::Metric;
  t.type = IecType::LREAL;
  if (axes == 0) {
    *err = text + ": the project names no metrics axis_errors";
    return std::nullopt;
  }
  std::string name = text.substr(8), index;
  if (auto lb = name.find('['); lb != std::string::npos && name.back() == ']') {
    index = name.substr(lb + 1, name.size() - lb - 2);
    name = name.substr(0, lb);
  }
  const bool per_axis = name == "max_abs_error" || name == "max_abs_sync_error";
  if (name == "track_rsme") t.metric = Target::MetricKind::TrackRsme;
  else if (name == "sync_rsme") t.metric = Target::MetricKind::SyncRsme;
  else if (name == "max_abs_error") t.metric = Target::MetricKind::MaxAbsError;
  else if (name == "max_abs_sync_error") t.metric = Target::MetricKind::MaxAbsSyncError;
  else {
    *err = "unknown metric '" + name + "' (track_rsme, sync_rsme, max_abs_error[i], max_abs_sync_error[i])";
    return std::nullopt;
  }
  if (per_axis != !index.empty()) {
    *err = per_axis ? "metrics." + name + " needs an axis: metrics." + name + "[1]" : "metrics." + name + " takes no index";
    return std::nullopt;
  }
  if (per_axis) {
    char* end = nullptr;
    long a = std::strtol(index.c_str(), &end, 10);
    if (*end || a < 1 || static_cast<std::size_t>(a) > axes) {
      *err = "axis " + index + " is outside 1.." + std::to_string(axes);
      return std::nullopt;
    }
    t.axis = static_cast<std::size_t>(a - 1);
  }
  return t;
}

std::optional<Target> resolve_target(const Program& p, std::size_t axes, const std::string& text, std::string* err) {
  if (text.rfind("metrics.", 0) == 0) return resolve_metric(axes, text, err);
  Target t;
  t.text = text;
  std::string base = text.substr(0, text.find('['));
  if (auto dot = base.find('.'); dot != std::string::npos) {
    std::string owner = base.substr(0, dot), member = base.substr(dot + 1);
    if (p.instances.count(owner)) {
      auto r = p.resolve(text, err);
      if (!r) return std::nullopt;
      t.ref = *r;
      t.type = r->type;
      t.length = r->length;
      auto [task, pos] = p.instances.at(owner);
      const auto& bi = p.tasks[task]->blocks[pos];
      // A pin's unit; an instance's variable (instance.path of an ST POU) has none.
      if (const int pin = bi.type->pin_index(member); pin >= 0) t.unit = bi.type->pins[static_cast<std::size_t>(pin)].unit;
      return t;
    }
    int d = p.find_driver(owner);
    if (d < 0) {
      *err = "no block instance or driver '" + owner + "'";
      return std::nullopt;
    }
    const auto& chans = p.drivers[static_cast<std::size_t>(d)].driver->channels();
    for (std::size_t i = 0; i < chans.size(); ++i)
      if (chans[i].name == member) {
        t.kind = chans[i].dir == PinDir::In ? Target::DriverIn : Target::DriverOut;
        t.driver = d;
        t.channel = static_cast<int>(i);
        t.type = chans[i].type;
        t.length = chans[i].length;
        t.unit = chans[i].unit;
        return t;
      }
    *err = "driver " + owner + " has no channel '" + member + "'";
    return std::nullopt;
  }
  auto r = p.resolve(text, err);
  if (!r) return std::nullopt;
  t.ref = *r;
  t.type = r->type;
  t.length = r->length;
  t.unit = p.find_tag(base)->unit;
  return t;
}

std::optional<Cell> parse_cell(IecType t, const std::string& unit, const std::string& text, std::string* err) {
  return parse_value_in_unit(t, unit, text, err);
}

// A system's targets start with the node: axis1.ref_ok, master.metrics.track_rsme.
std::optional<Target> resolve_in_system(const LoadedSystem& sys, bool named, const std::string& text, std::string* err) {
  std::size_t node = 0;
  std::string rest = text;
  if (named) {
    const auto dot = text.find('.');
    const int n = dot == std::string::npos ? -1 : sys.find(text.substr(0, dot));
    if (n < 0) {
      std::string names;
      for (const auto& x : sys.nodes) names += (names.empty() ? "" : ", ") + x.name;
      *err = text + ": a system's target starts with its node (" + names + "), e.g. " + sys.nodes[0].name + ".tag";
      return std::nullopt;
    }
    node = static_cast<std::size_t>(n);
    rest = text.substr(dot + 1);
  }
  const LoadResult& r = sys.nodes[node].loaded;
  auto t = resolve_target(*r.program, r.metrics.axis_errors.size(), rest, err);
  if (t) {
    t->node = node;
    t->local = rest;
    t->text = text;
  }
  return t;
}

class TestsReader {
 public:
  TestsReader(const LoadedSystem& sys, Diagnostics& d)
      : sys_(sys), named_(!sys.nodes[0].name.empty()), p_(*sys.nodes[0].loaded.program), d_(d) {}

  std::vector<Case> read(const ConfigNode& root) {
    std::vector<Case> cases;
    if (!root.is_map()) {
      d_.error(root.loc, "a tests file is a map with a list 'cases'");
      return cases;
    }
    for (const auto& [k, v] : root.map)
      if (k != "cases" && k != "description") d_.error(v.loc, "unknown key '" + k + "' (cases, description)");
    const ConfigNode* list = root.find("cases");
    if (!list || !list->is_list() || list->items.empty()) {
      d_.error(list ? list->loc : root.loc, "'cases' must be a non-empty list");
      return cases;
    }
    std::set<std::string> names;
    for (const auto& c : list->items) {
      Case k = read_case(c);
      if (!names.insert(k.name).second) d_.error(c.loc, "duplicate case name '" + k.name + "'");
      cases.push_back(std::move(k));
    }
    return cases;
  }

 private:
  Case read_case(const ConfigNode& n) {
    Case c;
    c.loc = n.loc;
    if (!n.is_map()) {
      d_.error(n.loc, "a case is a map {name, steps}");
      return c;
    }
    for (const auto& [k, v] : n.map) {
      if (k == "name") c.name = v.scalar;
      else if (k == "seed") {
        std::string err;
        auto s = parse_value(IecType::ULINT, v.scalar, &err);
        if (!s) d_.error(v.loc, "seed: " + err);
        else c.seed = s->get<std::uint64_t>();
      } else if (k == "steps") {
        if (!v.is_list()) d_.error(v.loc, "steps: expected a list");
        else for (const auto& s : v.items) read_step(s, c);
      } else if (k != "description") d_.error(v.loc, "unknown key '" + k + "' in a case (name, seed, steps, description)");
    }
    if (c.name.empty()) d_.error(n.loc, "case without a name");
    if (c.actions.empty()) d_.error(n.loc, "case '" + c.name + "' has no steps");
    return c;
  }

  // `cycle: n` (of `task`, default the first; of a system: node.task, default
  // the first node's first): the planned release of its n-th scan.
  void read_cycle(const ConfigNode& cycle, const ConfigNode* task, std::int64_t& time, std::string& when) {
    std::string err;
    auto n = parse_value(IecType::ULINT, cycle.scalar, &err);
    if (!n) { d_.error(cycle.loc, "cycle: " + err); return; }
    int ti = 0;
    const Program* p = &p_;
    if (task) {
      std::string name = task->scalar;
      if (named_) {
        const auto dot = name.find('.');
        const int node = dot == std::string::npos ? -1 : sys_.find(name.substr(0, dot));
        if (node < 0) { d_.error(task->loc, "task: a system's task is node.task, e.g. " + sys_.nodes[0].name + ".main"); return; }
        p = sys_.nodes[static_cast<std::size_t>(node)].loaded.program.get();
        name = name.substr(dot + 1);
      }
      ti = p->find_task(name);
      if (ti < 0) { d_.error(task->loc, "unknown task '" + task->scalar + "'"); return; }
    }
    const auto& cfg = p->tasks[static_cast<std::size_t>(ti)]->config();
    // The release time phase + n * period must fit 64 bits of nanoseconds.
    std::int64_t offset = 0;
    if (n->get<std::uint64_t>() > static_cast<std::uint64_t>(INT64_MAX) ||
        __builtin_mul_overflow(static_cast<std::int64_t>(n->get<std::uint64_t>()), cfg.period_ns, &offset) ||
        __builtin_add_overflow(offset, cfg.phase_ns, &time)) {
      d_.error(cycle.loc, "cycle " + cycle.scalar + " of task " + cfg.name + " is later than TIME can count");
      return;
    }
    when = "cycle " + std::to_string(n->get<std::uint64_t>()) + " of " + cfg.name;
  }

  void read_step(const ConfigNode& s, Case& c) {
    if (!s.is_map()) {
      d_.error(s.loc, "a step is a map {at or cycle, set, expect}");
      return;
    }
    const ConfigNode *at = s.find("at"), *cycle = s.find("cycle"), *task = s.find("task");
    for (const auto& [k, v] : s.map)
      if (k != "at" && k != "cycle" && k != "task" && k != "set" && k != "expect")
        d_.error(v.loc, "unknown key '" + k + "' in a step (at, cycle, task, set, expect)");
    std::int64_t time = 0;
    std::string when;
    // An error in the step's time does not stop it: its set and expect are
    // read all the same, so that their errors are reported in the same run.
    if (at && cycle) d_.error(s.loc, "a step has either 'at' or 'cycle'");
    else if (at) {
      std::string err;
      auto t = parse_duration_ns(at->scalar, &err);
      if (!t || *t < 0) d_.error(at->loc, "at: " + (t ? std::string("must not be negative") : err));
      else time = *t;
      when = "at " + format_duration(time);
    } else if (cycle) {
      read_cycle(*cycle, task, time, when);
    } else {
      d_.error(s.loc, "a step needs 'at: <time>' or 'cycle: <n>'");
    }
    if (task && !cycle) d_.error(task->loc, "'task' goes with 'cycle'");
    for (const char* key : {"set", "expect"}) {
      const ConfigNode* m = s.find(key);
      if (!m) continue;
      Action a;
      a.time = time;
      a.expect = std::string(key) == "expect";
      a.order = order_++;
      a.when = when;
      if (!m->is_map()) { d_.error(m->loc, std::string(key) + ": expected a map of target: value"); continue; }
      for (const auto& [target, value] : m->map) read_assignment(target, value, a);
      c.actions.push_back(std::move(a));
    }
    if (!s.find("set") && !s.find("expect")) d_.error(s.loc, "a step needs 'set' or 'expect'");
  }

  void read_assignment(const std::string& target, const ConfigNode& v, Action& a) {
    std::string err;
    auto t = resolve_in_system(sys_, named_, target, &err);
    if (!t) { d_.error(v.loc, err); return; }
    const Program& p_ = *sys_.nodes[t->node].loaded.program;
    const std::string local = named_ ? target.substr(target.find('.') + 1) : target;
    if (!a.expect && t->kind == Target::DriverOut) { d_.error(v.loc, target + " is a driver output: it can only be expected"); return; }
    if (a.expect && t->kind == Target::DriverIn) { d_.error(v.loc, target + " is a driver input: set it, expect the tag it feeds"); return; }
    if (!a.expect && t->kind == Target::Metric) { d_.error(v.loc, target + " is a metric: it can only be expected"); return; }
    if (!a.expect && t->kind == Target::Image) {
      const Tag* tag = p_.find_tag(local.substr(0, local.find('[')));
      if (tag && tag->written_every_scan) {
        // The writer runs in every scan after the set: the value would never be seen.
        const bool driver = tag->writer.rfind("driver ", 0) == 0;
        const std::string what = driver ? tag->writer.substr(7) : tag->writer.substr(6);
        d_.error(v.loc, target + " is written every scan by " + tag->writer + ", which wins: this set would be "
                        "overwritten before anything reads it; " +
                        (driver ? "set the driver's channel " + what + " instead"
                                : "set what block " + what.substr(0, what.find('.')) + " reads instead"));
        return;
      }
    }
    Assignment as;
    as.target = *t;
    as.loc = v.loc;
    const ConfigNode* val = &v;
    if (v.is_map()) {
      if (!a.expect) { d_.error(v.loc, "set takes a value, not a map"); return; }
      val = v.find("value");
      const ConfigNode* tol = v.find("tolerance");
      for (const auto& [k, x] : v.map)
        if (k != "value" && k != "tolerance" && k != "max" && k != "min")
          d_.error(x.loc, "unknown key '" + k + "' (value, tolerance, or max and/or min)");
      for (const char* bound : {"max", "min"})
        if (const ConfigNode* b = v.find(bound)) {
          if (val) { d_.error(b->loc, std::string(bound) + " and value exclude each other"); return; }
          if (t->length != 1 || (!is_real(t->type) && !is_integer(t->type))) {
            d_.error(b->loc, std::string(bound) + " needs a single number: " + target);
            return;
          }
          auto q = parse_quantity(b->scalar, t->unit, &err);
          if (!q) { d_.error(b->loc, std::string(bound) + ": " + err); return; }
          (std::string(bound) == "max" ? as.max : as.min) = *q;
        }
      if (as.max || as.min) {
        a.items.push_back(std::move(as));
        return;
      }
      if (!val) { d_.error(v.loc, "expected value missing"); return; }
      if (tol) {
        if (t->type == IecType::TIME) {
          auto ns = parse_duration_ns(tol->scalar, &err);
          if (!ns) { d_.error(tol->loc, "tolerance: " + err); return; }
          as.tolerance = static_cast<double>(*ns) * 1e-9;
        } else {
          auto q = parse_quantity(tol->scalar, t->unit, &err);
          if (!q) { d_.error(tol->loc, "tolerance: " + err); return; }
          as.tolerance = std::fabs(*q);
        }
      }
    }
    std::vector<const ConfigNode*> items;
    if (val->is_list()) for (const auto& i : val->items) items.push_back(&i);
    else items.push_back(val);
    if (items.size() != t->length && !(items.size() == 1 && t->length > 1)) {
      d_.error(val->loc, fmt::format("{}: {} values for {} elements", target, items.size(), t->length));
      return;
    }
    for (const ConfigNode* i : items) {
      if (!i->is_scalar()) { d_.error(i->loc, "expected a value"); return; }
      auto c = parse_cell(t->type, t->unit, i->scalar, &err);
      if (!c) { d_.error(i->loc, target + ": " + err); return; }
      as.values.push_back(*c);
    }
    if (as.values.size() == 1 && t->length > 1) as.values.assign(t->length, as.values[0]);
    a.items.push_back(std::move(as));
  }

  const LoadedSystem& sys_;
  bool named_;         // a system file: targets start with their node
  const Program& p_;   // the first node's
  Diagnostics& d_;
  std::size_t order_ = 0;
};

bool values_equal(IecType t, Cell a, Cell b, std::optional<double> tol) {
  if (tol) return std::fabs(cell_as_double(t, a) - cell_as_double(t, b)) <= *tol;
  if (is_real(t)) return cell_as_double(t, a) == cell_as_double(t, b);
  return dispatch_type(t, [&]<IecType T>() {
    using N = typename Native<T>::type;
    return a.get<N>() == b.get<N>();
  });
}

// A test's set goes the way an HMI or Modbus write goes: into the owning
// task's write queue, applied at the start of its next scan (the scan
// released at the step's time), so the tests exercise that path.
bool queue_write(const Program& p, const Target& t, const std::vector<Cell>& values) {
  const auto count = static_cast<std::uint32_t>(values.size());
  if (const Tag* tag = p.find_tag(t.local.substr(0, t.local.find('[')));
      tag && t.local.find('.') == std::string::npos)
    return p.write_tag(*tag, t.ref.cell - tag->cell, values.data(), count);
  // An instance's input pin: its task's queue all the same.
  std::vector<QueuedWrite> w(values.size());
  for (std::size_t i = 0; i < values.size(); ++i) w[i] = QueuedWrite{t.ref.cell + static_cast<std::uint32_t>(i), values[i]};
  return p.tasks[t.ref.task]->enqueue(w.data(), w.size());
}

ScanTestCaseResult run_case(const std::string& project, const LoadOptions& base, const Case& c) {
  ScanTestCaseResult r;
  r.name = c.name;
  LoadOptions o = base;
  if (c.seed) o.seed = c.seed;
  LoadedSystem sys = load_system_or_project(project, o);
  if (!sys.ok()) {
    for (const auto& d : sys.diagnostics.sorted()) r.failures.push_back(d.text());
    return r;
  }
  std::string err;
  if (!open_system(sys, &err)) {
    r.failures.push_back(err);
    return r;
  }
  std::vector<const Action*> actions;
  for (const auto& a : c.actions) actions.push_back(&a);
  std::stable_sort(actions.begin(), actions.end(), [](const Action* x, const Action* y) {
    if (x->time != y->time) return x->time < y->time;
    if (x->expect != y->expect) return !x->expect;  // sets before expects at one instant
    return x->order < y->order;
  });
  SystemRun run(sys);
  SystemClock& clock = run.clock();
  auto metric_value = [&](const Target& t) {
    const MotionMetrics& metrics = run.metrics(t.node);
    switch (t.metric) {
      case Target::MetricKind::TrackRsme: return metrics.track_rsme();
      case Target::MetricKind::SyncRsme: return metrics.sync_rsme();
      case Target::MetricKind::MaxAbsError: return metrics.max_abs_error(t.axis);
      case Target::MetricKind::MaxAbsSyncError: return metrics.max_abs_sync_error(t.axis);
    }
    return 0.0;
  };
  for (const Action* a : actions) {
    clock.run_until(a->time, a->expect);
    for (const auto& as : a->items) {
      const Target& t = as.target;
      Program& p = *sys.nodes[t.node].loaded.program;
      const VirtualClock& nc = run.node_clock(t.node);
      if (as.max || as.min || t.kind == Target::Metric) {
        ++r.steps_checked;
        double x = 0;
        if (t.kind == Target::Metric) x = metric_value(t);
        else if (t.kind == Target::DriverOut) {
          Cell c;
          p.drivers[static_cast<std::size_t>(t.driver)].driver->read_output(t.channel, &c);
          x = cell_as_double(t.type, c);
        } else x = cell_as_double(t.type, *nc.live_cell(t.ref));
        if (as.max || as.min) {
          if ((as.max && !(x <= *as.max)) || (as.min && !(x >= *as.min)))
            r.failures.push_back(fmt::format("{}: case '{}' {}: {} is {}, expected{}{}", as.loc.text(), c.name, a->when,
                                             t.text, x, as.min ? fmt::format(" >= {}", *as.min) : "",
                                             as.max ? fmt::format(" <= {}", *as.max) : ""));
        } else {
          double want = as.values[0].get<double>();
          if (!(std::fabs(x - want) <= as.tolerance.value_or(0)))
            r.failures.push_back(fmt::format("{}: case '{}' {}: {} is {}, expected {}{}", as.loc.text(), c.name, a->when,
                                             t.text, x, want, as.tolerance ? fmt::format(" ± {}", *as.tolerance) : ""));
        }
        continue;
      }
      if (!a->expect) {
        if (t.kind == Target::DriverIn) {
          p.drivers[static_cast<std::size_t>(t.driver)].driver->force_input(t.channel, as.values.data());
        } else if (!queue_write(p, t, as.values)) {
          r.failures.push_back(fmt::format("{}: case '{}' {}: set {}: the write queue of task {} is full", as.loc.text(),
                                           c.name, a->when, t.text, p.tasks[t.ref.task]->config().name));
        }
        continue;
      }
      std::vector<Cell> actual(t.length);
      if (t.kind == Target::DriverOut) p.drivers[static_cast<std::size_t>(t.driver)].driver->read_output(t.channel, actual.data());
      else std::copy(nc.live_cell(t.ref), nc.live_cell(t.ref) + t.length, actual.begin());
      ++r.steps_checked;
      for (std::uint32_t i = 0; i < t.length; ++i) {
        if (values_equal(t.type, actual[i], as.values[i], as.tolerance)) continue;
        std::string name = t.length > 1 ? fmt::format("{}[{}]", t.text, i) : t.text;
        std::string tol = as.tolerance ? fmt::format(" ± {}", *as.tolerance) : "";
        r.failures.push_back(fmt::format("{}: case '{}' {}: {} is {}, expected {}{}", as.loc.text(), c.name, a->when, name,
                                         format_value(t.type, actual[i]), format_value(t.type, as.values[i]), tol));
      }
    }
  }
  r.virtual_seconds = static_cast<double>(clock.now()) * 1e-9;
  close_system(sys);
  r.passed = r.failures.empty();
  return r;
}

std::string xml_escape(const std::string& s) {
  std::string o;
  for (char ch : s) {
    switch (ch) {
      case '&': o += "&amp;"; break;
      case '<': o += "&lt;"; break;
      case '>': o += "&gt;"; break;
      case '"': o += "&quot;"; break;
      default: o += ch;
    }
  }
  return o;
}

}  // namespace

bool ScanTestReport::ok() const { return diagnostics.empty() && failed() == 0 && !cases.empty(); }

std::size_t ScanTestReport::failed() const {
  return static_cast<std::size_t>(std::count_if(cases.begin(), cases.end(), [](const auto& c) { return !c.passed; }));
}

ScanTestReport run_scan_tests(const std::string& project_path, const std::string& tests_path, const LoadOptions& options) {
  ScanTestReport rep;
  LoadedSystem loaded = load_system_or_project(project_path, options);
  if (!loaded.ok()) {
    rep.diagnostics = loaded.diagnostics;
    return rep;
  }
  ConfigNode root = read_yaml_file(tests_path, rep.diagnostics);
  if (!rep.diagnostics.empty()) return rep;
  TestsReader reader(loaded, rep.diagnostics);
  auto cases = reader.read(root);
  if (!rep.diagnostics.empty()) return rep;
  for (const auto& c : cases) rep.cases.push_back(run_case(project_path, options, c));
  return rep;
}

void write_junit(std::ostream& os, const std::string& suite, const ScanTestReport& r) {
  double total = 0;
  for (const auto& c : r.cases) total += c.virtual_seconds;
  os << "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n";
  os << fmt::format("<testsuites tests=\"{}\" failures=\"{}\">\n", r.cases.size(), r.failed());
  os << fmt::format("  <testsuite name=\"{}\" tests=\"{}\" failures=\"{}\" errors=\"0\" time=\"{:.6f}\">\n",
                    xml_escape(suite), r.cases.size(), r.failed(), total);
  for (const auto& c : r.cases) {
    os << fmt::format("    <testcase classname=\"{}\" name=\"{}\" time=\"{:.6f}\"", xml_escape(suite), xml_escape(c.name),
                      c.virtual_seconds);
    if (c.passed) {
      os << "/>\n";
      continue;
    }
    os << ">\n";
    std::string all;
    for (const auto& f : c.failures) all += f + "\n";
    os << fmt::format("      <failure message=\"{}\">{}</failure>\n", xml_escape(c.failures.front()), xml_escape(all));
    os << "    </testcase>\n";
  }
  os << "  </testsuite>\n</testsuites>\n";
}

}  // namespace syncplc
