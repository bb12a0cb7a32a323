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
  std::string type;             // block type name
  std::uint32_t layout = 1;     // Block::retain_layout()
  std::uint16_t task = 0;
  std::uint32_t position = 0;   // in the task's execution order
  std::uint32_t cell = 0;
  std::uint32_t length = 0;
  bool persistent = false;
};

class Program {
 public:
  std::string name;
  std::string version;
  std::string file;
  std::uint64_t seed = 0;
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
  // Instance name -> (task, position in execution order).
  std::map<std::string, std::pair<std::uint16_t, std::uint32_t>> instances;

  // Non-real-time side. read_tag: the owner's latest published value.
  void read_tag(const Tag& tag, Cell* out) const;
  // Queues a write of `count` elements starting at `element`; applied at the
  // owner's next scan start. False when the owner's queue is full.
  bool write_tag(const Tag& tag, std::uint32_t element, const Cell* values, std::uint32_t count) const;

  bool open_drivers(std::string* error);
  void close_drivers();
  // A clean stop: each driver's stop_outputs with its safe outputs, then close().
  void stop_drivers();
  // The `safe:` values of the tags bound to a driver's output channels.
  std::vector<SafeOutput> safe_outputs(const DriverBinding& d) const;
  // Virtual-time tools (single thread): the live value in a task's image.
  Cell* live_cell(const CellRef& r) const { return &tasks[r.task]->image[r.cell]; }
};

}  // namespace syncplc
