// The running PLC as one object (docs/architecture.md, "runtime/plc"): it
// owns the program, the real-time runner, the supervisor on its own thread,
// the store, the Modbus and HTTP servers, the event routing and online
// change. `syncplc run` is a thin shell over it (arguments, terminal,
// signals); tests create instances directly.
//
// Threads: the task threads (RealtimeRunner); the supervisor's
// (supervisor_thread.hpp), which nothing else holds up; the control thread,
// which carries out online changes one at a time as transactions
// (transaction.hpp) without ever waiting for a switch, routes the tasks' and
// the supervisor's events, watches the store and refreshes the status the
// HTTP API shows; the store thread; the servers' threads. Every public
// member function may be called from any thread but the task threads.
#pragma once

#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <functional>
#include <future>
#include <iosfwd>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "runtime/core/program.hpp"
#include "runtime/core/realtime.hpp"
#include "runtime/core/supervisor.hpp"
#include "runtime/modbus/server.hpp"
#include "runtime/plc/change_request.hpp"
#include "runtime/project/loader.hpp"
#include "runtime/store/retain.hpp"
#include "runtime/web/web_config.hpp"

namespace syncplc::web {
class Server;
}

namespace syncplc::plc {

class StoreLink;
class EventRecorder;
class WebHost;
class SupervisorThread;
class ChangeRunner;
class ChangeScheduler;
class StoreStatusRegisters;
class DriverChange;
class SupervisorChange;
class ReadersChange;
class StoreChange;
class EventsChange;

struct PlcOptions {
  std::string project;         // the project file
  std::string origin = "run";  // how the project store records the start: "run", "boot"
  std::string source;          // "version 3" for a boot project; "" otherwise
  LoadOptions load;            // --set overrides (also for every online change)
  std::string db;              // the database ("" : the project's store: path, else the default; docs/store.md)
  store::StartMode start = store::StartMode::Warm;
  std::optional<int> modbus_port;  // --modbus-port
  web::WebConfig http;             // http.enabled false: no HTTP server
  RealtimeRunner::Options runner;
  // The exit statuses `open` reports (the command line's).
  int status_invalid = 2, status_driver_failed = 5;
  // Where the servers say where they listen (and why not): `run`'s stderr.
  std::ostream* log = nullptr;
};

// Why a PLC did not open or start: the exit status and the reason.
struct PlcFailure {
  int status = 2;
  std::string why;          // the project's errors (one per line, file:line:col), or the reason
  bool load_errors = false;  // why holds the project's errors
};

// How a run ended, for the event log, the exit status and the statistics.
struct StopReport {
  bool joined = true;       // every task thread ended (else one is stuck in a scan)
  bool all_stopped = false;  // every task had stopped (watchdogs, the supervisor)
  bool any_hung = false;     // the supervisor gave up on a scan
};

class Plc {
 public:
  // Loads the project, opens the database (a second instance on it stops
  // here), restores retained values, opens the drivers and binds the
  // servers: nothing runs yet. Null with `failure` when the PLC must not
  // start (a rejected load is recorded in the database first). `notices`:
  // what the operator must see (the store moved a file aside, runs read-only,
  // what the start restored), also written to options.log as they come.
  static std::unique_ptr<Plc> open(PlcOptions options, std::vector<std::string>& notices, PlcFailure* failure);
  ~Plc();
  Plc(const Plc&) = delete;
  Plc& operator=(const Plc&) = delete;

  // Starts the tasks, the store, the supervisor and the control thread.
  void start();
  // Ends the run: no further change is taken (waiting ones are answered),
  // the servers stop, the tasks are asked to stop and joined within the
  // supervisor's grace (a scan past it is given up on: its outputs are made
  // safe and its thread is left), drivers take their at_stop outputs, the
  // store's final run stores the last values and `why` (given the report,
  // for a reason that depends on how the threads ended). Idempotent.
  StopReport stop(const std::function<std::string(const StopReport&)>& why);
  StopReport stop(const std::string& why) {
    return stop([why](const StopReport&) { return why; });
  }

  // An online change, from any thread but a task's: carried out by the
  // control thread, one at a time, in the order asked. `done` is called on
  // the control thread with the outcome: when every task switched, when a
  // task has still not reached its switch a second after it should have
  // (the change completes when it does), or at once when it is refused.
  void request_change(ChangeRequest request, std::function<void(const ChangeResult&)> done);
  // The same, waiting for the outcome.
  ChangeResult change(ChangeRequest request);

  // Each event the way `run` prints it (tasks', the supervisor's, changes'),
  // on the control thread. Set before start().
  void on_event_line(std::function<void(const std::string&)> f) { event_line_ = std::move(f); }

  // What readers may use, held against an online change replacing it.
  struct View {
    Program& program;
    const modbus::Server* modbus;  // null when none runs
    const Supervisor* supervisor;  // null before start
  };
  void with_view(const std::function<void(const View&)>& f);

  // The run has ended by itself: every task stopped, or (--duration) every
  // task thread returned.
  bool ended() const;
  bool all_stopped() const;

  std::int64_t epoch_ns() const;
  const std::string& project() const { return options_.project; }
  const std::string& database_path() const;
  std::string http_url() const;
  // Where the HTTP server listens, or why it does not (a warning): for the
  // screen once it is up. "" without --http.
  const std::string& http_notice() const { return http_notice_; }
  // The program running now, without a lock: for the command line after
  // stop() (statistics), and single-threaded tests.
  Program& program_after_stop() { return *current_; }
  std::vector<std::string> runner_warnings() const;
  StoreLink& store() { return *store_; }
  const StoreLink& store() const { return *store_; }
  Supervisor* supervisor() { return supervisor_.get(); }
  // Changes carried out so far (accepted and complete), for tests.
  std::uint64_t changes_completed() const { return changes_completed_.load(); }

 private:
  Plc() = default;
  void control_loop();
  void emit(const std::string& line);
  void route_events();
  void route_task_events(Program& p);
  void refresh_status();
  void finish_request(std::function<void(const ChangeResult&)>& done, const ChangeResult& r);
  bool start_next_change();
  void poll_change();
  void keep_threads_off_tasks(const Program& p);

  // Declared in the order they depend on each other: destroyed in reverse,
  // whatever uses the program (the runner, the servers, a change under way)
  // goes before it.
  PlcOptions options_;
  std::unique_ptr<StoreLink> store_;
  std::unique_ptr<EventRecorder> events_;
  std::unique_ptr<StoreStatusRegisters> store_registers_;
  std::string start_hash_;

  // What readers use (current_, modbus_): replaced under readers_mutex_ by
  // a change's commit (never taken by a task thread). program_ owns the
  // running program; during a change the new one is the transaction's
  // until it completes.
  mutable std::mutex readers_mutex_;
  std::unique_ptr<Program> program_;
  Program* current_ = nullptr;
  std::unique_ptr<modbus::Server> modbus_;
  std::atomic<std::uint64_t> generation_{0};

  std::unique_ptr<WebHost> web_host_;
  std::unique_ptr<web::Server> web_server_;
  std::string http_notice_;
  std::unique_ptr<RealtimeRunner> runner_;
  std::unique_ptr<ChangeScheduler> scheduler_;
  std::unique_ptr<Supervisor> supervisor_;
  std::unique_ptr<SupervisorThread> supervisor_thread_;

  // The control thread and its queue of changes.
  struct Pending {
    ChangeRequest request;
    std::function<void(const ChangeResult&)> done;
  };
  std::thread control_;
  std::mutex control_mutex_;
  std::condition_variable control_cv_;
  std::deque<Pending> queue_;
  bool stopping_ = false;
  std::atomic<bool> cancel_{false};  // a load under way gives up (the PLC stops)
  // The change under way and its participants (control thread only).
  std::unique_ptr<ChangeRunner> active_;
  std::function<void(const ChangeResult&)> active_done_;
  std::unique_ptr<DriverChange> drivers_change_;
  std::unique_ptr<SupervisorChange> supervisor_change_;
  std::unique_ptr<ReadersChange> readers_change_;
  std::unique_ptr<StoreChange> store_change_;
  std::unique_ptr<EventsChange> events_change_;
  std::atomic<std::uint64_t> changes_completed_{0};
  std::function<void(const std::string&)> event_line_;
  std::int64_t started_ns_ = 0;
  bool started_ = false;
  bool threads_off_tasks_ = false;  // keep_threads_off_tasks moved them (control thread)
  bool stopped_ = false;

  friend class WebHost;
};

}  // namespace syncplc::plc
