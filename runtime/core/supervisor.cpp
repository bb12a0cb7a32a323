#include "runtime/core/supervisor.hpp"

#include <time.h>

#include <algorithm>

namespace syncplc {

Supervisor::Supervisor(Program& program, RealtimeRunner& runner) : runner_(&runner) { add(program); }

void Supervisor::add(Program& p) {
  for (std::size_t t = 0; t < p.tasks.size(); ++t) {
    const Task& task = *p.tasks[t];
    TaskSafety s;
    s.program = &p;
    s.index = static_cast<std::uint16_t>(t);
    s.by_slot.resize(task.drivers.size());
    for (const auto& b : p.drivers) {
      if (b.task != t || !b.driver) continue;
      const auto slot = std::find(task.drivers.begin(), task.drivers.end(), b.driver.get()) - task.drivers.begin();
      if (static_cast<std::size_t>(slot) < s.by_slot.size()) s.by_slot[static_cast<std::size_t>(slot)] = p.safe_outputs(b);
    }
    safety_[&task] = std::move(s);
  }
}

void Supervisor::watch(Program& next) {
  std::lock_guard lock(mutex_);
  add(next);
}

void Supervisor::forget(const Program& p) {
  std::lock_guard lock(mutex_);
  for (const auto& t : p.tasks) {
    safety_.erase(t.get());
    hung_.erase(t.get());
  }
}

std::int64_t Supervisor::hang_limit_ns(const TaskConfig& c) {
  const std::int64_t watchdog_limit = c.watchdog ? c.watchdog_ns * std::max(1, c.sensitivity) : 0;
  if (c.watchdog && c.action != WatchdogAction::Log) return watchdog_limit;
  return std::max({std::int64_t{1'000'000'000}, 10 * c.period_ns, watchdog_limit});
}

void Supervisor::raise(const Task& t, EventKind kind, const char* message, double value) {
  const std::int64_t since_epoch = RealtimeRunner::monotonic_ns() - runner_->epoch_ns();
  auto it = safety_.find(&t);
  const std::uint16_t index = it == safety_.end() ? t.index() : it->second.index;
  events_.push_back({Event{since_epoch, index, -1, kind, message, value}, t.config().name});
}

void Supervisor::give_up(const RealtimeRunner::ThreadView& v, const char* why) {
  watch_[v.id].hung = true;
  Task& task = *v.task;
  hung_[&task] = true;
  task.stop_from_supervisor();
  raise(task, EventKind::ScanHung, why, static_cast<double>(v.running_ns) * 1e-9);
  // The drivers this task uses now (a kept driver moved into it at its
  // switch, which happened before the thread published it as its task).
  auto it = safety_.find(&task);
  bool any_safe = false, all_reached = true;
  const std::size_t n = task.drivers.size();
  for (std::size_t slot = 0; slot < n; ++slot) {
    static const std::vector<SafeOutput> kNone;
    const auto& outputs = it != safety_.end() && slot < it->second.by_slot.size() ? it->second.by_slot[slot] : kNone;
    any_safe = any_safe || !outputs.empty();
    if (!task.drivers[slot]->write_safe_outputs(outputs.data(), outputs.size())) {
      all_reached = false;
      raise(task, EventKind::DriverFault, "a driver did not confirm its safe outputs (a write_outputs still under way)", 0);
    }
  }
  if (n > 0 && all_reached)
    raise(task, EventKind::SafeStateApplied,
          any_safe ? "outputs driven to their safe values by the supervisor"
                   : "outputs held at their last values by the supervisor (no safe values declared)",
          0);
}

void Supervisor::check() {
  std::lock_guard lock(mutex_);
  for (const auto& v : runner_->threads()) {
    if (!v.task || !v.alive) continue;
    Watch& w = watch_[v.id];
    if (v.running_ns <= 0) {
      w.reported = false;
      continue;
    }
    if (w.hung) continue;
    const TaskConfig& c = v.task->config();
    if (v.running_ns > hang_limit_ns(c)) {
      give_up(v, "scan did not end: task stopped by the supervisor (a scan cannot be interrupted)");
    } else if (c.watchdog && !w.reported && v.running_ns > c.watchdog_ns * std::max(1, c.sensitivity)) {
      raise(*v.task, EventKind::ScanHung, "scan past its watchdog limit and not finished (watchdog action log)",
            static_cast<double>(v.running_ns) * 1e-9);
      w.reported = true;
    }
  }
}

bool Supervisor::stop(std::int64_t grace_ns) {
  runner_->request_stop();
  const std::int64_t t0 = RealtimeRunner::monotonic_ns();
  // A thread between scans sees the stop within its poll (100 ms); a thread
  // that has just ended its last scan needs a moment more to leave.
  constexpr std::int64_t kLeaving = 200'000'000;
  while (runner_->threads_alive()) {
    const std::int64_t waited = RealtimeRunner::monotonic_ns() - t0;
    if (waited >= grace_ns) {
      std::lock_guard lock(mutex_);
      bool in_scan = false;
      for (const auto& v : runner_->threads()) {
        if (!v.alive || !v.task || v.running_ns <= 0) continue;
        in_scan = true;
        if (!watch_[v.id].hung) give_up(v, "scan still running at the stop: the process ends without it");
      }
      if (in_scan || waited >= grace_ns + kLeaving) return false;
    }
    timespec pause{0, 2'000'000};
    nanosleep(&pause, nullptr);
  }
  return true;
}

bool Supervisor::pop_event(SupervisorEvent& e) {
  std::lock_guard lock(mutex_);
  if (events_.empty()) return false;
  e = std::move(events_.front());
  events_.pop_front();
  return true;
}

bool Supervisor::hung(const Task* t) const {
  std::lock_guard lock(mutex_);
  auto it = hung_.find(t);
  return it != hung_.end() && it->second;
}

bool Supervisor::any_hung() const {
  std::lock_guard lock(mutex_);
  return std::any_of(hung_.begin(), hung_.end(), [](const auto& h) { return h.second; });
}

bool Supervisor::all_stopped() const {
  // Under the mutex: forget() takes it before an old program goes, so no
  // task read here can be freed meanwhile.
  std::lock_guard lock(mutex_);
  const auto threads = runner_->threads();
  bool any = false;
  for (const auto& v : threads) {
    if (!v.alive || !v.task) continue;
    any = true;
    if (!v.task->stopped()) return false;
  }
  return any;
}

}  // namespace syncplc
