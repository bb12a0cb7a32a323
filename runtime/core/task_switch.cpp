#include "runtime/core/task_switch.hpp"

#include <algorithm>

namespace syncplc {
namespace {

// The first index of `c`'s grid whose release is at or after t.
std::int64_t first_index_at(const TaskConfig& c, std::int64_t t) {
  const std::int64_t d = t - c.phase_ns;
  if (d <= 0) return 0;
  return (d + c.period_ns - 1) / c.period_ns;
}

bool new_grid_from_T(const TaskHandover& h, const OldGrid& g) { return h.timing_changed || g.stopped; }

}  // namespace

bool switch_due(const TaskHandover& h, const OldGrid& g) {
  return g.stopped || h.from->release_ns(g.k) >= h.switch_ns;
}

std::int64_t switch_at(const TaskHandover& h, const OldGrid& g) {
  const std::int64_t planned = new_grid_from_T(h, g) ? h.switch_ns : h.from->release_ns(g.k);
  return std::max(planned, g.last_end);
}

NewGrid new_grid(const TaskHandover& h, const OldGrid& g) {
  NewGrid n;
  n.k = g.k;
  n.prev_planned = g.prev_planned;
  if (!new_grid_from_T(h, g)) return n;  // the same grid goes on
  const TaskConfig& c = h.to->config();
  n.k = first_index_at(c, switch_at(h, g));
  n.skipped = static_cast<std::uint64_t>(n.k - first_index_at(c, h.switch_ns));
  // A restarted task's first scan sees one period, as at a start; a
  // re-timed one the time since its last old scan.
  if (g.stopped) n.prev_planned = h.to->release_ns(n.k) - c.period_ns;
  return n;
}

}  // namespace syncplc
