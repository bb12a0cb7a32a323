// The HTTP server's threads, with small stacks. `run` locks all its memory
// (mlockall, for the tasks' sake), and with it every thread's stack: 72
// workers at the default 8 MiB would pin 576 MiB that an idle HTTP server
// never touches. The same pool runs the network threads (Boost.Asio's
// io_context) and the handlers' workers.
#pragma once

#include <pthread.h>
#include <sched.h>

#include <condition_variable>
#include <cstddef>
#include <deque>
#include <functional>
#include <mutex>
#include <string>
#include <vector>

namespace syncplc::web {

// 1 MiB: the deepest a request goes is std::regex matching its path (the
// routes; a target is at most 8 KiB) and nlohmann's dump.
inline constexpr std::size_t kWorkerStackBytes = 1 << 20;
// The nice value of every worker (the HTTP server's threads): below nice 0.
inline constexpr int kWorkerNice = 10;

class WorkerPool final {
 public:
  // `name`: each thread's, as top -H and /proc/<pid>/task/*/comm show it (at most 15 characters).
  WorkerPool(std::size_t workers, const char* name);
  ~WorkerPool();
  WorkerPool(const WorkerPool&) = delete;
  WorkerPool& operator=(const WorkerPool&) = delete;
  void enqueue(std::function<void()> fn);
  // Runs what is queued, then joins the threads.
  void shutdown();
  // Moves every thread to `cpus` (runtime/core/task_cpus.hpp); "" or why not.
  std::string keep_to(const cpu_set_t& cpus);

 private:
  static void* run(void* self);
  std::mutex mutex_;
  std::condition_variable wake_;
  std::deque<std::function<void()>> jobs_;
  bool stopping_ = false;
  std::vector<pthread_t> threads_;  // under mutex_
};

}  // namespace syncplc::web
