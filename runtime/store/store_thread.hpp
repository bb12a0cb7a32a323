// The store thread: the one thread that writes the PLC's database. Its jobs
// (retain, events, trends, ...) each run on their own schedule; the scan path
// never waits for any of them: jobs read the tasks' published snapshots and
// take records from queues the non-real-time threads fill.
//
// A job that fails (disk full, read-only file system, I/O error) keeps what
// it could not write, bounded, and is tried again a second later; the thread's
// health shows the fault until a run succeeds. What is already stored is
// never touched by a failed transaction (SQLite rolls it back whole).
#pragma once

#include <sched.h>

#include <condition_variable>
#include <cstdint>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "runtime/core/program.hpp"
#include "runtime/store/database.hpp"
#include "runtime/store/store_settings.hpp"

namespace syncplc::store {

class StoreJob {
 public:
  virtual ~StoreJob() = default;
  virtual const char* name() const = 0;
  // Creates or migrates the job's tables (schema.hpp). Called once, on the
  // thread that starts the store, before the store thread runs. False with
  // `error` when the job cannot work with this database.
  virtual bool prepare(Database& db, std::string* error) = 0;
  // Monotonic ns when run() is due next (a job with queued records says
  // "now"; INT64_MAX: nothing to do). Asked again after every wake().
  // Called on the store thread (never during switch_program) and must be cheap.
  virtual std::int64_t due_ns() const = 0;
  // Does the job's work. `final`: the last run, at a clean stop. Throws
  // (SQLite::Exception or std::exception) when the database refuses: the job
  // keeps its pending data and is run again later.
  virtual void run(Database& db, std::int64_t now_ns, bool final) = 0;
  // An online change installed `next` with its store settings: read its
  // snapshots from now on. Called inside StoreThread::exclusive (no run
  // meanwhile), before the old program goes.
  virtual void switch_program(Program& next, const StoreSettings& settings) {
    (void)next;
    (void)settings;
  }
  // The tasks of `p` have stopped running it for good: at a clean stop after
  // their threads were joined (p is the program served), or after an online
  // change once every task switched away from it (p is the previous one,
  // still alive). Take what they left unfinished. Inside exclusive().
  virtual void tasks_ended(Program& p) { (void)p; }
};

struct StoreHealth {
  bool fault = false;           // the last run of some job failed
  std::string last_error;       // "events: database or disk is full"
  std::uint64_t failures = 0;   // failed runs since start
  std::int64_t last_ok_ns = 0;  // monotonic ns of the last successful run (0: none yet)
};

class StoreThread {
 public:
  explicit StoreThread(std::unique_ptr<Database> db);
  ~StoreThread();
  StoreThread(const StoreThread&) = delete;
  StoreThread& operator=(const StoreThread&) = delete;

  // Before start(): prepares the job (its tables) and adds it. False with
  // `error` when prepare() fails; the job is not added.
  bool add(std::unique_ptr<StoreJob> job, std::string* error);
  void start();
  // Runs every job once more (final) and joins. Idempotent.
  void stop();
  // A job has new work (a queued record): ask the jobs when they are due now.
  void wake();
  StoreHealth health() const;
  // Moves the thread, while it runs, to `cpus` (runtime/core/task_cpus.hpp); "" or why not.
  std::string keep_to(const cpu_set_t& cpus);

  // Runs `f` while no job runs (e.g. to point jobs at the program an online
  // change installed, before the old one goes). Not for the real-time threads.
  template <class F>
  void exclusive(F&& f) {
    std::lock_guard lk(run_mutex_);
    f();
  }

  // Every job's tasks_ended(p) (inside exclusive()).
  void tasks_ended(Program& p);
  // An online change: every job reads `next` from now on (inside exclusive()).
  void switch_program(Program& next, const StoreSettings& settings);

  Database& database() { return *db_; }

 private:
  void loop();
  void run_job(StoreJob& job, std::int64_t now, bool final);

  std::unique_ptr<Database> db_;
  std::vector<std::unique_ptr<StoreJob>> jobs_;
  std::vector<std::int64_t> retry_at_;  // per job: after a failure, not before this
  std::thread thread_;
  std::mutex run_mutex_;                // held by the store thread while jobs run
  mutable std::mutex state_mutex_;      // wake_, stop_, health_
  std::condition_variable cv_;
  bool wake_ = false;
  bool stop_ = false;
  bool running_ = false;
  StoreHealth health_;
};

}  // namespace syncplc::store
