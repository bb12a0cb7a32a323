#include "runtime/core/virtual_clock.hpp"

#include <algorithm>
#include <limits>

#include "runtime/core/task_switch.hpp"

namespace syncplc {

VirtualClock::VirtualClock(Program& program) : program_(&program) {
  for (auto& t : program_->tasks) {
    t->reset_timing();
    TaskState s;
    s.task = t.get();
    state_.push_back(s);
  }
}

std::int64_t VirtualClock::release_of(std::uint16_t task, std::uint64_t n) const {
  return program_->tasks[task]->release_ns(static_cast<std::int64_t>(n));
}

std::uint64_t VirtualClock::scans(std::uint16_t task) const {
  const Task* t = program_->tasks[task].get();
  for (const auto& s : state_)
    if (s.task == t) return s.scans;
  return 0;
}

void VirtualClock::flush_observer() {
  if (observed_ >= 0 && observer_) observer_(observed_);
  observed_ = -1;
}

void VirtualClock::begin_change(ProgramChange& change) {
  change_ = &change;
  begin_mirroring(change);
  // Tasks only the new program has start on their own grid at T.
  for (std::size_t i = 0; i < change.to->tasks.size(); ++i) {
    TaskHandover* h = change.for_new_task(i);
    if (h->from) continue;
    Task& t = *h->to;
    t.reset_timing();
    TaskState s;
    s.task = &t;
    const auto& c = t.config();
    s.k = std::max<std::int64_t>(0, (change.switch_ns - c.phase_ns + c.period_ns - 1) / c.period_ns);
    s.not_before = change.switch_ns;
    s.prev_planned = t.release_ns(s.k) - c.period_ns;
    h->perform();
    h->finish();
    state_.push_back(s);
  }
  // A task its watchdog stopped restarts with the new program at T.
  for (auto& s : state_) {
    if (!s.stopped || s.gone) continue;
    TaskHandover* h = s.task->handover();
    if (!h || h->to == nullptr) continue;
    s.stopped = false;
    s.not_before = std::max(s.not_before, change.switch_ns);
  }
}

OldGrid VirtualClock::old_grid(const TaskState& s) {
  return OldGrid{s.k, s.prev_planned, s.not_before, s.task->stopped()};
}

void VirtualClock::switch_task(TaskState& s) {
  TaskHandover* h = s.task->handover();
  if (!h->to) {
    s.gone = true;
    h->perform();
    h->finish();
    return;
  }
  // task_switch.hpp: the same rule as each real-time thread's.
  const NewGrid next = new_grid(*h, old_grid(s));
  h->to->reset_timing();
  h->perform();
  h->finish();
  s.task = h->to;
  s.stopped = false;  // as the real-time thread: a stopped task restarts with the new program
  s.k = next.k;
  s.prev_planned = next.prev_planned;
  if (next.skipped) s.task->stats.skipped.fetch_add(next.skipped, std::memory_order_relaxed);
}

void VirtualClock::finish_change() {
  // Order the states as the new program orders its tasks (ties between equal
  // releases and priorities go by that order from now on).
  std::vector<TaskState> next;
  for (const auto& t : change_->to->tasks)
    for (const auto& s : state_)
      if (s.task == t.get() && !s.gone) next.push_back(s);
  state_ = std::move(next);
  program_ = change_->to;
  change_ = nullptr;
}

VirtualClock::Next VirtualClock::pick() const {
  // The next event: (time, publish before start, higher priority, lower index).
  int best = -1;
  bool best_publish = false;
  std::int64_t best_time = kNever;
  for (std::size_t i = 0; i < state_.size(); ++i) {
    const auto& s = state_[i];
    if (s.gone) continue;
    const auto& task = *s.task;
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
                   task.config().priority > state_[static_cast<std::size_t>(best)].task->config().priority);
    if (better) best = static_cast<int>(i), best_publish = false, best_time = start;
  }
  return Next{best, best_publish, best_time};
}

std::int64_t VirtualClock::next_event() const {
  // An online change under way switches tasks first (run_until); their next
  // events are not known before, so the change's instant stands for them.
  const Next n = pick();
  if (change_ && change_->switch_ns < n.time) return std::max(change_->switch_ns, now_);
  return n.state < 0 ? kNever : n.time;
}

void VirtualClock::run_until(std::int64_t t, bool inclusive) {
  for (;;) {
    if (change_) {
      // Switch every task whose next release is at or after T (and whose
      // last old publication is out), as each real-time thread does.
      bool all = true;
      for (auto& s : state_) {
        if (s.gone) continue;
        TaskHandover* h = s.task->handover();
        if (h && h->from == s.task && s.publish_at < 0 && switch_due(*h, old_grid(s)) &&
            switch_at(*h, old_grid(s)) <= (inclusive ? t : t - 1))
          switch_task(s);
        h = s.task->handover();
        if (!s.gone && h && h->from == s.task) all = false;
      }
      if (all) finish_change();
    }
    const Next n = pick();
    const int best = n.state;
    const bool best_publish = n.publish;
    const std::int64_t best_time = n.time;
    if (best < 0 || best_time == kNever) break;
    if (inclusive ? best_time > t : best_time >= t) break;

    auto& s = state_[static_cast<std::size_t>(best)];
    auto& task = *s.task;
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
