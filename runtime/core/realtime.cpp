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
  volatile unsigned char buf[kBytes];
  for (std::size_t i = 0; i < kBytes; i += 4096) buf[i] = 0;
}

}  // namespace

std::int64_t RealtimeRunner::monotonic_ns() { return syncplc::monotonic_ns(); }

RealtimeRunner::RealtimeRunner(Program& program, Options options) : program_(program), options_(options) {}

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

void RealtimeRunner::start() {
  if (kSanitizerBuild && options_.lock_memory) {
    std::lock_guard lock(warnings_mutex_);
    warnings_.push_back("sanitizer build: memory is not locked (mlockall skipped)");
  } else if (options_.lock_memory && mlockall(MCL_CURRENT | MCL_FUTURE) != 0) {
    std::lock_guard lock(warnings_mutex_);
    warnings_.push_back(std::string("mlockall failed (") + std::strerror(errno) +
                        "): page faults may delay scans; run as root or raise RLIMIT_MEMLOCK");
  }
  if (options_.cpu_latency_us >= 0) {
    std::string err;
    if (!cpu_latency_.hold(options_.cpu_latency_us, &err)) {
      std::lock_guard lock(warnings_mutex_);
      warnings_.push_back("cannot hold /dev/cpu_dma_latency at " + std::to_string(options_.cpu_latency_us) + " us (" +
                          err + "): idle CPUs may wake tasks late");
    }
  }
  stop_.store(false);
  for (auto& t : program_.tasks) t->reset_timing();
  scan_started_ = std::make_unique<std::atomic<std::int64_t>[]>(program_.tasks.size());
  for (std::size_t i = 0; i < program_.tasks.size(); ++i) scan_started_[i].store(-1);
  epoch_ = monotonic_ns() + options_.start_delay_ns;
  alive_.store(static_cast<int>(program_.tasks.size()));
  for (std::size_t i = 0; i < program_.tasks.size(); ++i) threads_.emplace_back([this, i] { task_thread(i); });
}

void RealtimeRunner::join() {
  for (auto& t : threads_)
    if (t.joinable()) t.join();
  threads_.clear();
  cpu_latency_.release();
}

std::int64_t RealtimeRunner::scan_running_ns(std::size_t task) const {
  if (!scan_started_ || task >= program_.tasks.size()) return 0;
  std::int64_t s = scan_started_[task].load(std::memory_order_relaxed);
  return s < 0 ? 0 : std::max<std::int64_t>(0, monotonic_ns() - epoch_ - s);
}

bool RealtimeRunner::running() const { return alive_.load(std::memory_order_acquire) > 0; }

std::vector<std::string> RealtimeRunner::warnings() const {
  std::lock_guard lock(warnings_mutex_);
  return warnings_;
}

void RealtimeRunner::task_thread(std::size_t index) {
  Task& task = *program_.tasks[index];
  const auto& cfg = task.config();
  {
    std::string name = cfg.name.substr(0, 15);
    pthread_setname_np(pthread_self(), name.c_str());
  }
  if (options_.fifo) {
    sched_param sp{};
    sp.sched_priority = std::clamp(cfg.priority, sched_get_priority_min(SCHED_FIFO), sched_get_priority_max(SCHED_FIFO));
    int rc = pthread_setschedparam(pthread_self(), SCHED_FIFO, &sp);
    if (rc != 0) {
      std::lock_guard lock(warnings_mutex_);
      warnings_.push_back("task " + cfg.name + ": cannot use SCHED_FIFO priority " + std::to_string(sp.sched_priority) +
                          " (" + std::strerror(rc) + "); running at normal priority, expect more jitter");
    }
  }
  if (cfg.cpu >= 0) {
    cpu_set_t set;
    CPU_ZERO(&set);
    CPU_SET(cfg.cpu, &set);
    int rc = pthread_setaffinity_np(pthread_self(), sizeof set, &set);
    if (rc != 0) {
      std::lock_guard lock(warnings_mutex_);
      warnings_.push_back("task " + cfg.name + ": cannot pin to CPU " + std::to_string(cfg.cpu) + " (" +
                          std::strerror(rc) + ")");
    }
  }
  prefault_stack();

  std::int64_t k = 0;
  std::int64_t prev_planned = 0;
  std::uint64_t n = 0;
  constexpr std::int64_t kStopPoll = 100'000'000;  // a long period still notices a stop within 100 ms
  while (!stop_.load(std::memory_order_acquire)) {
    const std::int64_t planned = task.release_ns(k);
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
    const std::int64_t start = monotonic_ns() - epoch_;
    scan_started_[index].store(start, std::memory_order_relaxed);
    ScanContext ctx;
    ctx.now_ns = planned;
    ctx.dt_ns = n == 0 ? cfg.period_ns : planned - prev_planned;
    ctx.scan = n;
    ctx.virtual_time = false;
    task.scan(ctx);
    const std::int64_t end = monotonic_ns() - epoch_;
    scan_started_[index].store(-1, std::memory_order_relaxed);
    task.publish();
    auto next = task.account(k, planned, start, end);
    prev_planned = planned;
    ++n;
    k = next.index;
    if (next.stop) break;
  }
  alive_.fetch_sub(1, std::memory_order_acq_rel);
}

}  // namespace syncplc
