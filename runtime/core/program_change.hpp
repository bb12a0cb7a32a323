// Online change: a running program replaced by a newly loaded one without a
// stop (docs/user-guide.md, "Online change").
//
// The main thread loads and checks the new program beside the running one and
// plans the change (plan_change): tasks are matched by name, block instances
// by name, drivers by name and settings. Each task then switches on its own
// thread, between two scans, at its first release at or after the switch
// instant T (TaskHandover::perform, called by either scheduler): its time
// grid, scan count and statistics go on; block instances whose type and
// structure are unchanged move into the new program with all their state
// (retuned: they also take the new tunable parameters); drivers whose
// settings are unchanged move over open, with their state.
//
// Why the result is exact: with logical-execution-time exchange
// (snapshot_channel.hpp) a scan released at t reads publications visible at
// t. A scan before T reads only publications of scans released before T, all
// old; a scan at or after T may read an old scan's publication. So from
// planning until its own switch, every old task also publishes into its
// successor's channels, in the new layout (TaskHandover::mirror), and a new
// consumer that switches before its producer reads what it would have read
// had nothing changed. T leaves every task at least two scans of mirroring.
#pragma once

#include <atomic>
#include <cstdint>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "runtime/core/program.hpp"

namespace syncplc {

// Kept: the running instance goes on as it is. Retuned: it takes the new
// tunable parameters. Rewired: it takes what its factory fixed from the new
// wiring (and the tunables), keeping its state. New: the new program's
// instance replaces it (a new name, a structural change, a move between
// tasks); a persistent instance whose state layout is unchanged takes the old
// one's state, as a stop and start would restore it (the detail says so).
enum class InstanceFate : std::uint8_t { Kept, Retuned, Rewired, New, Removed };
enum class TaskFate : std::uint8_t { Kept, Retimed, Added, Removed, Restarted };
std::string_view instance_fate_name(InstanceFate f);
std::string_view task_fate_name(TaskFate f);

struct InstanceChange {
  std::string name;
  std::string type;
  std::string task;
  InstanceFate fate = InstanceFate::Kept;
  std::string detail;  // what changed ("kp 2 -> 3", "type PID -> PD_CONTROLLER", "moved from task a")
};

struct TaskChange {
  std::string name;
  TaskFate fate = TaskFate::Kept;
  std::string detail;
};

struct DriverChange {
  std::string name;
  bool kept = false;  // false: the new program's driver replaces the old one (or is new, or the old is removed)
  std::string detail;
};

inline constexpr std::uint32_t kDroppedCell = std::numeric_limits<std::uint32_t>::max();

struct BlockHandover {
  enum class Mode : std::uint8_t {
    Keep,        // the old instance moves into the new program
    Retune,      // ... and takes the fresh one's tunable parameters (Block::retune_from)
    Rewire,      // ... and takes the fresh one's wiring choices, guard and tunables (Block::rewire_from)
    CarryState,  // the fresh instance stays and takes the old one's state (save_retain -> load_retain)
  };
  std::uint32_t from = 0;  // position in the old task's execution order
  std::uint32_t to = 0;    // position in the new task's
  Mode mode = Mode::Keep;
};

struct DriverHandover {
  std::size_t from_binding = 0;  // index in the old Program::drivers
  std::size_t to_binding = 0;    // index in the new Program::drivers
  std::size_t to_slot = 0;       // index in the new task's drivers
  std::vector<Cell*> cells;      // the channel binding in the new image
};

// A cell of one image copied to a cell of another (old image -> new image).
struct CrossCopy {
  std::uint32_t from = 0;
  std::uint32_t to = 0;
  std::uint32_t n = 1;
};

// Everything one task's switch needs, resolved by the main thread in advance:
// perform() and mirror() run on the task's thread and never allocate.
struct TaskHandover {
  Program* from_program = nullptr;
  Program* to_program = nullptr;
  Task* from = nullptr;  // nullptr: a task the new program adds
  Task* to = nullptr;    // nullptr: a task the new program removes
  std::vector<CrossCopy> owned;          // the old task's owned tags -> the same tags in the new image
  std::vector<CrossCopy> pins;           // output pins of moved block instances
  std::vector<std::uint32_t> write_cell; // old image cell -> new image cell of a queued write (kDroppedCell)
  std::vector<std::uint32_t> write_back; // new owned cell -> old image cell (kDroppedCell: a tag only the new program has)
  std::vector<BlockHandover> blocks;
  std::vector<Cell> state_scratch;       // sized for the largest CarryState: perform() never allocates
  std::vector<DriverHandover> drivers;
  bool timing_changed = false;           // period or phase changed: the new grid starts at T
  std::int64_t switch_ns = 0;            // T (copied from the change by begin_mirroring)
  std::atomic<bool> done{false};
  // How late the new task's first scan started (actual start − planned
  // release, ns; real time only, -1 until it ran): what the switch cost.
  std::atomic<std::int64_t> first_scan_late_ns{-1};

  // The old task published: make the same publication for the new task.
  void mirror(const Cell* from_image, const SnapshotStamp& s) noexcept;
  // On the old task's thread, at its scan start: the writes HMIs queued to
  // the new task, applied to the old image (or, for tags only the new
  // program has, to the new image). Returns how many.
  std::uint64_t apply_successor_writes(Cell* from_image) noexcept;
  // The switch, between the old task's last scan and the new task's first.
  void perform() noexcept;
  // The scheduler is done with this handover (it never touches it again):
  // after perform for virtual time and a removed task, after the new task's
  // first scan started (first_scan_late_ns recorded) in real time.
  void finish() noexcept { done.store(true, std::memory_order_release); }
};

struct ProgramChange {
  Program* from = nullptr;
  Program* to = nullptr;
  // For each task of the new program, its handover (the old task may be
  // absent); then one for each task only the old program has (removed).
  std::vector<std::unique_ptr<TaskHandover>> handovers;
  std::vector<TaskChange> tasks;
  std::vector<InstanceChange> instances;
  std::vector<DriverChange> drivers;
  std::vector<std::size_t> new_drivers;  // bindings of `to` that need opening (not moved over)
  std::vector<std::size_t> old_drivers;  // bindings of `from` to close after the change (not moved)
  std::int64_t switch_ns = 0;            // T, on the schedulers' time axis
  std::size_t tags_carried = 0;          // tags of the new program that took the old program's value
  // The old program's forces, kept (same element, same type) or dropped,
  // filled by begin_mirroring: from then on the old program refuses forces.
  std::vector<ForceChange> forces;

  TaskHandover* for_new_task(std::size_t i) const { return handovers[i].get(); }
  // The handover of old task i (nullptr when the old program had none such).
  TaskHandover* for_old_task(std::size_t i) const;
  // Counts for the one-line summary.
  std::size_t count(InstanceFate f) const;
};

// Plans replacing `from` by `to` (neither runs differently yet). `to` must
// have been loaded but not started. Sets each new task's values to the old
// program's published ones (tags matched by name, type and size) and fills its
// channels; moves nothing yet.
std::unique_ptr<ProgramChange> plan_change(Program& from, Program& to);

// The earliest sensible switch instant after `now_ns`: every task (old and
// new) gets at least two scans of mirroring before it.
std::int64_t switch_instant(const ProgramChange& c, std::int64_t now_ns);

// Hands the old program's forces to the new one (Program::hand_forces_to,
// the outcome in c.forces) and each old task its handover: from now on they
// mirror their publications.
void begin_mirroring(ProgramChange& c);

}  // namespace syncplc
