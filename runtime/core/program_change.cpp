#include "runtime/core/program_change.hpp"

#include <algorithm>
#include <cstring>
#include <limits>
#include <optional>
#include <utility>

namespace syncplc {

std::string_view instance_fate_name(InstanceFate f) {
  switch (f) {
    case InstanceFate::Kept: return "kept";
    case InstanceFate::Retuned: return "retuned";
    case InstanceFate::Rewired: return "rewired";
    case InstanceFate::New: return "new";
    case InstanceFate::Removed: return "removed";
  }
  return "?";
}

std::string_view task_fate_name(TaskFate f) {
  switch (f) {
    case TaskFate::Kept: return "kept";
    case TaskFate::Retimed: return "re-timed";
    case TaskFate::Added: return "added";
    case TaskFate::Removed: return "removed";
    case TaskFate::Restarted: return "restarted";
  }
  return "?";
}

TaskHandover* ProgramChange::for_old_task(std::size_t i) const {
  if (!from || i >= from->tasks.size()) return nullptr;
  for (const auto& h : handovers)
    if (h->from == from->tasks[i].get()) return h.get();
  return nullptr;
}

std::size_t ProgramChange::count(InstanceFate f) const {
  return static_cast<std::size_t>(
      std::count_if(instances.begin(), instances.end(), [f](const InstanceChange& c) { return c.fate == f; }));
}

void TaskHandover::mirror(const Cell* from_image, const SnapshotStamp& s) noexcept {
  if (!to) return;
  Cell* dst = to->image(ImageAccess{}).data();
  for (const auto& c : owned) std::memcpy(static_cast<void*>(dst + c.to), from_image + c.from, c.n * sizeof(Cell));
  to->publish_for_predecessor(s);
}

std::uint64_t TaskHandover::apply_successor_writes(Cell* from_image) noexcept {
  if (!to) return 0;
  std::uint64_t n = 0;
  QueuedWrite w;
  while (to->pop_write(w)) {
    if (w.kind != WriteKind::Write) {
      // A force given to the new program: it holds from the switch on (the
      // new task's table is this thread's until then).
      to->apply_force_command(w);
      continue;
    }
    if (w.cell < write_back.size() && write_back[w.cell] != kDroppedCell) from_image[write_back[w.cell]] = w.value;
    else to->image(ImageAccess{})[w.cell] = w.value;
    ++n;
  }
  return n;
}

void TaskHandover::perform() noexcept {
  if (to && from) {
    Cell* dst = to->image(ImageAccess{}).data();
    const Cell* src = from->image(ImageAccess{}).data();
    for (const auto& c : owned) std::memcpy(static_cast<void*>(dst + c.to), src + c.from, c.n * sizeof(Cell));
    for (const auto& c : pins) std::memcpy(static_cast<void*>(dst + c.to), src + c.from, c.n * sizeof(Cell));
    // Writes acknowledged to the old task and not yet applied: into the new
    // image, before the new task's own queue (they arrived first).
    QueuedWrite w;
    // Force commands to the old task were carried over at begin_mirroring
    // (Program::hand_forces_to): its registry had them from the moment they were queued.
    while (from->pop_write(w))
      if (w.kind == WriteKind::Write && w.cell < write_cell.size() && write_cell[w.cell] != kDroppedCell) dst[write_cell[w.cell]] = w.value;
    // Swapped, not moved: the fresh instance the loader made goes to the old
    // program and is destroyed with it by the main thread (no free here).
    for (const auto& b : blocks) {
      if (b.mode == BlockHandover::Mode::CarryState) {
        from->blocks[b.from].block->save_retain(state_scratch.data());
        to->blocks[b.to].block->load_retain(state_scratch.data());
        continue;
      }
      auto& kept = to->blocks[b.to].block;
      auto& fresh = from->blocks[b.from].block;
      std::swap(kept, fresh);
      if (b.mode == BlockHandover::Mode::Rewire) {
        // The checks around execute follow the new wiring too (a tuning
        // input wired in or out); a unit delay's held input stays.
        const bool held = kept->guard().held;
        std::swap(kept->guard(), fresh->guard());
        kept->guard().held = held;
        kept->rewire_from(*fresh);
      }
      // A rewired instance also takes the parameters: a tuning input wired
      // out gives its parameter back (one wired in overrides it at the next
      // scan, through the guard).
      if (b.mode != BlockHandover::Mode::Keep) {
        kept->retune_from(*fresh);
        // A connected tuning input overrides the parameter just taken: seen
        // again at the next scan (NaN is never "the same value").
        for (auto& t : kept->guard().tuning) t.seen = std::numeric_limits<double>::quiet_NaN();
      }
      kept->bind_pins(to->blocks[b.to].pins.data());
    }
    for (const auto& d : drivers) {
      auto& kept = to_program->drivers[d.to_binding].driver;
      std::swap(kept, from_program->drivers[d.from_binding].driver);
      to->drivers[d.to_slot] = kept.get();
      kept->bind(d.cells);  // same channels, same size: the vector's storage is reused
    }
    // Links follow the swaps: a block linked to a kept instance reaches
    // that one, not the fresh instance that went to the old program.
    to->relink();
    to->stats.continue_from(from->stats);
    to->continue_scan_count(from->scan_count());
  }
}

namespace {

// What becomes of a new instance that has an old namesake in the matched
// task, from their signatures (instance_signature.hpp).
struct InstancePlan {
  InstanceChange change;
  std::optional<BlockHandover::Mode> mode;  // none: the new instance starts fresh
};

InstancePlan plan_instance(const BlockInstance& o, const BlockInstance& n, bool persistent, const std::string& task) {
  InstancePlan p{{n.name, n.type->name, task, InstanceFate::Kept, ""}, BlockHandover::Mode::Keep};
  const SignatureDiff d = compare_signatures(o.signature, n.signature);
  p.change.detail = d.detail;
  switch (d.verdict) {
    case SignatureVerdict::Same: break;
    case SignatureVerdict::Retune:
      p.change.fate = InstanceFate::Retuned;
      p.mode = BlockHandover::Mode::Retune;
      break;
    case SignatureVerdict::Rewire:
      p.change.fate = InstanceFate::Rewired;
      p.mode = BlockHandover::Mode::Rewire;
      break;
    case SignatureVerdict::Recreate:
      p.change.fate = InstanceFate::New;
      p.mode.reset();
      // Persistent state survives a changed project at a stop and start
      // (retain.hpp); an online change keeps it the same way.
      if (persistent && d.state_matches) {
        p.mode = BlockHandover::Mode::CarryState;
        p.change.detail += "; its persistent state carried over";
      }
      break;
  }
  return p;
}

// A re-created instance with variables (an ST POU's changed body, st_block.hpp):
// the new instance keeps each variable whose path and type are unchanged,
// copied at the switch from the old variables pin into the new one; the
// others keep their initial values. The report names both.
void carry_variables(const BlockInstance& o, const BlockInstance& n, TaskHandover& h, std::string& detail) {
  const auto op = static_cast<std::size_t>(o.type->variables_pin);
  const auto np = static_cast<std::size_t>(n.type->variables_pin);
  std::string kept, fresh;
  std::size_t kept_count = 0, fresh_count = 0;
  auto add = [](std::string& list, std::size_t& count, const std::string& path) {
    if (++count <= 8) list += (list.empty() ? "" : ", ") + path;
  };
  for (const auto& leaf : n.type->variable_leaves) {
    const BlockTypeInfo::VariableLeaf* old = nullptr;
    for (const auto& l : o.type->variable_leaves)
      if (l.path == leaf.path && l.type == leaf.type && l.count == leaf.count) old = &l;
    if (!old) {
      add(fresh, fresh_count, leaf.path);
      continue;
    }
    h.pins.push_back({o.pin_cell[op] + old->element, n.pin_cell[np] + leaf.element, leaf.count});
    add(kept, kept_count, leaf.path);
  }
  auto more = [](std::size_t count) { return count > 8 ? " and " + std::to_string(count - 8) + " more" : std::string(); };
  // The signature's difference is the compiler's parameters (code, frame size): say it in the user's words.
  detail = std::string("its code changed; its variables kept: ") + (kept.empty() ? "none" : kept) +
            more(kept_count) + (fresh.empty() ? "" : "; new, at their initial values: " + fresh + more(fresh_count));
}

const RetainedInstance* find_retained(const Program& p, const std::string& name) {
  for (const auto& r : p.retained)
    if (r.name == name) return &r;
  return nullptr;
}

}  // namespace

// plan_change's access to the new program's images (no thread runs it yet).
class ChangePlanner {
 public:
  static void carry_tags(Program& from, Program& to, ProgramChange& c);
};

void ChangePlanner::carry_tags(Program& from, Program& to, ProgramChange& c) {
  const ImageAccess access;
  for (const auto& t : to.tags) {
    const Tag* old = from.find_tag(t.name);
    if (!old || tag_identity(*old) != tag_identity(t)) continue;
    from.read_tag(*old, to.tasks[t.owner]->image(access).data() + t.cell);
    ++c.tags_carried;
  }
  // Retained block states of the same identity, as last published: what the
  // store reads from the new program's channels before the old tasks first
  // mirror into them is the running state, never the fresh instance's
  // initial one (the old task mirrors them from then on, plan_change).
  for (const auto& r : to.retained) {
    const RetainedInstance* o = find_retained(from, r.name);
    if (!o || o->identity != r.identity || o->length != r.length) continue;
    from.tasks[o->task]->read_published(o->cell, o->length, to.tasks[r.task]->image(access).data() + r.cell);
  }
  for (std::size_t i = 0; i < to.tasks.size(); ++i) {
    auto& task = *to.tasks[i];
    int j = from.find_task(task.config().name);
    SnapshotStamp stamp;
    if (j >= 0) stamp = from.tasks[static_cast<std::size_t>(j)]->published_stamp();
    for (auto& ch : task.channels) ch->fill(task.image(access).data(), stamp);
  }
}

std::unique_ptr<ProgramChange> plan_change(Program& from, Program& to) {
  auto c = std::make_unique<ProgramChange>();
  c->from = &from;
  c->to = &to;
  ChangePlanner::carry_tags(from, to, *c);

  std::vector<bool> old_kept_driver(from.drivers.size(), false);
  for (std::size_t i = 0; i < to.tasks.size(); ++i) {
    auto h = std::make_unique<TaskHandover>();
    h->from_program = &from;
    h->to_program = &to;
    Task& nt = *to.tasks[i];
    h->to = &nt;
    const std::string& tname = nt.config().name;
    const int j = from.find_task(tname);
    if (j < 0) {
      c->tasks.push_back({tname, TaskFate::Added, "first scan at the switch"});
    } else {
      Task& ot = *from.tasks[static_cast<std::size_t>(j)];
      h->from = &ot;
      const auto& oc = ot.config();
      const auto& nc = nt.config();
      std::string detail;
      if (oc.period_ns != nc.period_ns) detail += "period " + format_duration(oc.period_ns) + " -> " + format_duration(nc.period_ns);
      if (oc.phase_ns != nc.phase_ns)
        detail += (detail.empty() ? "" : ", ") + std::string("phase ") + format_duration(oc.phase_ns) + " -> " + format_duration(nc.phase_ns);
      h->timing_changed = !detail.empty();
      if (oc.priority != nc.priority)
        detail += (detail.empty() ? "" : ", ") + std::string("priority ") + std::to_string(oc.priority) + " -> " + std::to_string(nc.priority);
      if (oc.cpu != nc.cpu)
        detail += (detail.empty() ? "" : ", ") + std::string("cpu ") + std::to_string(oc.cpu) + " -> " + std::to_string(nc.cpu);
      if (ot.stopped()) c->tasks.push_back({tname, TaskFate::Restarted, "was stopped by its watchdog" + (detail.empty() ? "" : "; " + detail)});
      else c->tasks.push_back({tname, detail.empty() ? TaskFate::Kept : TaskFate::Retimed, detail});

      // Owned tags: same name, type and size.
      h->write_cell.assign(ot.image_cells(), kDroppedCell);
      h->write_back.assign(nt.owned_cells, kDroppedCell);
      for (const auto& t : to.tags) {
        if (t.owner != i) continue;
        const Tag* old = from.find_tag(t.name);
        if (!old || old->owner != static_cast<std::uint16_t>(j) || old->type != t.type || old->length != t.length) continue;
        h->owned.push_back({old->cell, t.cell, t.length});
        for (std::uint32_t k = 0; k < t.length; ++k) {
          h->write_cell[old->cell + k] = t.cell + k;
          h->write_back[t.cell + k] = old->cell + k;
        }
      }
      // Retained block state (same instance, type and layout): mirrored too,
      // so the store never reads a kept counter's state as its initial one.
      for (const auto& r : to.retained) {
        if (r.task != i) continue;
        const RetainedInstance* o = find_retained(from, r.name);
        if (o && o->task == static_cast<std::uint16_t>(j) && o->identity == r.identity && o->length == r.length)
          h->owned.push_back({o->cell, r.cell, r.length});
      }
      // Block instances.
      for (std::size_t p = 0; p < nt.blocks.size(); ++p) {
        const auto& nb = nt.blocks[p];
        auto it = from.instances.find(nb.name);
        if (it == from.instances.end()) {
          c->instances.push_back({nb.name, nb.type->name, tname, InstanceFate::New, ""});
          continue;
        }
        if (it->second.first != static_cast<std::uint16_t>(j)) {
          c->instances.push_back({nb.name, nb.type->name, tname, InstanceFate::New,
                                  "moved from task " + from.tasks[it->second.first]->config().name});
          continue;
        }
        const auto& ob = ot.blocks[it->second.second];
        const RetainedInstance* ret = find_retained(to, nb.name);
        InstancePlan ip = plan_instance(ob, nb, ret && ret->persistent, tname);
        if (!ip.mode && ob.type->variables_pin >= 0 && nb.type->variables_pin >= 0)
          carry_variables(ob, nb, *h, ip.change.detail);
        if (ip.mode) {
          h->blocks.push_back({it->second.second, static_cast<std::uint32_t>(p), *ip.mode});
          if (*ip.mode == BlockHandover::Mode::CarryState && h->state_scratch.size() < nb.signature.state.cells)
            h->state_scratch.resize(nb.signature.state.cells);
          for (std::size_t q = 0; q < nb.type->pins.size(); ++q)
            if (nb.type->pins[q].dir == PinDir::Out)
              h->pins.push_back({ob.pin_cell[q], nb.pin_cell[q], q < nb.pin_length.size() ? nb.pin_length[q] : 1});
        }
        c->instances.push_back(std::move(ip.change));
      }
      // Drivers: same name, same task, same settings.
      for (std::size_t b = 0; b < to.drivers.size(); ++b) {
        const auto& nd = to.drivers[b];
        if (nd.task != i) continue;
        int a = from.find_driver(nd.driver->name());
        if (a < 0) continue;
        const auto& od = from.drivers[static_cast<std::size_t>(a)];
        if (od.task != static_cast<std::uint16_t>(j) || od.settings != nd.settings || ot.stopped()) continue;
        DriverHandover dh;
        dh.from_binding = static_cast<std::size_t>(a);
        dh.to_binding = b;
        dh.to_slot = static_cast<std::size_t>(
            std::find(nt.drivers.begin(), nt.drivers.end(), nd.driver.get()) - nt.drivers.begin());
        dh.cells = nd.cells;
        h->drivers.push_back(std::move(dh));
        old_kept_driver[static_cast<std::size_t>(a)] = true;
      }
    }
    c->handovers.push_back(std::move(h));
  }
  // Old tasks the new program does not have.
  for (std::size_t j = 0; j < from.tasks.size(); ++j) {
    const std::string& tname = from.tasks[j]->config().name;
    if (to.find_task(tname) >= 0) continue;
    auto h = std::make_unique<TaskHandover>();
    h->from_program = &from;
    h->to_program = &to;
    h->from = from.tasks[j].get();
    c->tasks.push_back({tname, TaskFate::Removed, "its last scan is the one before the switch"});
    c->handovers.push_back(std::move(h));
  }
  // Instances the new program does not have (or has elsewhere: reported as new there).
  for (std::size_t j = 0; j < from.tasks.size(); ++j)
    for (const auto& ob : from.tasks[j]->blocks) {
      auto it = to.instances.find(ob.name);
      int nj = to.find_task(from.tasks[j]->config().name);
      if (it == to.instances.end() || nj < 0 || it->second.first != static_cast<std::uint16_t>(nj))
        c->instances.push_back({ob.name, ob.type->name, from.tasks[j]->config().name, InstanceFate::Removed,
                                it == to.instances.end() ? "" : "moved to task " + to.tasks[it->second.first]->config().name});
    }
  // Drivers.
  std::vector<bool> new_kept(to.drivers.size(), false);
  for (const auto& h : c->handovers)
    for (const auto& d : h->drivers) new_kept[d.to_binding] = true;
  for (std::size_t b = 0; b < to.drivers.size(); ++b) {
    const auto& nd = to.drivers[b];
    if (new_kept[b]) {
      c->drivers.push_back({nd.driver->name(), true, "kept open"});
      continue;
    }
    c->new_drivers.push_back(b);
    int a = from.find_driver(nd.driver->name());
    c->drivers.push_back({nd.driver->name(), false, a < 0 ? "new" : "restarted (settings or task changed)"});
  }
  for (std::size_t a = 0; a < from.drivers.size(); ++a) {
    if (old_kept_driver[a]) continue;
    c->old_drivers.push_back(a);
    if (to.find_driver(from.drivers[a].driver->name()) < 0) c->drivers.push_back({from.drivers[a].driver->name(), false, "removed"});
  }
  return c;
}

std::int64_t switch_instant(const ProgramChange& c, std::int64_t now_ns) {
  std::int64_t longest = 0;
  for (const auto& t : c.from->tasks) longest = std::max(longest, t->config().period_ns);
  for (const auto& t : c.to->tasks) longest = std::max(longest, t->config().period_ns);
  // Two scans of mirroring before T for every task, and one more period of
  // margin so that none of them is already in the scan that must mirror.
  return now_ns + 3 * longest + 2'000'000;
}

void begin_mirroring(ProgramChange& c) {
  // Forces go over first: each new task's table is filled before any
  // thread can reach it through its handover (set_handover releases it).
  c.forces = c.from->hand_forces_to(*c.to);
  for (auto& h : c.handovers) {
    h->switch_ns = c.switch_ns;
    if (h->from) h->from->set_handover(h.get());
  }
}

}  // namespace syncplc
