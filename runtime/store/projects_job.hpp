// The store thread's job for the project store: the loads that `run` and an
// online change hand over (submit, from a non-real-time thread) are written
// in the order they happened. Pending loads are kept, bounded, while the
// database refuses (disk full): the oldest goes first when the bound is hit.
#pragma once

#include <deque>
#include <mutex>

#include "runtime/store/project_store.hpp"
#include "runtime/store/store_thread.hpp"

namespace syncplc::store {

class ProjectsJob : public StoreJob {
 public:
  static constexpr std::size_t kMaxPending = 64;

  const char* name() const override { return "projects"; }
  bool prepare(Database& db, std::string* error) override { return prepare_projects(db.sql(), error); }
  std::int64_t due_ns() const override;
  void run(Database& db, std::int64_t now_ns, bool final) override;

  // Queues a load to be recorded; the caller then wakes the store thread.
  void submit(ProjectLoad load);
  // Loads dropped because the queue was full (the database refused too long).
  std::uint64_t dropped() const;

 private:
  mutable std::mutex mutex_;
  std::deque<std::pair<std::uint64_t, ProjectLoad>> pending_;  // with a sequence number
  std::uint64_t next_seq_ = 0;
  std::uint64_t dropped_ = 0;
};

}  // namespace syncplc::store
