#include "runtime/store/projects_job.hpp"

#include <limits>

namespace syncplc::store {

std::int64_t ProjectsJob::due_ns() const {
  std::lock_guard lk(mutex_);
  return pending_.empty() ? std::numeric_limits<std::int64_t>::max() : 0;
}

void ProjectsJob::run(Database& db, std::int64_t now_ns, bool final) {
  (void)now_ns;
  (void)final;
  for (;;) {
    std::pair<std::uint64_t, ProjectLoad> next;
    {
      std::lock_guard lk(mutex_);
      if (pending_.empty()) return;
      next = pending_.front();  // a copy: it stays queued until it is stored
    }
    record_load(db.sql(), next.second);  // throws when the database refuses: kept, tried again
    std::lock_guard lk(mutex_);
    // Unless a full queue dropped it meanwhile.
    if (!pending_.empty() && pending_.front().first == next.first) pending_.pop_front();
  }
}

void ProjectsJob::submit(ProjectLoad load) {
  std::lock_guard lk(mutex_);
  if (pending_.size() >= kMaxPending) {
    pending_.pop_front();
    ++dropped_;
  }
  pending_.emplace_back(next_seq_++, std::move(load));
}

std::uint64_t ProjectsJob::dropped() const {
  std::lock_guard lk(mutex_);
  return dropped_;
}

}  // namespace syncplc::store
