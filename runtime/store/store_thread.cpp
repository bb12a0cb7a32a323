#include "runtime/store/store_thread.hpp"

#include <pthread.h>

#include <algorithm>
#include <chrono>
#include <exception>
#include <limits>

#include "runtime/core/monotonic_clock.hpp"
#include "runtime/core/task_cpus.hpp"

namespace syncplc::store {
namespace {

constexpr std::int64_t kRetryNs = 1'000'000'000;  // a failed job is tried again a second later

}  // namespace

StoreThread::StoreThread(std::unique_ptr<Database> db) : db_(std::move(db)) {}

StoreThread::~StoreThread() { stop(); }

bool StoreThread::add(std::unique_ptr<StoreJob> job, std::string* error) {
  std::string why;
  bool ok = false;
  try {
    ok = job->prepare(*db_, &why);
  } catch (const std::exception& e) {
    why = e.what();
  }
  if (!ok) {
    *error = std::string(job->name()) + ": " + why;
    return false;
  }
  jobs_.push_back(std::move(job));
  retry_at_.push_back(0);
  return true;
}

void StoreThread::start() {
  std::lock_guard lk(state_mutex_);
  if (running_) return;
  running_ = true;
  thread_ = std::thread([this] { loop(); });
  pthread_setname_np(thread_.native_handle(), "store");
}

std::string StoreThread::keep_to(const cpu_set_t& cpus) {
  std::lock_guard lk(state_mutex_);
  if (!running_) return {};
  return keep_thread_to(thread_.native_handle(), cpus);
}

void StoreThread::stop() {
  {
    std::lock_guard lk(state_mutex_);
    if (!running_) return;
    stop_ = true;
  }
  cv_.notify_all();
  thread_.join();
  std::lock_guard lk(state_mutex_);
  running_ = false;
}

void StoreThread::wake() {
  {
    std::lock_guard lk(state_mutex_);
    wake_ = true;
  }
  cv_.notify_all();
}

void StoreThread::switch_program(Program& next, const StoreSettings& settings) {
  exclusive([&] {
    for (auto& j : jobs_) j->switch_program(next, settings);
  });
}

void StoreThread::tasks_ended(Program& p) {
  exclusive([&] {
    for (auto& j : jobs_) j->tasks_ended(p);
  });
}

StoreHealth StoreThread::health() const {
  std::lock_guard lk(state_mutex_);
  return health_;
}

void StoreThread::run_job(StoreJob& job, std::int64_t now, bool final) {
  std::string error;
  try {
    job.run(*db_, now, final);
  } catch (const std::exception& e) {
    error = std::string(job.name()) + ": " + e.what();
  }
  std::lock_guard lk(state_mutex_);
  if (error.empty()) {
    health_.last_ok_ns = monotonic_ns();
    // The fault clears when every job has run well again (retry_at_ is reset below).
  } else {
    health_.fault = true;
    health_.last_error = error;
    ++health_.failures;
  }
}

void StoreThread::loop() {
  for (;;) {
    bool stopping = false;
    std::int64_t next = std::numeric_limits<std::int64_t>::max();
    {
      // Under run_mutex_: a job's due time may depend on the program that
      // switch_program() (inside exclusive()) changes.
      std::lock_guard run(run_mutex_);
      for (std::size_t i = 0; i < jobs_.size(); ++i) next = std::min(next, std::max(jobs_[i]->due_ns(), retry_at_[i]));
    }
    {
      std::unique_lock lk(state_mutex_);
      const std::int64_t now = monotonic_ns();
      if (!stop_ && !wake_ && next > now) {
        const auto wait = std::chrono::nanoseconds(std::min<std::int64_t>(next - now, 1'000'000'000));
        cv_.wait_for(lk, wait, [this] { return stop_ || wake_; });
      }
      stopping = stop_;
      wake_ = false;
    }
    std::lock_guard run(run_mutex_);
    const std::int64_t now = monotonic_ns();
    bool all_ok = true;
    for (std::size_t i = 0; i < jobs_.size(); ++i) {
      StoreJob& job = *jobs_[i];
      if (!stopping && (job.due_ns() > now || retry_at_[i] > now)) continue;
      const std::uint64_t failures_before = health().failures;
      run_job(job, now, stopping);
      if (health().failures != failures_before) {
        retry_at_[i] = now + kRetryNs;
        all_ok = false;
      } else {
        retry_at_[i] = 0;
      }
    }
    if (all_ok) {
      bool any_waiting = false;
      for (auto r : retry_at_) any_waiting |= r != 0;
      if (!any_waiting) {
        std::lock_guard lk(state_mutex_);
        health_.fault = false;
      }
    }
    if (stopping) return;
  }
}

}  // namespace syncplc::store
