#include "runtime/plc/supervisor_thread.hpp"

#include <pthread.h>

#include <chrono>

#include "runtime/core/task_cpus.hpp"

namespace syncplc::plc {

SupervisorThread::SupervisorThread(Supervisor& s) : supervisor_(s), thread_([this] { loop(); }) {}

SupervisorThread::~SupervisorThread() { stop(); }

void SupervisorThread::stop() {
  {
    std::lock_guard lock(mutex_);
    stop_ = true;
  }
  cv_.notify_all();
  if (thread_.joinable()) thread_.join();
}

std::string SupervisorThread::keep_to(const cpu_set_t& cpus) { return keep_thread_to(thread_.native_handle(), cpus); }

void SupervisorThread::loop() {
  pthread_setname_np(pthread_self(), "supervisor");
  std::unique_lock lock(mutex_);
  while (!stop_) {
    lock.unlock();
    supervisor_.check();  // a scan that does not end: safe outputs, task stopped
    lock.lock();
    cv_.wait_for(lock, std::chrono::nanoseconds(kPeriodNs), [this] { return stop_; });
  }
}

}  // namespace syncplc::plc
