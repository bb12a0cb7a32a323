// Reading the project's sections into declarations: project, tasks, tags,
// connections (as written; resolved by check_connections.cpp), traces,
// watch and metrics. Blocks and drivers have files of their own.
#include "runtime/core/tag_limits.hpp"
#include "runtime/core/units.hpp"
#include "runtime/project/modbus_settings.hpp"
#include "runtime/project/store_section.hpp"
#include "runtime/project/stages.hpp"

namespace syncplc {
namespace {

constexpr std::int64_t kMinPeriod = 100'000;         // 100 us
constexpr std::int64_t kMaxPeriod = 10'000'000'000;  // 10 s
// The runtime multiplies it by the sensitivity (at most 1000): 1 h keeps that far from overflowing.
constexpr std::int64_t kMaxWatchdog = 3'600'000'000'000;

}  // namespace

void read_project(const ConfigNode& n, Declarations& p, Diagnostics& diags) {
  if (!n.is_map()) { diags.error(n.loc, "project: expected a map {name, version, seed}"); return; }
  for (const auto& [k, v] : n.map) {
    if (k == "name") p.name = v.scalar;
    else if (k == "version") p.version = v.scalar;
    else if (k == "description") {}
    else if (k == "seed") {
      std::string err;
      auto c = parse_value(IecType::ULINT, v.scalar, &err);
      if (!c) diags.error(v.loc, "seed: " + err);
      else p.seed = c->get<std::uint64_t>();
    } else if (k == "max_forces") {
      std::string err;
      auto c = parse_value(IecType::UDINT, v.scalar, &err);
      if (!c || c->get<std::uint32_t>() < 1 || c->get<std::uint32_t>() > kMaxMaxForces)
        diags.error(v.loc, "max_forces: 1.." + std::to_string(kMaxMaxForces) + " forced elements at once");
      else p.max_forces = c->get<std::uint32_t>();
    } else if (k == "st_engine") {
      if (v.scalar == "native") p.st_native = true;
      else if (v.scalar == "interpreter") p.st_native = false;
      else diags.error(v.loc, "st_engine: native or interpreter, not '" + v.scalar + "'");
    } else diags.error(v.loc, "unknown key '" + k + "' in project (name, version, description, seed, max_forces, st_engine)");
  }
  if (p.name.empty()) diags.error(n.loc, "project name is empty");
}

void read_tasks(const ConfigNode& n, Declarations& p, Diagnostics& diags) {
  if (!n.is_list()) { diags.error(n.loc, "tasks: expected a list"); return; }
  for (const auto& t : n.items) {
    if (!t.is_map()) { diags.error(t.loc, "a task is a map {name, period, priority, ...}"); continue; }
    TaskDecl td;
    td.loc = t.loc;
    bool has_period = false, period_ok = false;
    for (const auto& [k, v] : t.map) {
      std::string err;
      if (k == "name") {
        td.cfg.name = v.scalar;
        if (!is_identifier(v.scalar)) diags.error(v.loc, "task name '" + v.scalar + "' is not an identifier");
        else if (p.task_index(v.scalar) >= 0) diags.error(v.loc, "duplicate task '" + v.scalar + "'");
      } else if (k == "period") {
        has_period = true;
        auto ns = parse_duration_ns(v.scalar, &err);
        if (!ns) diags.error(v.loc, "period: " + err);
        else if (*ns < kMinPeriod || *ns > kMaxPeriod)
          diags.error(v.loc, "period " + v.scalar + " is outside 100us .. 10s");
        else { td.cfg.period_ns = *ns; period_ok = true; }
      } else if (k == "phase") {
        auto ns = parse_duration_ns(v.scalar, &err);
        if (!ns) diags.error(v.loc, "phase: " + err);
        else if (*ns < 0) diags.error(v.loc, "phase must not be negative");
        else td.cfg.phase_ns = *ns;
      } else if (k == "priority") {
        auto c = parse_value(IecType::DINT, v.scalar, &err);
        if (!c) diags.error(v.loc, "priority: " + err);
        else if (c->get<std::int32_t>() < 1 || c->get<std::int32_t>() > 99)
          diags.error(v.loc, "priority " + v.scalar + " is outside 1..99 (SCHED_FIFO; higher runs first)");
        else td.cfg.priority = c->get<std::int32_t>();
      } else if (k == "cpu") {
        auto c = parse_value(IecType::DINT, v.scalar, &err);
        if (!c || c->get<std::int32_t>() < 0 || c->get<std::int32_t>() > 1023) diags.error(v.loc, "cpu: a CPU number 0..1023");
        else td.cfg.cpu = c->get<std::int32_t>();
      } else if (k == "missed_cycles") {
        if (v.scalar == "skip") td.cfg.missed = MissedCycles::Skip;
        else if (v.scalar == "immediate") td.cfg.missed = MissedCycles::Immediate;
        else diags.error(v.loc, "missed_cycles must be 'skip' or 'immediate', not '" + v.scalar + "'");
      } else if (k == "write_queue") {
        auto c = parse_value(IecType::UDINT, v.scalar, &err);
        if (!c || c->get<std::uint32_t>() < 16 || c->get<std::uint32_t>() > 1'000'000) diags.error(v.loc, "write_queue: 16..1000000 entries");
        else {
          td.cfg.write_queue = c->get<std::uint32_t>();
          td.write_queue_loc = v.loc;
        }
      } else if (k == "watchdog") {
        if (!v.is_map()) { diags.error(v.loc, "watchdog: expected a map {time, sensitivity, action}"); continue; }
        td.cfg.watchdog = true;
        bool has_time = false;
        for (const auto& [wk, wv] : v.map) {
          if (wk == "time") {
            has_time = true;
            auto ns = parse_duration_ns(wv.scalar, &err);
            if (!ns) diags.error(wv.loc, "watchdog time: " + err);
            else if (*ns <= 0) diags.error(wv.loc, "watchdog time must be positive");
            else if (*ns > kMaxWatchdog) diags.error(wv.loc, "watchdog time " + wv.scalar + " is longer than 1h");
            else td.cfg.watchdog_ns = *ns;
          } else if (wk == "sensitivity") {
            auto c = parse_value(IecType::DINT, wv.scalar, &err);
            if (!c || c->get<std::int32_t>() < 1 || c->get<std::int32_t>() > 1000)
              diags.error(wv.loc, "sensitivity must be an integer 1..1000");
            else td.cfg.sensitivity = c->get<std::int32_t>();
          } else if (wk == "action") {
            if (wv.scalar == "log") td.cfg.action = WatchdogAction::Log;
            else if (wv.scalar == "stop") td.cfg.action = WatchdogAction::Stop;
            else if (wv.scalar == "safe_stop") td.cfg.action = WatchdogAction::SafeStop;
            else diags.error(wv.loc, "watchdog action must be log, stop or safe_stop, not '" + wv.scalar + "'");
          } else diags.error(wv.loc, "unknown key '" + wk + "' in watchdog (time, sensitivity, action)");
        }
        if (!has_time) diags.error(v.loc, "watchdog needs a time");
      } else diags.error(v.loc, "unknown key '" + k + "' in a task (name, period, phase, priority, watchdog, missed_cycles, cpu, write_queue)");
    }
    if (td.cfg.name.empty()) diags.error(t.loc, "task without a name");
    if (!has_period) diags.error(t.loc, "task " + td.cfg.name + " has no period");
    if (td.cfg.phase_ns >= td.cfg.period_ns && period_ok)
      diags.error(t.find("phase") ? t.find("phase")->loc : t.loc, "phase must be shorter than the period");
    if (p.tasks.size() >= kMaxTasks) { diags.error(t.loc, "more than " + std::to_string(kMaxTasks) + " tasks"); continue; }
    if (!td.cfg.name.empty()) p.task_by_name.emplace(td.cfg.name, static_cast<int>(p.tasks.size()));
    p.tasks.push_back(std::move(td));
  }
}

// min: and max: of a numeric tag, values of its type in its unit
// (tag_limits.hpp); min not above max.
static void read_tag_limits(Tag& tag, const ConfigNode* min, const ConfigNode* max, Diagnostics& diags) {
  if (tag.type == IecType::BOOL || tag.type == IecType::TIME || is_bit_string(tag.type)) {
    diags.error((min ? min : max)->loc, "min and max are for numeric tags; " + tag.name + " is " +
                                           std::string(type_name(tag.type)));
    return;
  }
  auto limit = [&](const ConfigNode* n, const char* key) -> std::optional<double> {
    if (!n) return std::nullopt;
    std::string err;
    auto c = n->is_scalar() ? parse_value_in_unit(tag.type, tag.unit, n->scalar, &err) : std::nullopt;
    if (!c) {
      diags.error(n->loc, std::string(key) + ": " + (n->is_scalar() ? err : "expected one value of the tag's type"));
      return std::nullopt;
    }
    return cell_as_double(tag.type, *c);
  };
  tag.min = limit(min, "min");
  tag.max = limit(max, "max");
  if (tag.min && tag.max && *tag.min > *tag.max) {
    diags.error(min->loc, "min " + min->scalar + " is above max " + max->scalar + " of " + tag.name);
    tag.min.reset();
    tag.max.reset();
  }
}

static void check_within_limits(const Tag& tag, const std::vector<Cell>& values, const ConfigNode& n, const char* what,
                         Diagnostics& diags) {
  for (const Cell& v : values)
    if (std::string why = outside_limits(tag, v); !why.empty()) {
      diags.error(n.loc, std::string(what) + ": " + why);
      return;
    }
}

void read_tags(const ConfigNode& n, Declarations& p, Diagnostics& diags) {
  if (!n.is_list()) { diags.error(n.loc, "tags: expected a list"); return; }
  p.tags.reserve(p.tags.size() + n.items.size());
  for (const auto& t : n.items) {
    if (!t.is_map()) { diags.error(t.loc, "a tag is a map {name, type, ...}"); continue; }
    TagDecl td;
    td.tag.loc = t.loc;
    bool ok = true, has_type = false;
    const ConfigNode *addr = nullptr, *modbus = nullptr, *init = nullptr, *safe = nullptr, *trend = nullptr;
    const ConfigNode *min = nullptr, *max = nullptr;
    for (const auto& [k, v] : t.map) {
      if (k == "name") {
        td.tag.name = v.scalar;
        if (!is_identifier(v.scalar)) { diags.error(v.loc, "tag name '" + v.scalar + "' is not an identifier"); ok = false; }
        else if (p.names.count(v.scalar)) { diags.error(v.loc, "duplicate name '" + v.scalar + "' (first defined at " + p.names[v.scalar].text() + ")"); ok = false; }
        else p.names[v.scalar] = v.loc;
      } else if (k == "type") {
        has_type = true;
        std::string err;
        std::int64_t lower;
        if (!parse_tag_type(v.scalar, td.tag.type, td.tag.length, lower, td.tag.is_array, err)) { diags.error(v.loc, err); ok = false; }
        td.tag.array_lower = lower;
      } else if (k == "address") addr = &v;
      else if (k == "retain") {
        std::string err;
        auto c = parse_value(IecType::BOOL, v.scalar, &err);
        if (!c) diags.error(v.loc, "retain: " + err); else td.tag.retain = c->get<bool>();
      } else if (k == "persistent") {
        std::string err;
        auto c = parse_value(IecType::BOOL, v.scalar, &err);
        if (!c) diags.error(v.loc, "persistent: " + err); else td.tag.persistent = c->get<bool>();
      } else if (k == "trend") {
        trend = &v;
      } else if (k == "hmi") {
        td.hmi_loc = v.loc;
        if (v.scalar == "none") td.tag.hmi = HmiAccess::None;
        else if (v.scalar == "read") td.tag.hmi = HmiAccess::Read;
        else if (v.scalar == "readwrite") td.tag.hmi = HmiAccess::ReadWrite;
        else diags.error(v.loc, "hmi must be none, read or readwrite, not '" + v.scalar + "'");
      } else if (k == "unit") {
        std::string err;
        if (!parse_unit(v.scalar, &err)) diags.error(v.loc, err);
        td.tag.unit = v.scalar;
      } else if (k == "description") td.tag.description = v.scalar;
      else if (k == "init") init = &v;
      else if (k == "safe") safe = &v;
      else if (k == "min") min = &v;
      else if (k == "max") max = &v;
      else if (k == "task") { td.task = v.scalar; td.task_loc = v.loc; }
      else if (k == "modbus") modbus = &v;
      else diags.error(v.loc, "unknown key '" + k + "' in a tag (name, type, address, modbus, retain, persistent, trend, hmi, unit, description, init, safe, min, max, task)");
    }
    if (td.tag.name.empty()) { diags.error(t.loc, "tag without a name"); ok = false; }
    if (!has_type) { diags.error(t.loc, "tag " + td.tag.name + " has no type"); ok = false; }
    if (!ok && !td.tag.name.empty()) p.failed_names.insert(td.tag.name);
    if (ok && addr) {
      std::string err;
      auto a = parse_direct_address(addr->scalar, &err);
      if (!a) diags.error(addr->loc, err);
      else if (auto why = check_address_type(*a, td.tag.type); !why.empty()) diags.error(addr->loc, why);
      else {
        td.tag.address = *a;
        td.address_loc = addr->loc;  // overlaps: check_addresses
      }
    }
    if (ok && modbus) {
      // After the loop: the place is checked against the tag's type, length and hmi.
      td.modbus_loc = modbus->loc;
      td.modbus = read_modbus_place(*modbus, td.tag, diags);
      td.modbus_failed = !td.modbus;
    }
    if (td.tag.persistent) td.tag.retain = true;  // PERSISTENT implies RETAIN (CODESYS's VAR PERSISTENT RETAIN)
    if (ok && trend) td.trend = read_trend(*trend, td.tag, diags);
    if (!td.task.empty() && p.task_index(td.task) < 0) diags.error(td.task_loc, "unknown task '" + td.task + "'");
    if (ok && (min || max)) read_tag_limits(td.tag, min, max, diags);
    if (ok) {
      td.tag.init.assign(td.tag.length, Cell{});
      if (init) { auto v = parse_tag_values(td.tag, *init, "init", diags); if (!v.empty()) td.tag.init = v; }
      if (safe) td.tag.safe = parse_tag_values(td.tag, *safe, "safe value", diags);
      // Its own values within its limits: a limit that refused the tag's init would refuse every setpoint near it.
      if (init) check_within_limits(td.tag, td.tag.init, *init, "init", diags);
      if (safe) check_within_limits(td.tag, td.tag.safe, *safe, "safe value", diags);
      p.tag_by_name.emplace(td.tag.name, static_cast<int>(p.tags.size()));
      p.tags.push_back(std::move(td));
    }
  }
}

void read_connections(const ConfigNode& n, Declarations& p, Diagnostics& diags) {
  if (!n.is_list()) { diags.error(n.loc, "connections: expected a list of 'source.pin -> target.pin'"); return; }
  p.connections.reserve(p.connections.size() + n.items.size());
  for (const auto& c : n.items) {
    std::string src, dst;
    SourceLoc sl = c.loc, dl = c.loc;
    if (c.is_scalar()) {
      auto arrow = c.scalar.find("->");
      if (arrow == std::string::npos) { diags.error(c.loc, "a connection is written 'source.pin -> target.pin'"); continue; }
      src = c.scalar.substr(0, arrow);
      dst = c.scalar.substr(arrow + 2);
      std::size_t lead = dst.find_first_not_of(' ');
      dl.col += static_cast<int>(arrow + 2 + (lead == std::string::npos ? 0 : lead));
    } else if (c.is_map() && c.find("from") && c.find("to")) {
      src = c.find("from")->scalar;
      dst = c.find("to")->scalar;
      sl = c.find("from")->loc;
      dl = c.find("to")->loc;
    } else { diags.error(c.loc, "a connection is written 'source.pin -> target.pin' or {from: , to: }"); continue; }
    p.connections.push_back({src, dst, sl, dl, c.loc});
  }
}

void read_refs(const ConfigNode& root, const char* key, RefList& out, Diagnostics& diags) {
  const ConfigNode* n = root.find(key);
  if (!n) return;
  if (!n->is_list()) { diags.error(n->loc, std::string(key) + ": expected a list"); return; }
  for (const auto& i : n->items) {
    if (!i.is_scalar()) diags.error(i.loc, std::string(key) + ": expected instance.pin or a tag name");
    else out.emplace_back(i.scalar, i.loc);
  }
}

void read_metrics(const ConfigNode& n, Declarations& p, Diagnostics& diags) {
  if (!n.is_map()) { diags.error(n.loc, "metrics: expected a map {axis_errors, from}"); return; }
  for (const auto& [k, v] : n.map) {
    if (k == "axis_errors") {
      if (v.is_scalar()) p.axis_errors.emplace_back(v.scalar, v.loc);
      else if (v.is_list())
        for (const auto& i : v.items) {
          if (i.is_scalar()) p.axis_errors.emplace_back(i.scalar, i.loc);
          else diags.error(i.loc, "metrics axis_errors: expected a tag, tag[i] or instance.pin");
        }
      else diags.error(v.loc, "metrics axis_errors: an array tag or a list of tags, in axis order");
    } else if (k == "from") {
      std::string err;
      auto ns = v.is_scalar() ? parse_duration_ns(v.scalar, &err) : std::nullopt;
      if (!ns || *ns < 0) diags.error(v.loc, "metrics from: " + (err.empty() ? "'" + v.scalar + "' must not be negative" : err));
      else p.metrics_from_ns = *ns;
    } else if (k == "contour") {
      read_contour_metric(v, p.metrics_contour, diags);
    } else {
      diags.error(v.loc, "unknown key '" + k + "' in metrics (axis_errors, from, contour)");
    }
  }
  if (p.axis_errors.empty()) diags.error(n.loc, "metrics: axis_errors is missing");
}

}  // namespace syncplc
