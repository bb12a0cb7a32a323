// A task: its configuration, its process image, its resolved program (blocks
// in execution order with their connections as cell copies), and the scan.
//
// One scan (architecture.md, "The data path"):
//   1. apply queued writes        (HMI/Modbus/test writes, in arrival order)
//   2. latch inputs               (other tasks' snapshots, then drivers)
//   3. execute blocks in order    (each block: copy its inputs, execute, copy its outputs)
//   4. write outputs              (drivers)
//   5. publish                    (snapshot of the task's own tags)
//   6. account                    (exec time, start jitter, overruns, watchdog)
// Steps 1–4 are scan(), 5 is publish(), 6 is account(). Both schedulers call
// exactly these, so virtual-time tests exercise the real-time code path.
#pragma once

#include <atomic>
#include <cstdint>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "runtime/core/block.hpp"
#include "runtime/core/force_table.hpp"
#include "runtime/core/histogram.hpp"
#include "runtime/core/image_access.hpp"
#include "runtime/core/instance_signature.hpp"
#include "runtime/core/io_driver.hpp"
#include "runtime/core/pin_monitor.hpp"
#include "runtime/core/spsc_ring.hpp"
#include "runtime/core/snapshot_channel.hpp"
#include "runtime/core/trend_fold.hpp"

namespace syncplc {

enum class WatchdogAction : std::uint8_t { Log, Stop, SafeStop };
enum class MissedCycles : std::uint8_t { Skip, Immediate };

std::string_view watchdog_action_name(WatchdogAction a);
std::string_view missed_cycles_name(MissedCycles m);

struct TaskConfig {
  std::string name;
  std::int64_t period_ns = 1'000'000;
  std::int64_t phase_ns = 0;
  int priority = 50;            // SCHED_FIFO priority 1..99; higher runs first
  bool watchdog = false;
  std::int64_t watchdog_ns = 0;  // a scan longer than this is a watchdog overrun
  int sensitivity = 1;          // the n-th consecutive overrun trips; one scan > n × time trips at once
  WatchdogAction action = WatchdogAction::Log;
  MissedCycles missed = MissedCycles::Skip;
  int cpu = -1;                 // pin the real-time thread to this CPU (-1: any)
  std::size_t write_queue = 1024;  // capacity of the queued-write ring
};

// A copy of n cells inside the task's image: a connection.
struct CellCopy {
  std::uint32_t src = 0;
  std::uint32_t dst = 0;
  std::uint32_t n = 1;
};

enum class WriteKind : std::uint8_t {
  Write,    // value into cell
  Force,    // hold cell at value (force_table.hpp); point, block and restore say where and how
  Unforce,  // release cell
};

// A write queued by a non-real-time thread: applied at the next scan start.
// Forces travel the same way, as commands (Program::force builds them).
struct QueuedWrite {
  std::uint32_t cell = 0;  // index in the owning task's image
  Cell value;
  WriteKind kind = WriteKind::Write;
  ForcePoint point = ForcePoint::Tag;
  bool restore = false;
  std::uint32_t block = kNoBlock;
};

struct TaskStats {
  Histogram exec;    // ns from scan start to end of step 4
  Histogram jitter;  // ns, actual start minus planned release
  std::atomic<std::uint64_t> scans{0};
  std::atomic<std::uint64_t> overruns{0};        // scans that ended after the next release
  std::atomic<std::uint64_t> skipped{0};         // grid points that got no scan
  std::atomic<std::uint64_t> watchdog_trips{0};
  std::atomic<std::uint64_t> writes_applied{0};
  std::atomic<std::uint64_t> events_dropped{0};
  // Inbound reads that found not even the producer's previous scan visible
  // (this scan started more than a producer period late): the values then
  // differ from virtual time's.
  std::atomic<std::uint64_t> late_reads{0};
  std::atomic<std::int64_t> last_exec_ns{0};

  struct Summary {
    std::uint64_t scans, overruns, skipped, watchdog_trips, writes_applied, events_dropped, late_reads;
    Histogram::Summary exec, jitter;
  };
  Summary summary() const;
  // Online change: the new task's statistics go on from the old task's.
  void continue_from(const TaskStats& old) noexcept;
};

struct TaskHandover;

// One block instance placed in a task.
struct BlockInstance {
  std::string name;
  const BlockTypeInfo* type = nullptr;
  IecType datatype = IecType::LREAL;
  // Structure, parameters, wiring and state layout as loaded: what online
  // change, retain and the historian compare (instance_signature.hpp).
  InstanceSignature signature;
  std::unique_ptr<Block> block;
  std::vector<Cell*> pins;          // bound pin cells, by declaration index
  std::vector<std::uint32_t> pin_cell;  // image index of each pin (its first element)
  std::vector<std::uint32_t> pin_length;  // elements of each pin: 1, or n for an array pin
  std::vector<CellCopy> copy_in;    // before execute (for a unit delay: before end_of_scan)
  std::vector<CellCopy> copy_out;   // after execute: output -> tags
  std::uint32_t retain_cell = 0;    // retained state: image[retain_cell, + retain_length), published
  std::uint32_t retain_length = 0;  // 0: not retained
  // Active forces at this block's points (force_table.hpp): 0 takes the
  // scan's plain path, so a program without forces pays one branch per block.
  std::uint32_t forces = 0;
  // Its links (BlockTypeInfo::links): link index -> the target's position
  // in the task's execution order (the target runs first).
  struct Link {
    std::int32_t link = 0;
    std::uint32_t element = 0;  // of a list link
    std::uint32_t target = 0;
  };
  std::vector<Link> links;
};

// Values of other tasks' tags, taken from their snapshot channels at the
// consumer's release instant (logical execution time, snapshot_channel.hpp).
struct Inbound {
  SnapshotChannel* channel = nullptr;
  std::uint32_t producer = 0;
  std::vector<CellCopy> copies;  // src: producer's owned range; dst: this image
};

class Task : private EventSink {
 public:
  Task(std::uint16_t index, TaskConfig cfg);
  Task(const Task&) = delete;
  Task& operator=(const Task&) = delete;

  const TaskConfig& config() const { return cfg_; }
  std::uint16_t index() const { return index_; }

  // --- built by the loader ---------------------------------------------------
  // The process image, [owned tags | foreign tag copies | pins]: the task's
  // real-time state, reachable only with an ImageAccess (image_access.hpp).
  std::vector<Cell>& image(ImageAccess) noexcept { return image_; }
  const std::vector<Cell>& image(ImageAccess) const noexcept { return image_; }
  std::size_t image_cells() const noexcept { return image_.size(); }
  std::uint32_t owned_cells = 0;    // published range: image[0, owned_cells)
  std::vector<BlockInstance> blocks;  // execution order; unit delays first
  // Every block's links given their targets (Block::link): after the load,
  // and after an online change swapped instances. No allocation.
  void relink() noexcept;
  std::size_t unit_delays = 0;      // blocks[0, unit_delays) are unit delays
  std::vector<std::uint32_t> retained_blocks;  // positions in blocks of instances declared retain
  std::vector<Inbound> inbound;
  std::vector<IoDriver*> drivers;
  std::vector<std::pair<std::uint32_t, Cell>> safe_values;  // cell, value on SafeStop
  // Snapshot channels this task publishes into: [0] is read by non-real-time
  // threads (under external_mutex; newest publication only), the others each
  // by one consuming task (with the publication before, for LET reads).
  std::vector<std::unique_ptr<SnapshotChannel>> channels;
  std::mutex external_mutex;        // serialises readers of channels[0]; never taken by the scan
  TrendFold trends;                 // the trended elements of its owned tags (trend_fold.hpp)
  std::size_t force_capacity = kDefaultMaxForces;  // the project's max_forces, sized by finalize()

  // Sizes queues and channels and binds pins. Call once, after the image is final.
  void finalize();

  // --- the scan ----------------------------------------------------------------
  void scan(ScanContext& ctx) noexcept;   // steps 1–4
  void publish() noexcept;                // step 5
  // Step 6: records the scan and returns the grid index of the next release.
  // end_ns is the time step 4 finished. Applies the watchdog action.
  struct Next {
    std::int64_t index;  // grid index of the next scan's planned release
    bool stop;           // the watchdog stopped the task
  };
  Next account(std::int64_t grid_index, std::int64_t planned_ns, std::int64_t start_ns, std::int64_t end_ns) noexcept;
  std::int64_t release_ns(std::int64_t grid_index) const { return cfg_.phase_ns + grid_index * cfg_.period_ns; }

  // Resets timing state (not the image) before a run.
  void reset_timing();
  bool stopped() const { return stopped_.load(std::memory_order_acquire); }
  // From the supervisor (supervisor.hpp), for a scan that does not end: the
  // task counts as stopped (writes to it are refused) and the runner starts
  // no further scan of it, should the scan ever end.
  void stop_from_supervisor() { stopped_.store(true, std::memory_order_release); }

  // --- other threads -----------------------------------------------------------
  // Queues writes to be applied together at the start of the next scan; false
  // (nothing queued) when the queue lacks room. Thread-safe, never blocks the scan.
  bool enqueue(const QueuedWrite* writes, std::size_t n);
  // One request's writes to several tasks: every batch is queued, or none
  // (false) when one task's queue lacks room. Batches name distinct tasks in
  // ascending index order (the order their locks are taken in).
  struct WriteBatch {
    Task* task;
    const QueuedWrite* writes;
    std::size_t n;
  };
  static bool enqueue_all(const WriteBatch* batches, std::size_t count);
  // Copies the latest published values of the owned cells [first, first+n).
  void read_published(std::uint32_t first, std::uint32_t n, Cell* out);
  // Calls f(const Cell* owned) with the latest published snapshot, held for
  // the call: several reads from one snapshot are never torn between scans.
  template <class F>
  void with_published(F&& f) {
    std::lock_guard lock(external_mutex);
    f(static_cast<const Cell*>(channels[0]->latest()));
  }
  // The stamp of the newest publication: its scan count and logical times.
  SnapshotStamp published_stamp() {
    std::lock_guard lock(external_mutex);
    SnapshotStamp s;
    channels[0]->latest(&s);
    return s;
  }
  // Snapshots published so far. A write enqueued when this read n is in the
  // snapshot of publication n + 2 at the latest (a scan may be between its
  // write step and its publication when the write arrives).
  std::uint64_t published_count() const { return published_.load(std::memory_order_acquire); }
  // Takes the task's events (the consumer side of its event ring).
  bool pop_event(Event& e) { return events_.pop(e); }
  // Live pin values for non-real-time readers (pin_monitor.hpp).
  PinMonitor& pin_monitor() noexcept { return monitor_; }

  // --- forces (force_table.hpp) ----------------------------------------------------
  // A Force or Unforce command, applied by the thread that scans this task
  // (at its scan start, or by its predecessor's thread during an online
  // change), or by the main thread before the task runs. Never allocates.
  void apply_force_command(const QueuedWrite& w) noexcept;
  // The task's forces as it holds them: only its scanning thread may call it
  // while it runs (tests in virtual time; readers use Program::forces()).
  const ForceTable& force_table() const noexcept { return forces_; }

  // --- online change (program_change.hpp) -----------------------------------------
  // From the moment the main thread sets a handover until this task's switch,
  // every publication of this (old) task is also made, in the new task's
  // layout, into the new task's channels: consumers that switch first read
  // the right values (program_change.hpp). Set before the switch instant.
  void set_handover(TaskHandover* h) noexcept { handover_.store(h, std::memory_order_release); }
  TaskHandover* handover() const noexcept { return handover_.load(std::memory_order_acquire); }
  // A publication made for this (new) task by its predecessor: the image's
  // owned cells as the handover left them, with the predecessor's stamp. It
  // counts as this task's publication: the predecessor applied this task's
  // queued writes before it (TaskHandover::apply_successor_writes).
  void publish_for_predecessor(const SnapshotStamp& s) noexcept;
  // The scan count and time base an online change carries over.
  std::uint64_t scan_count() const noexcept { return scan_count_; }
  void continue_scan_count(std::uint64_t n) noexcept { scan_count_ = n; }
  // Pops the task's queued writes (the switch moves an old task's into the new one).
  bool pop_write(QueuedWrite& w) noexcept { return writes_.pop(w); }

  TaskStats stats;

 private:
  void push(const Event& e) noexcept override;  // EventSink for blocks
  void apply_writes() noexcept;
  void run_block(std::size_t i, ScanContext& ctx) noexcept;         // the plain path
  void run_forced_block(std::size_t i, ScanContext& ctx) noexcept;  // a block with forces at its points
  void apply_safe_state(ScanContext& ctx) noexcept;
  // Ends the task after this scan (a watchdog's stop or safe_stop, a
  // driver's request): the safe state first when `safe`, then the event.
  void stop_now(std::int64_t planned, bool safe, const char* why) noexcept;

  std::uint16_t index_;
  TaskConfig cfg_;
  std::vector<Cell> image_;
  SpscRing<QueuedWrite> writes_;
  std::mutex write_producers_;  // taken only by writers (non-real-time threads)
  SpscRing<Event> events_;
  ForceTable forces_;
  PinMonitor monitor_;
  std::vector<std::uint64_t> last_fault_scan_;  // per block: suppresses repeats
  std::uint64_t scan_count_ = 0;
  std::int64_t now_ = 0;
  int wd_consecutive_ = 0;
  bool overrun_series_ = false;
  const char* stop_request_ = nullptr;  // a driver's ScanContext::request_stop, taken by account()
  std::atomic<bool> stopped_{false};
  std::atomic<std::uint64_t> published_{0};
  std::atomic<TaskHandover*> handover_{nullptr};
};

}  // namespace syncplc
