// A program ready to run: tags, tasks with their resolved blocks, I/O
// drivers, traces. Built by the project loader (runtime/project); run by a
// scheduler (virtual_clock.hpp, realtime.hpp). What else a project says (its
// Modbus server and places, the paper-000 metrics) stays beside the program
// in the loader's result: the core holds the image, tasks and channels. Other threads (Modbus, HMI,
// status display) read tags through the published snapshots and write them
// through the owning task's queue: they never touch a task's image.
#pragma once

#include <atomic>
#include <cstdint>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "runtime/core/config_node.hpp"
#include "runtime/core/direct_address.hpp"
#include "runtime/core/io_driver.hpp"
#include "runtime/core/task.hpp"

namespace syncplc {

// Most tasks a project may declare (task numbers are 16-bit; per-task tables
// such as the status display's are sized by it).
inline constexpr std::size_t kMaxTasks = 64;

enum class HmiAccess : std::uint8_t { None, Read, ReadWrite };
std::string_view hmi_access_name(HmiAccess a);

struct Tag {
  std::string name;
  IecType type = IecType::LREAL;
  std::uint32_t length = 1;  // cells; > 1 or is_array for ARRAY[0..length-1] OF type
  bool is_array = false;
  std::int64_t array_lower = 0;  // ARRAY[lower..lower+length-1]
  std::optional<DirectAddress> address;
  bool retain = false;      // RETAIN: survives a restart (warm start)
  bool persistent = false;  // PERSISTENT: also survives loading a changed project; implies retain
  HmiAccess hmi = HmiAccess::None;
  std::string unit;
  std::string description;
  std::vector<Cell> init;   // length cells
  std::vector<Cell> safe;   // empty: no safe value
  std::uint16_t owner = 0;  // the task that writes it and publishes it
  std::uint32_t cell = 0;   // first cell in the owner's image (inside its owned range)
  // Engineering limits (the project's min: and max:, in the tag's unit):
  // the range a write from outside (HTTP API, HMI) may set; nullopt: only
  // the type's own range (tag_limits.hpp).
  std::optional<double> min, max;
  std::string writer;       // "block x.Q", "driver io.ch", "" (HMI / tests only)
  bool written_every_scan = false;  // by its writer, every element: a write from outside would be overwritten
  SourceLoc loc;
};

// A cell in some task's image, for traces, tests and the status display.
struct CellRef {
  std::uint16_t task = 0;
  std::uint32_t cell = 0;
  IecType type = IecType::LREAL;
  std::uint32_t length = 1;
};

struct TraceColumn {
  std::string label;  // instance.pin, tag or tag[i]
  CellRef ref;
};

struct DriverBinding {
  std::unique_ptr<IoDriver> driver;
  std::string type;
  std::uint16_t task = 0;
  std::vector<std::string> bound_tags;  // per channel, "" when unbound
  std::vector<Cell*> cells;             // per channel, the bound cell in the task's image (nullptr: unbound)
  // type, task period, seed and the entry without `bind`: equal settings
  // mean the same driver (an online change keeps it open, state and all).
  std::string settings;
};

// A block instance declared retain: its state (Block::save_retain) is copied
// each scan into `length` cells of its task's published range at `cell`, so
// the store thread reads it from the snapshots like a tag.
struct RetainedInstance {
  std::string name;
  std::string identity;         // InstanceSignature::state_identity(): "CTU<INT> state 1 (2 cells)"
  std::uint16_t task = 0;
  std::uint32_t position = 0;   // in the task's execution order
  std::uint32_t cell = 0;
  std::uint32_t length = 0;
  bool persistent = false;
};

// --- forcing (docs/user-guide.md, "Forcing and monitoring") ---------------------

// One active force as every reader sees it (Program::forces).
struct ForceEntry {
  std::string ref;         // "tag", "tag[i]", "instance.pin", "instance.pin[i]"
  CellRef cell;            // one element
  Cell value;
  std::string value_text;  // the value as IEC text (format_value)
  std::string task;        // the owning task's name
};

// What force/unforce did, with all an audit event needs; the caller (HTTP
// server, command line) knows the user and writes the event with
// event_text() (the core has no user to name).
struct ForceResult {
  bool ok = false;
  std::string error;        // why nothing was done, when !ok
  std::string ref;          // as resolved: "motor.speed", "levels[2]"
  std::string task;         // the owning task
  IecType type = IecType::LREAL;
  std::string value;        // force: the value now held; unforce: the value it was held at
  std::string previous;     // force: the value it was held at before ("" when it was not forced)
  bool unforce = false;
  // "forced motor.speed to 1.5 (was forced to 1)", "unforced motor.speed (was forced to 1.5)".
  std::string event_text() const;
};

// What an online change did with a force (program_change.hpp's report).
struct ForceChange {
  std::string ref;
  bool kept = false;
  std::string detail;  // why it was dropped
};

// --- pin monitoring -----------------------------------------------------------------

struct PinInfo {
  std::string name;
  PinDir dir = PinDir::In;
  IecType type = IecType::LREAL;
  std::string unit;
  CellRef cell;  // length n for an array pin (ARRAY[1..n])
};

// An elementary variable of an instance that has them (an ST instance's
// "count", "t.ET", "hist[2]"), for monitoring.
struct VariableInfo {
  std::string name;  // the path below the instance
  IecType type = IecType::LREAL;
  CellRef cell;
};

struct InstanceInfo {
  std::string name;
  std::string type;            // block type; generic ones with their type: "ADD<LREAL>"
  std::string task;
  std::uint32_t position = 0;  // in the task's execution order
  std::vector<PinInfo> pins;   // in declaration order; not the hidden "(variables)" pins of an ST POU
  // Its variables that are not pins, element by element (BlockTypeInfo::
  // monitored: at most kMaxMonitored; strings are addressed by hand).
  std::vector<VariableInfo> variables;
  std::size_t variables_left_out = 0;
};

// How long a read keeps a task's pins monitored after it (Program::read_value).
inline constexpr std::int64_t kMonitorLeaseNs = 2'000'000'000;

// The scan a live value comes from (Program::read_value): the owning task's
// scan count (0: the value as loaded, before any scan) and that scan's
// planned release in logical time.
struct ValueStamp {
  std::uint64_t scan = 0;
  std::int64_t release_ns = 0;
};

class Program {
 public:
  std::string name;
  std::string version;
  std::string file;
  std::uint64_t seed = 0;
  // What the blocks' types and code live in beyond the registry (the
  // project's compiled Structured Text): kept as long as the program.
  std::shared_ptr<const void> code;
  std::vector<std::unique_ptr<Task>> tasks;
  std::vector<Tag> tags;
  std::vector<RetainedInstance> retained;  // block instances declared retain or persistent
  std::vector<DriverBinding> drivers;
  std::vector<TraceColumn> traces;
  std::vector<std::string> watch;  // tags shown by the live status

  // The real-time scheduler's epoch (monotonic ns of logical time 0), set when
  // it starts or switches to this program; -1 when no scheduler runs it in
  // real time. Readers use it to tell the age of a published value.
  std::atomic<std::int64_t> epoch_ns{-1};

  const Tag* find_tag(const std::string& name) const;
  int find_task(const std::string& name) const;
  int find_driver(const std::string& name) const;
  // "instance.pin", "tag" or "tag[i]" (i within the tag's declared bounds, e.g. 1..4).
  std::optional<CellRef> resolve(const std::string& ref, std::string* error = nullptr) const;
  // A variable of an instance that has them (an ST instance's "cell.count",
  // "cell.fb.q", "cell.arr[2]"), not a pin: its cell, or nullopt with
  // *names_one telling whether `ref` names such a variable at all (then
  // *error says what is wrong with it).
  // *info (when given): what else the type says of it (read only, a range).
  std::optional<CellRef> resolve_variable(const std::string& ref, bool* names_one, std::string* error,
                                          BlockTypeInfo::Variable* info = nullptr) const;
  // Instance name -> (task, position in execution order).
  std::map<std::string, std::pair<std::uint16_t, std::uint32_t>> instances;

  // Non-real-time side. read_tag: the owner's latest published value.
  void read_tag(const Tag& tag, Cell* out) const;
  // Queues a write of `count` elements starting at `element`; applied at the
  // owner's next scan start. False when the owner's queue is full.
  bool write_tag(const Tag& tag, std::uint32_t element, const Cell* values, std::uint32_t count) const;

  // Forcing. `ref` as resolve() takes it, one element (a scalar tag, tag[i],
  // instance.pin, instance.pin[i]); `value` as a project file writes it
  // (parse_value_in_unit: TRUE, 16#FF, T#5ms, "1500 mm" into a tag in m).
  // The force travels to the owning task through its write queue and holds
  // from that task's next scan start until unforced, whatever the program,
  // a driver or an outside writer puts there (force_table.hpp says where in
  // the scan). Forcing ignores `hmi:` access (the caller checks the user's
  // role). Refused, with the reason in ForceResult::error: an unknown or
  // array reference, a bad value, max_forces reached (a new element; a
  // forced one takes a new value), a stopped task, a full write queue, an
  // online change under way (force again on the new program). Thread-safe.
  ForceResult force(const std::string& ref, const std::string& value);
  // Releases ref: from the next scan the program writes it again (an
  // unconnected input pin gets its constant back; a tag nothing writes
  // keeps the forced value until something does).
  ForceResult unforce(const std::string& ref);
  // Releases every force, all in the same scan of each task (all or none
  // queued); one result per force released, for the caller's events.
  std::vector<ForceResult> unforce_all();
  // The active forces, sorted by ref: what to flag as forced. A force is
  // listed once it is queued, which may be up to one scan before its task
  // holds it. forces_version() changes with every change of the list, so a
  // reader can keep its copy until then.
  std::vector<ForceEntry> forces() const;
  std::size_t force_count() const noexcept { return force_count_.load(std::memory_order_relaxed); }
  std::uint64_t forces_version() const noexcept { return forces_version_.load(std::memory_order_acquire); }
  // The value `r` (one element) is forced to, nullopt when it is not forced.
  std::optional<Cell> forced_value(const CellRef& r) const;
  // At most this many forces at once (the project's `project: max_forces`);
  // each task's force table is sized by it at load.
  std::size_t max_forces = kDefaultMaxForces;
  // Online change (begin_mirroring): the forces this program holds go over to
  // `to` where the same element exists with the same type; this program
  // refuses forces from then on. The report says which were dropped and why.
  std::vector<ForceChange> hand_forces_to(Program& to);

  // Live values for non-real-time readers. read_value: the newest value of
  // `r` (a tag, element or pin, as resolve() gives it; r.length cells):
  // tags from the owner's publication, pins from its task's pin monitor
  // (pin_monitor.hpp), whose lease every read extends by lease_ns. Returns
  // the scan of the owning task the values come from (its count and planned
  // release, the logical time a reader tells the value's age by), or
  // nullopt while a pin's monitoring is only starting (no copy since a
  // lapsed lease: ask again after one period of the task) or for a task that
  // stopped unmonitored. Thread-safe; never waits for a scan.
  std::optional<ValueStamp> read_value(const CellRef& r, Cell* out, std::int64_t lease_ns = kMonitorLeaseNs);
  // Every block instance with its pins, by task then execution order (GET /blocks).
  std::vector<InstanceInfo> block_instances() const;

  bool open_drivers(std::string* error);
  void close_drivers();
  // A clean stop: each driver's stop_outputs with its safe outputs, then close().
  void stop_drivers();
  // The `safe:` values of the tags bound to a driver's output channels.
  std::vector<SafeOutput> safe_outputs(const DriverBinding& d) const;
  // The live value in a task's image: for the virtual clock's tools (one
  // thread is every task's) and what prepares a program before it runs.
  Cell* live_cell(const CellRef& r, ImageAccess a) const { return &tasks[r.task]->image(a)[r.cell]; }

 private:
  mutable std::mutex forces_mutex_;  // the registry below; never taken by a scan
  std::vector<ForceEntry> forces_;
  bool forces_closed_ = false;       // handed to the next program (online change)
  std::atomic<std::size_t> force_count_{0};
  std::atomic<std::uint64_t> forces_version_{0};
  // Adds a force found valid, under forces_mutex_ (force, hand_forces_to).
  ForceResult add_force(std::string ref, const CellRef& r, Cell value, bool queue);
};

}  // namespace syncplc
