// Program's live values for non-real-time readers (program.hpp): tags from
// the published snapshots, pins from the tasks' pin monitors, and the list
// of block instances with their pins and variables.
#include <algorithm>

#include "runtime/core/program.hpp"

namespace syncplc {

std::optional<ValueStamp> Program::read_value(const CellRef& r, Cell* out, std::int64_t lease_ns) {
  if (r.task >= tasks.size()) return std::nullopt;
  Task& t = *tasks[r.task];
  if (r.length > t.image_cells() || r.cell > t.image_cells() - r.length) return std::nullopt;
  if (r.cell + r.length <= t.owned_cells) {
    std::lock_guard lock(t.external_mutex);  // values and stamp of one publication
    SnapshotStamp s;
    const Cell* src = t.channels[0]->latest(&s);
    std::copy_n(src + r.cell, r.length, out);
    return ValueStamp{s.scan, s.release_ns};
  }
  PinMonitor& m = t.pin_monitor();
  if (r.cell < m.first()) return std::nullopt;  // a copy of another task's tag: read the tag itself
  // The lease in the task's scans: from the scans it has made (stats.scans
  // lags its own count by at most the scan under way).
  const std::uint64_t scans = t.stats.scans.load(std::memory_order_relaxed);
  const auto period = std::max<std::int64_t>(1, t.config().period_ns);
  m.extend(scans + static_cast<std::uint64_t>(std::max<std::int64_t>(0, lease_ns) / period) + 2);
  std::int64_t release_ns = 0;
  const std::uint64_t taken = m.read(r.cell, r.length, out, &release_ns);
  // Copied at the newest scan (or the one before, read between its
  // publication and its accounting): live. Older: a lapsed lease's leftovers.
  if (taken + 1 < scans) return std::nullopt;
  return ValueStamp{taken, release_ns};
}

std::vector<InstanceInfo> Program::block_instances() const {
  std::vector<InstanceInfo> out;
  for (std::size_t ti = 0; ti < tasks.size(); ++ti) {
    const Task& t = *tasks[ti];
    for (std::size_t k = 0; k < t.blocks.size(); ++k) {
      const auto& bi = t.blocks[k];
      InstanceInfo info;
      info.name = bi.name;
      info.type = bi.type->is_generic() ? bi.type->name + "<" + std::string(type_name(bi.datatype)) + ">" : bi.type->name;
      info.task = t.config().name;
      info.position = static_cast<std::uint32_t>(k);
      for (std::size_t q = 0; q < bi.type->pins.size(); ++q) {
        const auto& decl = bi.type->pins[q];
        if (!decl.name.empty() && decl.name.front() == '(') continue;  // an ST POU's variables, below
        PinInfo p;
        p.name = decl.name;
        p.dir = decl.dir;
        p.type = decl.cls == TypeClass::Exact ? decl.type : bi.datatype;
        p.unit = decl.unit;
        p.cell = CellRef{static_cast<std::uint16_t>(ti), bi.pin_cell[q], p.type,
                         q < bi.pin_length.size() ? bi.pin_length[q] : 1};
        info.pins.push_back(std::move(p));
      }
      if (bi.type->variables_pin >= 0) {
        // The type's list, made once with it (BlockTypeInfo::monitored).
        const std::uint32_t base = bi.pin_cell[static_cast<std::size_t>(bi.type->variables_pin)];
        for (const auto& v : bi.type->monitored)
          info.variables.push_back({v.path, v.type, CellRef{static_cast<std::uint16_t>(ti), base + v.element, v.type, 1}});
        info.variables_left_out = bi.type->monitored_left_out;
      }
      out.push_back(std::move(info));
    }
  }
  return out;
}

}  // namespace syncplc
