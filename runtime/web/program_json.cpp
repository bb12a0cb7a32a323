#include "runtime/web/program_json.hpp"

#include <array>
#include <vector>

#include "runtime/web/json_values.hpp"

namespace syncplc::web {

ForcedCells forced_cells(const Program& p) {
  ForcedCells out;
  if (p.force_count() == 0) return out;
  for (const auto& f : p.forces()) out.emplace(f.cell.task, f.cell.cell);
  return out;
}

nlohmann::json histogram_json(const Histogram& h) {
  // 1 us … 1 s in 1-2-5 steps: what a scan's time and a start's lateness span.
  static constexpr std::array<std::int64_t, 19> kBounds = {
      1'000,      2'000,      5'000,      10'000,      20'000,      50'000,      100'000,
      200'000,    500'000,    1'000'000,  2'000'000,   5'000'000,   10'000'000,  20'000'000,
      50'000'000, 100'000'000, 200'000'000, 500'000'000, 1'000'000'000};
  std::array<std::uint64_t, kBounds.size() + 1> counts{};
  for (int i = 0; i < Histogram::kBuckets; ++i) {
    const std::uint64_t n = h.bucket(i);
    if (n == 0) continue;
    const auto upper = static_cast<std::int64_t>(Histogram::upper(i));
    std::size_t k = 0;
    while (k < kBounds.size() && upper > kBounds[k]) ++k;
    counts[k] += n;
  }
  return {{"bounds_ns", kBounds}, {"counts", counts}};
}

nlohmann::json full_histogram_json(const Histogram& h) {
  nlohmann::json upper = nlohmann::json::array(), counts = nlohmann::json::array();
  for (int i = 0; i < Histogram::kBuckets; ++i) {
    const std::uint64_t n = h.bucket(i);
    if (n == 0) continue;
    upper.push_back(Histogram::upper(i));
    counts.push_back(n);
  }
  return {{"upper_ns", upper}, {"counts", counts}};
}

nlohmann::json statistics_json(const Histogram& h, bool full) {
  const auto s = h.summary();
  nlohmann::json j{{"count", s.count}, {"min_ns", s.min}, {"max_ns", s.max}, {"mean_ns", s.mean},
                   {"p50_ns", s.p50},  {"p99_ns", s.p99}, {"histogram", histogram_json(h)}};
  if (full) j["full"] = full_histogram_json(h);
  return j;
}

nlohmann::json task_json(const Task& t, const nlohmann::json& state, bool full_histograms) {
  const TaskConfig& c = t.config();
  const TaskStats& st = t.stats;
  nlohmann::json j{{"name", c.name},
                   {"period_ns", c.period_ns},
                   {"priority", c.priority},
                   {"cpu", c.cpu >= 0 ? nlohmann::json(c.cpu) : nlohmann::json()},
                   {"state", t.stopped() ? "stopped" : "running"},
                   {"stop_reason", nullptr},
                   {"scans", st.scans.load(std::memory_order_relaxed)},
                   {"overruns", st.overruns.load(std::memory_order_relaxed)},
                   {"skipped", st.skipped.load(std::memory_order_relaxed)},
                   {"watchdog_trips", st.watchdog_trips.load(std::memory_order_relaxed)},
                   {"writes_applied", st.writes_applied.load(std::memory_order_relaxed)},
                   {"exec", statistics_json(st.exec, full_histograms)},
                   {"jitter", statistics_json(st.jitter, full_histograms)}};
  j["exec"]["last_ns"] = st.last_exec_ns.load(std::memory_order_relaxed);
  if (state.is_object()) {
    if (state.contains("state")) j["state"] = state["state"];
    if (state.contains("stop_reason")) j["stop_reason"] = state["stop_reason"];
  }
  return j;
}

RefValue ref_value(Program& p, const CellRef& r, const ForcedCells& forced) {
  RefValue out;
  for (std::uint32_t i = 0; i < r.length && !out.forced; ++i) out.forced = forced.count({r.task, r.cell + i}) > 0;
  std::vector<Cell> cells(r.length);
  if (!p.read_value(r, cells.data())) return out;  // a pin whose monitoring starts: null this time
  out.value = cells_json(r.type, cells.data(), r.length, r.length > 1);
  return out;
}

nlohmann::json tag_json(const Program& p, const Tag& t, const ForcedCells& forced) {
  std::vector<Cell> cells(t.length);
  p.read_tag(t, cells.data());
  const bool array = t.is_array || t.length > 1;
  nlohmann::json f;
  if (array) {
    f = nlohmann::json::array();
    for (std::uint32_t i = 0; i < t.length; ++i) f.push_back(forced.count({t.owner, t.cell + i}) > 0);
  } else {
    f = forced.count({t.owner, t.cell}) > 0;
  }
  return {{"name", t.name},
          {"type", type_name(t.type)},
          {"is_array", array},
          {"array_lower", t.array_lower},
          {"length", t.length},
          {"unit", t.unit},
          {"task", p.tasks[t.owner]->config().name},
          {"hmi", hmi_access_name(t.hmi)},
          {"writer", t.writer.empty() ? nlohmann::json() : nlohmann::json(t.writer)},
          {"written_every_scan", t.written_every_scan},
          {"retain", t.retain},
          {"persistent", t.persistent},
          {"description", t.description},
          {"min", t.min ? nlohmann::json(*t.min) : nlohmann::json()},
          {"max", t.max ? nlohmann::json(*t.max) : nlohmann::json()},
          {"value", cells_json(t.type, cells.data(), t.length, array)},
          {"forced", f}};
}

nlohmann::json instance_json(Program& p, const InstanceInfo& b, const ForcedCells& forced) {
  nlohmann::json pins = nlohmann::json::array();
  for (const auto& pin : b.pins) {
    const RefValue v = ref_value(p, pin.cell, forced);
    pins.push_back({{"name", pin.name},
                    {"direction", pin.dir == PinDir::In ? "in" : "out"},
                    {"type", type_name(pin.type)},
                    {"unit", pin.unit},
                    {"length", pin.cell.length},
                    {"value", v.value},
                    {"forced", v.forced}});
  }
  nlohmann::json j = {{"name", b.name}, {"type", b.type}, {"task", b.task}, {"position", b.position}, {"pins", pins}};
  // An ST instance's variables (addressed instance.path).
  if (!b.variables.empty()) {
    nlohmann::json vars = nlohmann::json::array();
    for (const auto& v : b.variables) {
      const RefValue rv = ref_value(p, v.cell, forced);
      vars.push_back({{"name", v.name}, {"type", type_name(v.type)}, {"value", rv.value}, {"forced", rv.forced}});
    }
    j["variables"] = std::move(vars);
  }
  if (b.variables_left_out) j["variables_left_out"] = b.variables_left_out;
  return j;
}

}  // namespace syncplc::web
