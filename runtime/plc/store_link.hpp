// The PLC's memory (docs/store.md): the database opened before any task
// runs, the store thread started with the jobs the project needs, pointed at
// the new program by an online change (StoreChange, its participant in the
// transaction), and stopped after the tasks at a clean stop (its jobs' final
// run stores the last values).
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "runtime/core/program.hpp"
#include "runtime/plc/transaction.hpp"
#include "runtime/project/loader.hpp"
#include "runtime/store/projects_job.hpp"
#include "runtime/store/event_log.hpp"
#include "runtime/store/retain.hpp"
#include "runtime/store/store_thread.hpp"

namespace syncplc::store {
class Historian;
}

namespace syncplc::plc {

// $XDG_STATE_HOME/syncplc/plc.db, else $HOME/.local/state/syncplc/plc.db.
std::string default_database_path();
// --db, else the project's store: path (relative to the project file's
// directory), else the default.
std::string database_path(const std::string& option, const store::StoreSettings& s, const std::string& project_file);

class StoreLink {
 public:
  // Opens the database at `path` and prepares the jobs for `p`. Null, with
  // `error`, when the PLC must not start: another instance holds the
  // database, another connection holds a lock on it past the busy timeout,
  // or a job cannot use it (tables from a newer syncplc). A file that is
  // corrupt is moved aside and a new one made; a write-protected one makes
  // the store read-only (read_only(): values restored from it, nothing
  // recorded); a database that cannot be opened at all leaves the store off
  // (off_reason()); each is in `notices`, which the caller shows loudly.
  // `start`: which retained values come back (retain.hpp) before the first scan.
  static std::unique_ptr<StoreLink> open(const std::string& path, Program& p, const LoadResult& loaded,
                                        std::vector<std::string>& notices, std::string* error,
                                        store::StartMode start = store::StartMode::Warm);
  ~StoreLink();

  void start();
  void stop();
  // An online change installed `next` (its load result `loaded`).
  void switch_program(Program& next, const LoadResult& loaded);
  // The tasks of `p` stopped running it for good (store_thread.hpp,
  // StoreJob::tasks_ended): after they were joined at a clean stop, or
  // after an online change completed, before the old program goes.
  void tasks_ended(Program& p);
  // Trend buckets lost so far (a task's full ring, the historian's full queue).
  std::uint64_t trend_buckets_lost() const;
  // A project load (start, online change, rollback) for the project store,
  // written by the store thread (nothing when the store is off).
  void record(store::ProjectLoad load);

  // The store thread runs: it records. False when off or read-only.
  bool on() const { return thread_ != nullptr; }
  const std::string& off_reason() const { return off_reason_; }
  // The database is write-protected: retained values came from it, nothing is recorded.
  bool read_only() const { return !read_only_reason_.empty(); }
  const std::string& read_only_reason() const { return read_only_reason_; }
  const std::string& path() const { return path_; }
  store::StoreHealth health() const;
  store::StoreThread* thread() { return thread_.get(); }
  // What the start restored and did not (retain.hpp), for the log and events.
  const std::vector<std::string>& retain_notices() const { return retain_notices_; }

  // The event log (store/event_log.hpp): a record for the store thread to
  // write. Nothing is recorded when the store is off. Any non-real-time thread.
  void record(store::EventRecord r);
  const store::EventQueue& events() const { return events_; }
  // Records the store's fault as an event when it starts and when it clears
  // (run's main thread calls it with its other periodic checks).
  void watch_health();

 private:
  StoreLink() = default;
  static std::unique_ptr<StoreLink> open_read_only(std::unique_ptr<StoreLink> s, store::Database& db,
                                                  const std::string& reason, Program& p, const LoadResult& loaded,
                                                  std::vector<std::string>& notices, std::string* error,
                                                  store::StartMode start);
  std::string path_;
  std::string off_reason_;
  std::string read_only_reason_;
  std::unique_ptr<store::StoreThread> thread_;
  store::ProjectsJob* projects_ = nullptr;  // owned by thread_
  const store::Historian* historian_ = nullptr;  // owned by thread_
  store::EventQueue events_;
  bool fault_seen_ = false;
  std::vector<std::string> retain_notices_;
};

// The store's part in an online change: from the commit on, the retain job
// and the historian read the new program's snapshots (the old tasks mirror
// theirs into it until each switches, and the new program's retained state
// was carried over at the plan: program_change.hpp), so no value is read
// from a program no task runs; at completion the historian takes the old
// tasks' buckets in progress, before the old program goes.
class StoreChange final : public ChangeParticipant {
 public:
  explicit StoreChange(StoreLink& s) : store_(s) {}
  const char* name() const override { return "store"; }
  void commit(ChangeContext& c) override { store_.switch_program(*c.next.program, c.next); }
  void complete(ChangeContext& c) override { store_.tasks_ended(c.from); }

 private:
  StoreLink& store_;
};

}  // namespace syncplc::plc
