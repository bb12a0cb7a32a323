#include "runtime/web/worker_pool.hpp"

#include <sys/resource.h>
#include <unistd.h>

#include <cstring>
#include <stdexcept>
#include <string>

namespace syncplc::web {

WorkerPool::WorkerPool(std::size_t workers, const char* name) {
  pthread_attr_t attr;
  pthread_attr_init(&attr);
  pthread_attr_setstacksize(&attr, kWorkerStackBytes);
  for (std::size_t i = 0; i < workers; ++i) {
    pthread_t t;
    if (pthread_create(&t, &attr, &WorkerPool::run, this) != 0) break;  // fewer workers, still serving
    pthread_setname_np(t, name);
    threads_.push_back(t);
  }
  pthread_attr_destroy(&attr);
}

WorkerPool::~WorkerPool() { shutdown(); }

void* WorkerPool::run(void* self) {
  auto& pool = *static_cast<WorkerPool*>(self);
  // The HTTP server's threads yield the CPU to the Modbus server, the
  // drivers and the store (nice 0): a flood of requests slows the HTTP
  // answers, not them. (The tasks run SCHED_FIFO above all of these.)
  // Raising one's own nice value needs no privilege; a refusal changes nothing.
  (void)setpriority(PRIO_PROCESS, static_cast<id_t>(gettid()), kWorkerNice);
  for (;;) {
    std::function<void()> job;
    {
      std::unique_lock lock(pool.mutex_);
      pool.wake_.wait(lock, [&] { return pool.stopping_ || !pool.jobs_.empty(); });
      if (pool.jobs_.empty()) return nullptr;  // stopping, nothing left: each queued connection is served (and closed) first
      job = std::move(pool.jobs_.front());
      pool.jobs_.pop_front();
    }
    job();
  }
}

void WorkerPool::enqueue(std::function<void()> fn) {
  {
    std::lock_guard lock(mutex_);
    jobs_.push_back(std::move(fn));
  }
  wake_.notify_one();
}

void WorkerPool::shutdown() {
  std::vector<pthread_t> threads;
  {
    std::lock_guard lock(mutex_);
    if (stopping_ && threads_.empty()) return;
    stopping_ = true;
    threads.swap(threads_);  // keep_to() no longer reaches them
  }
  wake_.notify_all();
  for (pthread_t t : threads) pthread_join(t, nullptr);
}

std::string WorkerPool::keep_to(const cpu_set_t& cpus) {
  std::lock_guard lock(mutex_);
  for (pthread_t t : threads_)
    if (const int rc = pthread_setaffinity_np(t, sizeof cpus, &cpus); rc != 0) return std::strerror(rc);
  return {};
}

}  // namespace syncplc::web
