// One task's switch at an online change, as both schedulers perform it
// (realtime.cpp on the task's thread, virtual_clock.cpp in its event loop):
// when it is due, and the grid the new task goes on with. One rule, so that
// real time and virtual time agree scan by scan, re-timed and restarted
// tasks included.
//
//   - A task that keeps its period and phase switches at its first release
//     at or after T, on the same grid: nothing about its timing changes.
//   - A re-timed task (period or phase changed) and a task restarted by the
//     change (its watchdog had stopped it) switch at T itself: the new grid
//     starts at its first point at or after T. When the old task's last
//     scan ran past T, the switch waits for it, and the new grid's points
//     between T and then count as skipped.
#pragma once

#include <cstdint>

#include "runtime/core/program_change.hpp"

namespace syncplc {

// What a scheduler knows of the old task at a switch decision.
struct OldGrid {
  std::int64_t k = 0;              // grid index of its next planned release
  std::int64_t prev_planned = 0;   // planned release of its last scan
  std::int64_t last_end = 0;       // when its last scan ended (no scan of the task before this)
  bool stopped = false;            // stopped by its watchdog or a driver's reaction
};

// Where the new task goes on.
struct NewGrid {
  std::int64_t k = 0;              // grid index of its first release
  std::int64_t prev_planned = 0;   // its first scan's dt is release(k) - prev_planned
  std::uint64_t skipped = 0;       // points of the new grid between T and the switch that got no scan
};

// The old task `h.from` is due to switch: its next release is at or after T
// (or it is stopped: it switches at T).
bool switch_due(const TaskHandover& h, const OldGrid& g);
// The instant of the switch (a due task's): T for a re-timed or restarted
// task, its next release otherwise; never before its last scan ended.
std::int64_t switch_at(const TaskHandover& h, const OldGrid& g);
// The new task's grid after the switch (h.to must be set).
NewGrid new_grid(const TaskHandover& h, const OldGrid& g);

}  // namespace syncplc
