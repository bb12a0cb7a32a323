// The HTTP server's workers: cpp-httplib's thread pool, but with small
// stacks. `run` locks all its memory (mlockall, for the tasks' sake), and
// with it every thread's stack: 72 workers at the default 8 MiB would pin
// 576 MiB that an idle HTTP server never touches.
#pragma once

#include <httplib.h>
#include <pthread.h>

#include <condition_variable>
#include <cstddef>
#include <deque>
#include <functional>
#include <mutex>
#include <vector>

namespace syncplc::web {

// 1 MiB: the deepest a request goes is std::regex matching its path
// (cpp-httplib's routes; a path is at most 8 KiB) and nlohmann's dump.
inline constexpr std::size_t kWorkerStackBytes = 1 << 20;

class WorkerPool final : public httplib::TaskQueue {
 public:
  explicit WorkerPool(std::size_t workers);
  ~WorkerPool() override;
  void enqueue(std::function<void()> fn) override;
  void shutdown() override;

 private:
  static void* run(void* self);
  std::mutex mutex_;
  std::condition_variable wake_;
  std::deque<std::function<void()>> jobs_;
  bool stopping_ = false;
  std::vector<pthread_t> threads_;
};

}  // namespace syncplc::web
