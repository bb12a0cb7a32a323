#include "runtime/core/supervisor.hpp"

#include <time.h>

#include <algorithm>

namespace syncplc {

Supervisor::Supervisor(Program& program, RealtimeRunner& runner) { attach(program, runner); }

void Supervisor::attach(Program& program, RealtimeRunner& runner) {
  program_ = &program;
  runner_ = &runner;
  watch_.assign(program.tasks.size(), Watch{});
  for (const auto& b : program.drivers) {
    if (b.task >= watch_.size() || !b.driver) continue;
    watch_[b.task].drivers.push_back(DriverSafeState{b.driver.get(), program.safe_outputs(b)});
  }
}

std::int64_t Supervisor::hang_limit_ns(const TaskConfig& c) {
  const std::int64_t watchdog_limit = c.watchdog ? c.watchdog_ns * std::max(1, c.sensitivity) : 0;
  if (c.watchdog && c.action != WatchdogAction::Log) return watchdog_limit;
  return std::max({std::int64_t{1'000'000'000}, 10 * c.period_ns, watchdog_limit});
}

void Supervisor::raise(std::size_t task, EventKind kind, const char* message, double value) {
  const std::int64_t since_epoch = RealtimeRunner::monotonic_ns() - runner_->epoch_ns();
  events_.push_back(Event{since_epoch, static_cast<std::uint16_t>(task), -1, kind, message, value});
}

void Supervisor::give_up(std::size_t i, std::int64_t running_ns, const char* why) {
  Watch& w = watch_[i];
  w.hung = true;
  program_->tasks[i]->stop_from_supervisor();
  raise(i, EventKind::ScanHung, why, static_cast<double>(running_ns) * 1e-9);
  bool any_safe = false, all_reached = true;
  for (auto& d : w.drivers) {
    any_safe = any_safe || !d.outputs.empty();
    if (!d.driver->write_safe_outputs(d.outputs.data(), d.outputs.size())) {
      all_reached = false;
      raise(i, EventKind::DriverFault, "a driver did not confirm its safe outputs (a write_outputs still under way)", 0);
    }
  }
  if (!w.drivers.empty() && all_reached)
    raise(i, EventKind::SafeStateApplied,
          any_safe ? "outputs driven to their safe values by the supervisor"
                   : "outputs held at their last values by the supervisor (no safe values declared)",
          0);
}

void Supervisor::check() {
  for (std::size_t i = 0; i < watch_.size(); ++i) {
    Watch& w = watch_[i];
    const std::int64_t running = runner_->scan_running_ns(i);
    if (running <= 0) {
      w.reported = false;
      continue;
    }
    if (w.hung) continue;
    const TaskConfig& c = program_->tasks[i]->config();
    if (running > hang_limit_ns(c)) {
      give_up(i, running, "scan did not end: task stopped by the supervisor (a scan cannot be interrupted)");
    } else if (c.watchdog && !w.reported && running > c.watchdog_ns * std::max(1, c.sensitivity)) {
      raise(i, EventKind::ScanHung, "scan past its watchdog limit and not finished (watchdog action log)",
            static_cast<double>(running) * 1e-9);
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
      bool in_scan = false;
      for (std::size_t i = 0; i < watch_.size(); ++i) {
        const std::int64_t running = runner_->scan_running_ns(i);
        if (running <= 0) continue;
        in_scan = true;
        if (!watch_[i].hung) give_up(i, running, "scan still running at the stop: the process ends without it");
      }
      if (in_scan || waited >= grace_ns + kLeaving) return false;
    }
    timespec pause{0, 2'000'000};
    nanosleep(&pause, nullptr);
  }
  return true;
}

bool Supervisor::pop_event(Event& e) {
  if (events_.empty()) return false;
  e = events_.front();
  events_.pop_front();
  return true;
}

bool Supervisor::any_hung() const {
  return std::any_of(watch_.begin(), watch_.end(), [](const Watch& w) { return w.hung; });
}

bool Supervisor::all_stopped() const {
  return !program_->tasks.empty() &&
         std::all_of(program_->tasks.begin(), program_->tasks.end(), [](const auto& t) { return t->stopped(); });
}

}  // namespace syncplc
