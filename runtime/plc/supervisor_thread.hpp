// The supervisor on its own thread (runtime/core/supervisor.hpp): it looks
// at every task thread every 10 ms, whatever else the PLC does: an online
// change being loaded or waiting for a switch, a signal, an HTTP request, a
// store that hangs. Its own participant in an online change: it learns the
// new program's tasks and drivers before the change begins and forgets the
// old ones when it completes.
#pragma once

#include <sched.h>

#include <atomic>
#include <condition_variable>
#include <mutex>
#include <string>
#include <thread>

#include "runtime/core/supervisor.hpp"
#include "runtime/plc/transaction.hpp"

namespace syncplc::plc {

class SupervisorThread {
 public:
  static constexpr std::int64_t kPeriodNs = 10'000'000;
  explicit SupervisorThread(Supervisor& s);
  ~SupervisorThread();  // stops the thread
  void stop();
  // Moves the thread to `cpus` (runtime/core/task_cpus.hpp); "" or why not. Before stop().
  std::string keep_to(const cpu_set_t& cpus);

 private:
  void loop();
  Supervisor& supervisor_;
  std::mutex mutex_;
  std::condition_variable cv_;
  bool stop_ = false;
  std::thread thread_;
};

class SupervisorChange final : public ChangeParticipant {
 public:
  explicit SupervisorChange(Supervisor& s) : supervisor_(s) {}
  const char* name() const override { return "supervisor"; }
  bool prepare(ChangeContext& c, std::string*) override {
    supervisor_.watch(*c.next.program);
    return true;
  }
  void abort(ChangeContext& c) override { supervisor_.forget(*c.next.program); }
  void complete(ChangeContext& c) override { supervisor_.forget(c.from); }

 private:
  Supervisor& supervisor_;
};

}  // namespace syncplc::plc
