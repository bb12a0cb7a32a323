#include "runtime/core/virtual_clock.hpp"

#include <algorithm>
#include <limits>

namespace syncplc {

VirtualClock::VirtualClock(Program& program) : program_(program), state_(program.tasks.size()) {
  for (auto& t : program_.tasks) t->reset_timing();
}

std::int64_t VirtualClock::release_of(std::uint16_t task, std::uint64_t n) const {
  return program_.tasks[task]->release_ns(static_cast<std::int64_t>(n));
}

void VirtualClock::flush_observer() {
  if (observed_ >= 0 && observer_) observer_(observed_);
  observed_ = -1;
}

void VirtualClock::run_until(std::int64_t t, bool inclusive) {
  constexpr std::int64_t kNever = std::numeric_limits<std::int64_t>::max();
  for (;;) {
    // Pick the next event: (time, publish before start, higher priority, lower index).
    int best = -1;
    bool best_publish = false;
    std::int64_t best_time = kNever;
    for (std::size_t i = 0; i < state_.size(); ++i) {
      const auto& s = state_[i];
      const auto& task = *program_.tasks[i];
      if (s.publish_at >= 0) {
        if (s.publish_at < best_time || (s.publish_at == best_time && !best_publish)) {
          best = static_cast<int>(i), best_publish = true, best_time = s.publish_at;
        }
        continue;  // its next scan waits for the publication
      }
      if (s.stopped) continue;
      std::int64_t start = std::max(task.release_ns(s.k), s.not_before);
      bool better = start < best_time ||
                    (start == best_time && !best_publish &&
                     task.config().priority > program_.tasks[static_cast<std::size_t>(best)]->config().priority);
      if (better) best = static_cast<int>(i), best_publish = false, best_time = start;
    }
    if (best < 0 || best_time == kNever) break;
    if (inclusive ? best_time > t : best_time >= t) break;

    auto& s = state_[static_cast<std::size_t>(best)];
    auto& task = *program_.tasks[static_cast<std::size_t>(best)];
    if (observed_ >= 0 && best_time != observed_) flush_observer();
    now_ = best_time;
    if (best_publish) {
      task.publish();
      s.publish_at = -1;
      continue;
    }
    const std::int64_t planned = task.release_ns(s.k);
    ScanContext ctx;
    ctx.now_ns = planned;
    ctx.dt_ns = s.scans == 0 ? task.config().period_ns : planned - s.prev_planned;
    ctx.scan = s.scans;
    ctx.virtual_time = true;
    task.scan(ctx);
    const std::int64_t end = best_time + ctx.consumed_ns;
    if (end == best_time) task.publish();
    else s.publish_at = end;
    auto next = task.account(s.k, planned, best_time, end);
    s.prev_planned = planned;
    s.scans++;
    s.k = next.index;
    s.not_before = end;
    s.stopped = next.stop;
    observed_ = best_time;
  }
  flush_observer();
}

}  // namespace syncplc
