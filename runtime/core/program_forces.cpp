// Program's force registry (program.hpp, "Forcing"): which elements are
// forced, for every reader, and the commands that make the owning tasks hold
// them (force_table.hpp). Runs on non-real-time threads only.
#include <algorithm>

#include "runtime/core/program.hpp"
#include "runtime/core/reference.hpp"
#include "runtime/core/units.hpp"

namespace syncplc {
namespace {

// Where in the scan a force on `r` must be put back, and the unit its value is written in.
struct Target {
  ForcePoint point = ForcePoint::Tag;
  std::uint32_t block = kNoBlock;
  bool restore = false;
  std::string unit;
};

Target locate(const Program& p, const Reference& ref, const CellRef& r) {
  Target t;
  const Task& task = *p.tasks[r.task];
  if (ref.dotted()) {
    const auto pos = p.instances.at(ref.owner).second;
    const auto& bi = task.blocks[pos];
    const auto& decl = bi.type->pins[static_cast<std::size_t>(bi.type->pin_index(ref.member))];
    t.unit = decl.unit;
    t.block = pos;
    if (decl.dir == PinDir::Out) {
      t.point = ForcePoint::PinOut;
    } else {
      t.point = ForcePoint::PinIn;
      // An input nothing is copied into holds its constant: unforce puts it back.
      t.restore = std::none_of(bi.copy_in.begin(), bi.copy_in.end(),
                               [&](const CellCopy& c) { return r.cell >= c.dst && r.cell - c.dst < c.n; });
    }
    return t;
  }
  const Tag* tag = p.find_tag(ref.base);
  t.unit = tag->unit;
  // The tag's writer, element by element: a block's output copy, a driver input, or nothing in the scan.
  for (std::size_t k = 0; k < task.blocks.size(); ++k)
    for (const auto& c : task.blocks[k].copy_out)
      if (r.cell >= c.dst && r.cell - c.dst < c.n) {
        t.point = ForcePoint::BlockTag;
        t.block = static_cast<std::uint32_t>(k);
        return t;
      }
  if (tag->writer.rfind("driver ", 0) == 0) t.point = ForcePoint::Driver;
  return t;
}

std::string canonical(const Reference& ref) {
  return ref.index ? ref.base + "[" + std::to_string(*ref.index) + "]" : ref.base;
}

ForceResult failed(std::string ref, std::string why) {
  ForceResult r;
  r.ref = std::move(ref);
  r.error = std::move(why);
  return r;
}

// The one element `text` names in p, with its parsed reference.
std::optional<CellRef> element(const Program& p, const std::string& text, Reference* ref, std::string* error) {
  auto parsed = parse_reference(text, error);
  if (!parsed) return std::nullopt;
  auto r = p.resolve(text, error);
  if (!r) return std::nullopt;
  if (r->length != 1) {
    *error = parsed->base + " is an array of " + std::to_string(r->length) + " elements: force one element, " +
             parsed->base + "[i]";
    return std::nullopt;
  }
  *ref = *parsed;
  return r;
}

const char* const kChangeUnderWay = "an online change is under way: force again once the new program runs";

}  // namespace

std::string ForceResult::event_text() const {
  if (!ok) return (unforce ? "unforce of " : "force of ") + ref + " refused: " + error;
  if (unforce) return "unforced " + ref + " (was forced to " + value + ")";
  return "forced " + ref + " to " + value + (previous.empty() ? "" : " (was forced to " + previous + ")");
}

ForceResult Program::add_force(std::string text, const CellRef& r, Cell value, bool queue) {
  Reference ref;
  std::string err;
  if (!element(*this, text, &ref, &err)) return failed(std::move(text), err);
  const Target t = locate(*this, ref, r);
  ForceResult res;
  res.ref = canonical(ref);
  res.task = tasks[r.task]->config().name;
  res.type = r.type;
  res.value = format_value(r.type, value);

  std::lock_guard lock(forces_mutex_);
  if (forces_closed_) return failed(res.ref, kChangeUnderWay);
  auto it = std::find_if(forces_.begin(), forces_.end(),
                         [&](const ForceEntry& e) { return e.cell.task == r.task && e.cell.cell == r.cell; });
  if (it == forces_.end() && forces_.size() >= max_forces)
    return failed(res.ref, std::to_string(forces_.size()) + " elements are forced, the project's max_forces: unforce one first");
  QueuedWrite w{r.cell, value, WriteKind::Force, t.point, t.restore, t.block};
  Task& task = *tasks[r.task];
  if (queue) {
    if (task.stopped()) return failed(res.ref, "task " + res.task + " is stopped: a force would not take effect");
    if (!task.enqueue(&w, 1)) return failed(res.ref, "the write queue of task " + res.task + " is full: try again");
  } else {
    task.apply_force_command(w);  // the task does not run yet (online change, before its threads see it)
  }
  if (it == forces_.end()) {
    forces_.push_back(ForceEntry{res.ref, r, value, res.value, res.task});
  } else {
    res.previous = it->value_text;
    it->value = value;
    it->value_text = res.value;
  }
  force_count_.store(forces_.size(), std::memory_order_relaxed);
  forces_version_.fetch_add(1, std::memory_order_acq_rel);
  res.ok = true;
  return res;
}

ForceResult Program::force(const std::string& text, const std::string& value) {
  Reference ref;
  std::string err;
  auto r = element(*this, text, &ref, &err);
  if (!r) return failed(text, err);
  const Target t = locate(*this, ref, *r);
  auto cell = parse_value_in_unit(r->type, t.unit, value, &err);
  if (!cell) return failed(canonical(ref), "value '" + value + "' for " + std::string(type_name(r->type)) + ": " + err);
  return add_force(text, *r, *cell, true);
}

ForceResult Program::unforce(const std::string& text) {
  Reference ref;
  std::string err;
  auto r = element(*this, text, &ref, &err);
  ForceResult res = failed(r ? canonical(ref) : text, err);
  res.unforce = true;
  if (!r) return res;
  res.task = tasks[r->task]->config().name;
  res.type = r->type;
  std::lock_guard lock(forces_mutex_);
  if (forces_closed_) {
    res.error = kChangeUnderWay;
    return res;
  }
  auto it = std::find_if(forces_.begin(), forces_.end(),
                         [&](const ForceEntry& e) { return e.cell.task == r->task && e.cell.cell == r->cell; });
  if (it == forces_.end()) {
    res.error = res.ref + " is not forced";
    return res;
  }
  QueuedWrite w{r->cell, Cell{}, WriteKind::Unforce};
  if (!tasks[r->task]->enqueue(&w, 1)) {
    res.error = "the write queue of task " + res.task + " is full: try again";
    return res;
  }
  res.value = it->value_text;
  forces_.erase(it);
  force_count_.store(forces_.size(), std::memory_order_relaxed);
  forces_version_.fetch_add(1, std::memory_order_acq_rel);
  res.ok = true;
  res.error.clear();
  return res;
}

std::vector<ForceResult> Program::unforce_all() {
  std::lock_guard lock(forces_mutex_);
  auto refused = [](std::string why) {
    ForceResult r = failed("*", std::move(why));
    r.unforce = true;
    return std::vector<ForceResult>{r};
  };
  if (forces_closed_) return refused(kChangeUnderWay);
  if (forces_.empty()) return {};
  // One batch per task, in ascending task order (Task::enqueue_all): all queued or none.
  std::vector<std::vector<QueuedWrite>> per_task(tasks.size());
  for (const auto& e : forces_) per_task[e.cell.task].push_back(QueuedWrite{e.cell.cell, Cell{}, WriteKind::Unforce});
  std::vector<Task::WriteBatch> batches;
  for (std::size_t t = 0; t < tasks.size(); ++t)
    if (!per_task[t].empty()) batches.push_back({tasks[t].get(), per_task[t].data(), per_task[t].size()});
  if (!Task::enqueue_all(batches.data(), batches.size())) return refused("a task's write queue is full: try again");
  std::vector<ForceResult> out;
  for (const auto& e : forces_) {
    ForceResult r;
    r.ok = true;
    r.unforce = true;
    r.ref = e.ref;
    r.task = e.task;
    r.type = e.cell.type;
    r.value = e.value_text;
    out.push_back(std::move(r));
  }
  forces_.clear();
  force_count_.store(0, std::memory_order_relaxed);
  forces_version_.fetch_add(1, std::memory_order_acq_rel);
  return out;
}

std::vector<ForceEntry> Program::forces() const {
  std::vector<ForceEntry> out;
  {
    std::lock_guard lock(forces_mutex_);
    out = forces_;
  }
  std::sort(out.begin(), out.end(), [](const ForceEntry& a, const ForceEntry& b) { return a.ref < b.ref; });
  return out;
}

std::optional<Cell> Program::forced_value(const CellRef& r) const {
  std::lock_guard lock(forces_mutex_);
  for (const auto& e : forces_)
    if (e.cell.task == r.task && e.cell.cell == r.cell) return e.value;
  return std::nullopt;
}

std::vector<ForceChange> Program::hand_forces_to(Program& to) {
  std::vector<ForceEntry> mine;
  {
    std::lock_guard lock(forces_mutex_);
    forces_closed_ = true;  // this program's tasks hold them until their switch; nothing changes them now
    mine = forces_;
  }
  std::sort(mine.begin(), mine.end(), [](const ForceEntry& a, const ForceEntry& b) { return a.ref < b.ref; });
  std::vector<ForceChange> out;
  for (const auto& e : mine) {
    ForceChange c{e.ref, false, ""};
    std::string err;
    auto r = to.resolve(e.ref, &err);
    if (!r) c.detail = err;
    else if (r->type != e.cell.type)
      c.detail = "type " + std::string(type_name(e.cell.type)) + " -> " + std::string(type_name(r->type));
    else if (r->length != 1) c.detail = "now an array of " + std::to_string(r->length) + " elements";
    else {
      ForceResult added = to.add_force(e.ref, *r, e.value, false);
      c.kept = added.ok;
      c.detail = added.ok ? "held at " + e.value_text : added.error;
    }
    out.push_back(std::move(c));
  }
  return out;
}

}  // namespace syncplc
