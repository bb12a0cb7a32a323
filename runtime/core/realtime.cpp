#include "runtime/core/realtime.hpp"

#include <pthread.h>
#include <sched.h>
#include <sys/mman.h>
#include <time.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <mutex>

#include "runtime/core/monotonic_clock.hpp"
#include "runtime/core/task_switch.hpp"

namespace syncplc {
namespace {

timespec to_timespec(std::int64_t ns) {
  timespec ts;
  ts.tv_sec = static_cast<time_t>(ns / 1'000'000'000);
  ts.tv_nsec = static_cast<long>(ns % 1'000'000'000);
  return ts;
}

// Touch the stack once so later scans take no page faults.
void prefault_stack() {
  constexpr std::size_t kBytes = 256 * 1024;
  [[maybe_unused]] volatile unsigned char buf[kBytes];  // written only to fault its pages in
  for (std::size_t i = 0; i < kBytes; i += 4096) buf[i] = 0;
}

}  // namespace

std::int64_t RealtimeRunner::monotonic_ns() { return syncplc::monotonic_ns(); }

RealtimeRunner::RealtimeRunner(Program& program, Options options) : program_(&program), options_(options) {}

RealtimeRunner::~RealtimeRunner() {
  request_stop();
  join();
}

// Sanitizers reserve terabytes of shadow memory: locking it all would fail or
// exhaust RAM, so sanitizer builds never call mlockall.
#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
constexpr bool kSanitizerBuild = true;
#else
constexpr bool kSanitizerBuild = false;
#endif

void RealtimeRunner::warn(std::string w) {
  std::lock_guard lock(warnings_mutex_);
  warnings_.push_back(std::move(w));
}

void RealtimeRunner::start() {
  if (kSanitizerBuild && options_.lock_memory) {
    warn("sanitizer build: memory is not locked (mlockall skipped)");
  } else if (options_.lock_memory && mlockall(MCL_CURRENT | MCL_FUTURE) != 0) {
    warn(std::string("mlockall failed (") + std::strerror(errno) +
         "): page faults may delay scans; run as root or raise RLIMIT_MEMLOCK");
  }
  if (options_.cpu_latency_us >= 0) {
    std::string err;
    if (!cpu_latency_.hold(options_.cpu_latency_us, &err))
      warn("cannot hold /dev/cpu_dma_latency at " + std::to_string(options_.cpu_latency_us) + " us (" + err +
           "): idle CPUs may wake tasks late");
  }
  stop_.store(false);
  for (auto& t : program_->tasks) t->reset_timing();
  // Both clocks read back to back; the realtime epoch is where the grid sits
  // on CLOCK_REALTIME, the monotonic one where the threads sleep to.
  const std::int64_t rt = realtime_ns(), mono = monotonic_ns();
  std::int64_t epoch_rt = rt + options_.start_delay_ns;
  if (options_.align_ns > 0) epoch_rt = (epoch_rt / options_.align_ns + 1) * options_.align_ns;
  epoch_ = mono + (epoch_rt - rt);
  epoch_realtime_ = epoch_rt;
  program_->epoch_ns.store(epoch_, std::memory_order_release);
  std::lock_guard lock(workers_mutex_);
  by_task_.clear();
  for (auto& t : program_->tasks) {
    Worker& w = workers_.emplace_back();
    w.task.store(t.get());
    by_task_.push_back(&w);
  }
  for (auto* w : by_task_) w->thread = std::thread([this, w] { task_thread(*w, Start{}); });
}

void RealtimeRunner::join() {
  std::lock_guard lock(workers_mutex_);
  for (auto& w : workers_)
    if (w.thread.joinable()) w.thread.join();
  workers_.clear();
  by_task_.clear();
  cpu_latency_.release();
}

std::int64_t RealtimeRunner::scan_running_ns(std::size_t task) const {
  std::lock_guard lock(workers_mutex_);
  if (task >= by_task_.size()) return 0;
  std::int64_t s = by_task_[task]->scan_started.load(std::memory_order_relaxed);
  return s < 0 ? 0 : std::max<std::int64_t>(0, monotonic_ns() - epoch_ - s);
}

std::vector<RealtimeRunner::ThreadView> RealtimeRunner::threads() const {
  std::lock_guard lock(workers_mutex_);
  std::vector<ThreadView> out;
  out.reserve(workers_.size());
  const std::int64_t now = monotonic_ns() - epoch_;
  for (const auto& w : workers_) {
    const std::int64_t s = w.scan_started.load(std::memory_order_acquire);
    out.push_back({&w, w.task.load(std::memory_order_acquire), s < 0 ? 0 : std::max<std::int64_t>(0, now - s),
                   w.alive.load(std::memory_order_acquire)});
  }
  return out;
}

bool RealtimeRunner::running() const {
  std::lock_guard lock(workers_mutex_);
  for (const auto& w : workers_) {
    if (!w.alive.load(std::memory_order_acquire)) continue;
    const Task* t = w.task.load(std::memory_order_acquire);
    if (t && !t->stopped()) return true;
  }
  return false;
}

bool RealtimeRunner::threads_alive() const {
  std::lock_guard lock(workers_mutex_);
  for (const auto& w : workers_)
    if (w.alive.load(std::memory_order_acquire)) return true;
  return false;
}

std::vector<std::string> RealtimeRunner::warnings() const {
  std::lock_guard lock(warnings_mutex_);
  return warnings_;
}

void RealtimeRunner::begin_change(ProgramChange& change) {
  std::lock_guard lock(workers_mutex_);
  change_ = &change;
  change.to->epoch_ns.store(epoch_, std::memory_order_release);  // one time axis for both programs
  // Added tasks: a thread each, asleep until its first release at or after T.
  std::vector<std::pair<Worker*, Start>> added;
  for (std::size_t i = 0; i < change.to->tasks.size(); ++i) {
    TaskHandover* h = change.for_new_task(i);
    if (h->from) continue;
    Task& t = *h->to;
    t.reset_timing();
    const auto& c = t.config();
    Start st;
    st.k = std::max<std::int64_t>(0, (change.switch_ns - c.phase_ns + c.period_ns - 1) / c.period_ns);
    st.prev_planned = t.release_ns(st.k) - c.period_ns;
    st.perform = h;
    Worker& w = workers_.emplace_back();
    w.task.store(&t);
    added.emplace_back(&w, st);
  }
  begin_mirroring(change);  // the running threads see their handovers from here on
  for (auto& a : added) {  // not a structured binding: clang 14 cannot capture one (the fuzzers build with clang)
    Worker* w = a.first;
    const Start s = a.second;
    w->thread = std::thread([this, w, s] { task_thread(*w, s); });
  }
}

bool RealtimeRunner::change_complete() const {
  if (!change_) return true;
  for (const auto& h : change_->handovers)
    if (!h->done.load(std::memory_order_acquire)) return false;
  return true;
}

void RealtimeRunner::finish_change() {
  std::lock_guard lock(workers_mutex_);
  if (!change_) return;
  std::vector<Worker*> next;
  for (const auto& t : change_->to->tasks)
    for (auto& w : workers_)
      if (w.task.load(std::memory_order_acquire) == t.get()) next.push_back(&w);
  // Threads of removed tasks have returned (their handover is done).
  for (auto& w : workers_)
    if (std::find(next.begin(), next.end(), &w) == next.end() && w.thread.joinable()) w.thread.join();
  workers_.remove_if([&](const Worker& w) { return std::find(next.begin(), next.end(), &w) == next.end(); });
  by_task_.clear();
  for (const auto& t : change_->to->tasks)
    for (auto& w : workers_)
      if (w.task.load(std::memory_order_acquire) == t.get()) by_task_.push_back(&w);
  program_ = change_->to;
  change_ = nullptr;
}

void RealtimeRunner::configure_thread(const TaskConfig& cfg) {
  {
    std::string name = cfg.name.substr(0, 15);
    pthread_setname_np(pthread_self(), name.c_str());
  }
  if (options_.fifo) {
    sched_param sp{};
    sp.sched_priority = std::clamp(cfg.priority, sched_get_priority_min(SCHED_FIFO), sched_get_priority_max(SCHED_FIFO));
    int rc = pthread_setschedparam(pthread_self(), SCHED_FIFO, &sp);
    if (rc != 0)
      warn("task " + cfg.name + ": cannot use SCHED_FIFO priority " + std::to_string(sp.sched_priority) + " (" +
           std::strerror(rc) + "); running at normal priority, expect more jitter");
  }
  cpu_set_t set;
  CPU_ZERO(&set);
  if (cfg.cpu >= 0) {
    CPU_SET(cfg.cpu, &set);
  } else {
    for (int c = 0; c < CPU_SETSIZE; ++c) CPU_SET(c, &set);  // an online change may unpin a task
  }
  int rc = pthread_setaffinity_np(pthread_self(), sizeof set, &set);
  if (rc != 0 && cfg.cpu >= 0)
    warn("task " + cfg.name + ": cannot pin to CPU " + std::to_string(cfg.cpu) + " (" + std::strerror(rc) + ")");
}

void RealtimeRunner::task_thread(Worker& w, Start start) {
  Task* task = w.task.load(std::memory_order_acquire);
  configure_thread(task->config());
  prefault_stack();
  if (start.perform) start.perform->perform();

  std::int64_t k = start.k;
  // The first scan's dt is one period, as in virtual time.
  std::int64_t prev_planned = start.perform ? start.prev_planned : task->release_ns(k) - task->config().period_ns;
  std::uint64_t n = 0;
  constexpr std::int64_t kStopPoll = 100'000'000;  // a long period still notices a stop within 100 ms
  bool stopped = false;  // by the watchdog: wait for an online change (or the end)
  std::int64_t last_end = 0;  // when the last scan ended (ns since the epoch)
  TaskHandover* switched = start.perform;  // its first scan's lateness is recorded
  while (!stop_.load(std::memory_order_acquire)) {
    std::int64_t planned = task->release_ns(k);
    if (options_.duration_ns > 0 && planned >= options_.duration_ns) break;  // --duration, counted from the epoch
    // Online change: between two scans, as task_switch.hpp says (the same
    // rule as the virtual clock's).
    if (TaskHandover* h = task->handover(); h && h->from == task) {
      const OldGrid old{k, prev_planned, last_end, stopped};
      if (switch_due(*h, old)) {
        if (!h->to) {
          h->perform();
          h->finish();
          break;  // removed: its last scan was the one before T
        }
        const NewGrid next = new_grid(*h, old);
        const TaskConfig old_cfg = task->config();
        h->to->reset_timing();
        h->perform();
        task = h->to;
        switched = h;
        w.task.store(task, std::memory_order_release);
        k = next.k;
        prev_planned = next.prev_planned;
        if (next.skipped) task->stats.skipped.fetch_add(next.skipped, std::memory_order_relaxed);
        const auto& c = task->config();
        if (c.priority != old_cfg.priority || c.cpu != old_cfg.cpu || c.name != old_cfg.name) configure_thread(c);
        stopped = false;
        continue;
      }
    }
    if (stopped) {
      // Looks for a change that restarts it once a period (at most every
      // 100 ms): T is at least two periods ahead, so it switches in time
      // and its first new scan is not late.
      timespec ts = to_timespec(monotonic_ns() + std::min(kStopPoll, task->config().period_ns));
      clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, nullptr);
      continue;
    }
    const std::int64_t deadline = epoch_ + planned;
    bool stopping = false;
    for (;;) {
      std::int64_t now = monotonic_ns();
      if (now >= deadline) break;
      if (stop_.load(std::memory_order_acquire)) { stopping = true; break; }
      timespec ts = to_timespec(std::min(deadline, now + kStopPoll));
      while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, nullptr) == EINTR) {
      }
    }
    if (stopping) break;
    const std::int64_t begin = monotonic_ns() - epoch_;
    w.scan_started.store(begin, std::memory_order_relaxed);
    if (switched) {
      // The last use of the handover: the main thread may destroy it once finished.
      switched->first_scan_late_ns.store(begin - planned, std::memory_order_relaxed);
      switched->finish();
      switched = nullptr;
    }
    ScanContext ctx;
    ctx.now_ns = planned;
    ctx.dt_ns = planned - prev_planned;
    ctx.scan = n;
    ctx.virtual_time = false;
    ctx.realtime_ns = epoch_realtime_ + planned;
    task->scan(ctx);
    const std::int64_t end = monotonic_ns() - epoch_;
    last_end = end;
    w.scan_started.store(-1, std::memory_order_relaxed);
    task->publish();
    auto next = task->account(k, planned, begin, end);
    prev_planned = planned;
    ++n;
    k = next.index;
    // task->stopped(): the supervisor gave up on a scan that did not end.
    if (next.stop || task->stopped()) stopped = true;
  }
  if (switched) switched->finish();  // stopped before the new task's first scan
  w.alive.store(false, std::memory_order_release);
}

}  // namespace syncplc
