#include "runtime/core/task.hpp"

#include "runtime/core/program_change.hpp"

#include <algorithm>
#include <cstring>

#include "runtime/core/finite_guard.hpp"

namespace syncplc {
namespace {

// Pin connections are one cell: copy those inline; memcpy (a library call
// for a run-time length) only for arrays.
inline void run_copies(Cell* img, const std::vector<CellCopy>& copies) noexcept {
  for (const auto& c : copies) {
    if (c.n == 1) img[c.dst] = img[c.src];
    else std::memcpy(static_cast<void*>(img + c.dst), img + c.src, c.n * sizeof(Cell));
  }
}

}  // namespace

std::string_view watchdog_action_name(WatchdogAction a) {
  switch (a) {
    case WatchdogAction::Log: return "log";
    case WatchdogAction::Stop: return "stop";
    case WatchdogAction::SafeStop: return "safe_stop";
  }
  return "?";
}

std::string_view missed_cycles_name(MissedCycles m) {
  return m == MissedCycles::Skip ? "skip" : "immediate";
}

TaskStats::Summary TaskStats::summary() const {
  Summary s;
  s.scans = scans.load(std::memory_order_relaxed);
  s.overruns = overruns.load(std::memory_order_relaxed);
  s.skipped = skipped.load(std::memory_order_relaxed);
  s.watchdog_trips = watchdog_trips.load(std::memory_order_relaxed);
  s.writes_applied = writes_applied.load(std::memory_order_relaxed);
  s.events_dropped = events_dropped.load(std::memory_order_relaxed);
  s.late_reads = late_reads.load(std::memory_order_relaxed);
  s.exec = exec.summary();
  s.jitter = jitter.summary();
  return s;
}

void TaskStats::continue_from(const TaskStats& o) noexcept {
  exec.continue_from(o.exec);
  jitter.continue_from(o.jitter);
  auto carry = [](std::atomic<std::uint64_t>& to, const std::atomic<std::uint64_t>& from) {
    to.store(from.load(std::memory_order_relaxed), std::memory_order_relaxed);
  };
  carry(scans, o.scans);
  carry(overruns, o.overruns);
  carry(skipped, o.skipped);
  carry(watchdog_trips, o.watchdog_trips);
  carry(writes_applied, o.writes_applied);
  carry(events_dropped, o.events_dropped);
  carry(late_reads, o.late_reads);
  last_exec_ns.store(o.last_exec_ns.load(std::memory_order_relaxed), std::memory_order_relaxed);
}

Task::Task(std::uint16_t index, TaskConfig cfg) : index_(index), cfg_(std::move(cfg)) {}

void Task::finalize() {
  writes_.reset(cfg_.write_queue);
  events_.reset(256);
  last_fault_scan_.assign(blocks.size(), 0);
  for (auto& b : blocks) {
    b.pins.clear();
    for (auto idx : b.pin_cell) b.pins.push_back(&image_[idx]);
    b.block->bind_pins(b.pins.data());
  }
  for (auto& ch : channels) {
    ch->resize(owned_cells);
    ch->fill(image_.data());
  }
  forces_.reserve(force_capacity);
  // Pins are the image's last part (the loader lays them out after the tags and copies).
  auto first = static_cast<std::uint32_t>(image_.size());
  for (auto& b : blocks) {
    b.forces = 0;
    if (!b.pin_cell.empty()) first = std::min(first, *std::min_element(b.pin_cell.begin(), b.pin_cell.end()));
  }
  monitor_.resize(first, static_cast<std::uint32_t>(image_.size()) - first, image_.data());
}

void Task::reset_timing() {
  scan_count_ = 0;
  wd_consecutive_ = 0;
  overrun_series_ = false;
  stop_request_ = nullptr;
  stopped_.store(false, std::memory_order_release);
}

void Task::push(const Event& e) noexcept {
  // A block that faults every scan reports once per series of faulting scans.
  if (e.kind == EventKind::BlockFault && e.block >= 0 &&
      static_cast<std::size_t>(e.block) < last_fault_scan_.size()) {
    auto& last = last_fault_scan_[static_cast<std::size_t>(e.block)];  // scan + 1, 0 = never
    const std::uint64_t cur = scan_count_ + 1;
    bool repeat = last != 0 && (last == cur || last + 1 == cur);
    last = cur;
    if (repeat) return;
  }
  Event stamped = e;
  stamped.scan = scan_count_;
  if (!events_.push(stamped)) stats.events_dropped.fetch_add(1, std::memory_order_relaxed);
}

void Task::apply_writes() noexcept {
  QueuedWrite w;
  std::uint64_t n = 0;
  while (writes_.pop(w)) {
    if (w.kind != WriteKind::Write) [[unlikely]] {
      apply_force_command(w);
      continue;
    }
    image_[w.cell] = w.value;
    ++n;
  }
  // During an online change HMIs already write to the new program: its
  // queue is applied here, so a write takes effect at the next scan as ever.
  if (TaskHandover* h = handover_.load(std::memory_order_acquire)) n += h->apply_successor_writes(image_.data());
  if (n) stats.writes_applied.fetch_add(n, std::memory_order_relaxed);
}

void Task::apply_force_command(const QueuedWrite& w) noexcept {
  if (w.kind == WriteKind::Force) {
    ForceSlot slot;
    slot.cell = w.cell;
    slot.block = w.block;
    slot.point = w.point;
    slot.restore = w.restore;
    slot.value = w.value;
    bool added = false;
    // Full cannot happen: Program::force admits no more than the table holds.
    if (forces_.set(slot, image_.data(), &added) && added && w.block < blocks.size()) ++blocks[w.block].forces;
  } else if (w.kind == WriteKind::Unforce) {
    ForceSlot gone;
    if (forces_.clear(w.cell, image_.data(), &gone) && gone.block < blocks.size()) --blocks[gone.block].forces;
  }
}

void Task::run_block(std::size_t i, ScanContext& ctx) noexcept {
  Cell* img = image_.data();
  auto& b = blocks[i];
  if (i >= unit_delays) run_copies(img, b.copy_in);
  ctx.block = static_cast<std::int32_t>(i);
  execute_guarded(*b.block, ctx);  // finite inputs, tuning, ENO (finite_guard.hpp)
  run_copies(img, b.copy_out);
}

void Task::run_forced_block(std::size_t i, ScanContext& ctx) noexcept {
  Cell* img = image_.data();
  auto& b = blocks[i];
  const auto k = static_cast<std::uint32_t>(i);
  if (i >= unit_delays) {
    run_copies(img, b.copy_in);
    forces_.apply(img, ForcePoint::PinIn, k);   // the block sees its forced inputs
  }
  ctx.block = static_cast<std::int32_t>(i);
  execute_guarded(*b.block, ctx);
  forces_.apply(img, ForcePoint::PinOut, k);    // its copies take the forced outputs
  run_copies(img, b.copy_out);
  forces_.apply(img, ForcePoint::BlockTag, k);  // later readers of its tags see the forced value
}

void Task::scan(ScanContext& ctx) noexcept {
  ctx.task = index_;
  ctx.events = this;
  now_ = ctx.now_ns;
  Cell* img = image_.data();

  apply_writes();                                       // 1 (force commands too)
  const bool forced = !forces_.empty();
  if (forced) [[unlikely]] forces_.apply_all(img);      // 1: outside writes to a forced element change nothing
  for (auto& in : inbound) {                            // 2: other tasks' tags, as visible at this release
    bool late = false;
    const Cell* src = in.channel->read_at(ctx.now_ns, &late);
    if (late) stats.late_reads.fetch_add(1, std::memory_order_relaxed);
    for (const auto& c : in.copies) std::memcpy(static_cast<void*>(img + c.dst), src + c.src, c.n * sizeof(Cell));
  }
  for (auto* d : drivers) d->latch_inputs(ctx);         // 2: field inputs
  if (forced && forces_.has_driver_inputs()) [[unlikely]] forces_.apply(img, ForcePoint::Driver);

  const std::size_t n = blocks.size();                  // 3
  for (std::size_t i = 0; i < n; ++i) {
    if (blocks[i].forces == 0) [[likely]] run_block(i, ctx);
    else run_forced_block(i, ctx);
  }
  for (std::size_t i = 0; i < unit_delays; ++i) {       // unit delays take this scan's input
    run_copies(img, blocks[i].copy_in);
    if (blocks[i].forces != 0) [[unlikely]] forces_.apply(img, ForcePoint::PinIn, static_cast<std::uint32_t>(i));
    ctx.block = static_cast<std::int32_t>(i);
    end_of_scan_guarded(*blocks[i].block, ctx);
  }
  ctx.block = -1;
  for (auto k : retained_blocks)                        // retained block state, published with the tags
    blocks[k].block->save_retain(img + blocks[k].retain_cell);

  for (auto* d : drivers) d->write_outputs(ctx);        // 4 (forced tags bound to outputs hold their forced value)
  if (ctx.stop_request) stop_request_ = ctx.stop_request;  // acted on by account(), after the scan is recorded
  if (!trends.empty()) trends.fold(img, ctx.now_ns);    // the historian's buckets see every scan
  ++scan_count_;
}

void Task::publish() noexcept {
  // LET: this scan's outputs are visible from its next grid point on.
  const SnapshotStamp stamp{scan_count_, now_, now_ + cfg_.period_ns};
  for (auto& ch : channels) ch->publish(image_.data(), stamp);
  monitor_.publish(image_.data(), scan_count_, now_);  // pins, only while someone monitors (pin_monitor.hpp)
  if (TaskHandover* h = handover_.load(std::memory_order_acquire)) h->mirror(image_.data(), stamp);
  published_.fetch_add(1, std::memory_order_release);
}

void Task::publish_for_predecessor(const SnapshotStamp& s) noexcept {
  for (auto& ch : channels) ch->publish(image_.data(), s);
  published_.fetch_add(1, std::memory_order_release);  // holds the writes applied for this task (Modbus FC 23 waits)
}

Task::Next Task::account(std::int64_t k, std::int64_t planned, std::int64_t start, std::int64_t end) noexcept {
  const std::int64_t exec = end - start;
  stats.exec.record(exec);
  stats.jitter.record(start - planned);
  stats.last_exec_ns.store(exec, std::memory_order_relaxed);
  stats.scans.fetch_add(1, std::memory_order_relaxed);

  // Next release on this task's own grid: never a burst of catch-up scans.
  Next next{k + 1, false};
  if (end > release_ns(k + 1)) {
    stats.overruns.fetch_add(1, std::memory_order_relaxed);
    // Say why: a scan longer than its period, or one that started so late
    // (a busy CPU, an earlier overrun) that a short scan still ended past
    // the next release.
    const std::int64_t late = start - planned;
    if (!overrun_series_) {
      if (exec <= cfg_.period_ns && late > 0)
        push(Event{planned, index_, -1, EventKind::ScanLate, "scan started late and ended after its next release",
                   static_cast<double>(late) * 1e-9});
      else
        push(Event{planned, index_, -1, EventKind::ScanOverrun, "scan overran its period", static_cast<double>(exec) * 1e-9});
    }
    overrun_series_ = true;
    const std::int64_t since = end - cfg_.phase_ns;
    if (cfg_.missed == MissedCycles::Skip) {
      next.index = (since + cfg_.period_ns - 1) / cfg_.period_ns;  // first grid point at or after end
    } else {
      next.index = since / cfg_.period_ns;  // the latest missed grid point, run once at once
    }
    stats.skipped.fetch_add(static_cast<std::uint64_t>(next.index - (k + 1)), std::memory_order_relaxed);
  } else {
    overrun_series_ = false;
  }

  if (cfg_.watchdog) {
    bool over = exec > cfg_.watchdog_ns;
    wd_consecutive_ = over ? wd_consecutive_ + 1 : 0;
    bool trip = wd_consecutive_ >= cfg_.sensitivity ||
                (over && exec > cfg_.watchdog_ns * static_cast<std::int64_t>(cfg_.sensitivity));
    if (trip) {
      stats.watchdog_trips.fetch_add(1, std::memory_order_relaxed);
      push(Event{planned, index_, -1, EventKind::WatchdogTrip, "watchdog tripped", static_cast<double>(exec) * 1e-9});
      wd_consecutive_ = 0;
      if (cfg_.action != WatchdogAction::Log) {
        stop_now(planned, cfg_.action == WatchdogAction::SafeStop, "task stopped by its watchdog");
        next.stop = true;
      }
    }
  }
  if (stop_request_ && !next.stop) {
    // A driver's request (ScanContext::request_stop): the safe state, then stop, as safe_stop does.
    stop_now(planned, true, stop_request_);
    next.stop = true;
  }
  stop_request_ = nullptr;
  return next;
}

void Task::stop_now(std::int64_t planned, bool safe, const char* why) noexcept {
  if (safe) {
    ScanContext ctx;
    ctx.now_ns = planned;
    ctx.task = index_;
    ctx.events = this;
    apply_safe_state(ctx);
  }
  stopped_.store(true, std::memory_order_release);
  push(Event{planned, index_, -1, EventKind::TaskStopped, why, 0});
}

void Task::apply_safe_state(ScanContext& ctx) noexcept {
  for (const auto& [cell, value] : safe_values) image_[cell] = value;
  for (auto* d : drivers) d->write_outputs(ctx);
  publish();
  push(Event{ctx.now_ns, index_, -1, EventKind::SafeStateApplied, "outputs driven to their safe values", 0});
}

bool Task::enqueue(const QueuedWrite* writes, std::size_t n) {
  const WriteBatch one{this, writes, n};
  return enqueue_all(&one, 1);
}

bool Task::enqueue_all(const WriteBatch* batches, std::size_t count) {
  // With every producer lock held no other writer can take room, and a scan
  // only makes more: checked room stays room until the commits.
  for (std::size_t i = 0; i < count; ++i) batches[i].task->write_producers_.lock();
  bool room = true;
  for (std::size_t i = 0; i < count && room; ++i) room = batches[i].task->writes_.has_room(batches[i].n);
  if (room)
    for (std::size_t i = 0; i < count; ++i) {
      auto& ring = batches[i].task->writes_;
      for (std::size_t k = 0; k < batches[i].n; ++k) ring.stage(batches[i].writes[k]);
      ring.commit();
    }
  for (std::size_t i = count; i-- > 0;) batches[i].task->write_producers_.unlock();
  return room;
}

void Task::read_published(std::uint32_t first, std::uint32_t n, Cell* out) {
  with_published([&](const Cell* src) {
    if (n) std::memcpy(static_cast<void*>(out), src + first, n * sizeof(Cell));
  });
}

void Task::relink() noexcept {
  for (auto& b : blocks)
    for (const auto& l : b.links) b.block->link(l.link, l.element, *blocks[l.target].block);
}

}  // namespace syncplc
