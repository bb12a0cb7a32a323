#include "runtime/web/live_values.hpp"

#include "runtime/core/monotonic_clock.hpp"
#include "runtime/web/json_values.hpp"
#include "runtime/web/program_json.hpp"

namespace syncplc::web {

std::int64_t logical_now_ns(const Program& p) {
  const std::int64_t epoch = p.epoch_ns.load(std::memory_order_acquire);
  return epoch < 0 ? -1 : monotonic_ns() - epoch;
}

nlohmann::json describe_ref(const Program& p, const HiddenCells* hidden, const std::string& ref) {
  std::string why;
  const auto src = value_source(p, ref, &why);
  if (!src) return {{"error", why.empty() ? "no tag or pin '" + ref + "'" : why}};
  if (hidden && hidden->hides(src->cell)) return {{"error", hidden_reason(ref)}};
  nlohmann::json j{{"task", src->task->config().name},
                   {"period_ns", src->task->config().period_ns},
                   {"type", type_name(src->cell.type)},
                   {"length", src->cell.length}};
  if (src->driver) j["driver"] = src->driver->name();
  return j;
}

void LiveRefs::set_refs(std::vector<std::string> refs) {
  refs_ = std::move(refs);
  resolved_ = false;
}

void LiveRefs::resolve(const Program& p, const HiddenCells* hidden) {
  entries_.assign(refs_.size(), Entry{});
  for (std::size_t i = 0; i < refs_.size(); ++i) {
    Entry& e = entries_[i];
    e.source = value_source(p, refs_[i], &e.error);
    if (!e.source) {
      if (e.error.empty()) e.error = "no tag or pin '" + refs_[i] + "'";
    } else if (hidden && hidden->hides(e.source->cell)) {
      e.source.reset();
      e.error = hidden_reason(refs_[i]);
    }
  }
}

nlohmann::json LiveRefs::tick(Program& p, std::uint64_t generation, const HiddenCells* hidden) {
  if (!resolved_ || generation != generation_) {
    // New refs, or an online change: a renamed tag is answered for itself.
    resolve(p, hidden);
    generation_ = generation;
    resolved_ = true;
  }
  // Read before the values: a value is never older than its age says.
  const std::int64_t now = logical_now_ns(p);
  const bool scheduled = p.epoch_ns.load(std::memory_order_acquire) >= 0;
  const ForcedCells forced = forced_cells(p);
  nlohmann::json values = nlohmann::json::object(), flags = nlohmann::json::object(),
                 quality = nlohmann::json::object(), errors = nlohmann::json::object();
  std::vector<Cell> cells;
  for (std::size_t i = 0; i < refs_.size(); ++i) {
    const Entry& e = entries_[i];
    const std::string& ref = refs_[i];
    if (!e.source) {
      errors[ref] = e.error;
      continue;
    }
    const CellRef& r = e.source->cell;
    cells.resize(r.length);
    const auto stamp = p.read_value(r, cells.data());
    if (!stamp) continue;  // a pin whose monitoring is starting
    QualityInputs in;
    in.task_stopped = !scheduled || e.source->task->stopped();
    in.stamp = *stamp;
    in.now_ns = now;
    in.period_ns = e.source->task->config().period_ns;
    in.driver_ok = !e.source->driver || e.source->driver->input_ok(e.source->channel);
    for (std::uint32_t k = 0; k < r.length && !in.forced; ++k) in.forced = forced.count({r.task, r.cell + k}) > 0;
    const ValueQuality q = judge_value(in);
    values[ref] = cells_json(r.type, cells.data(), r.length, r.length > 1);
    flags[ref] = in.forced;
    quality[ref] = {{"q", quality_name(q.quality)}, {"scan_ns", stamp->release_ns}, {"age_ns", q.age_ns}};
  }
  nlohmann::json out{{"now_ns", now}, {"values", values}, {"forced", flags}, {"quality", quality}};
  if (!errors.empty()) out["errors"] = errors;
  return out;
}

}  // namespace syncplc::web
