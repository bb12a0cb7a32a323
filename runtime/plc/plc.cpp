#include "runtime/plc/plc.hpp"

#include <fmt/format.h>
#include <pthread.h>

#include <chrono>
#include <filesystem>
#include <iostream>

#include "runtime/core/monotonic_clock.hpp"
#include "runtime/core/task_cpus.hpp"
#include "runtime/plc/change_runner.hpp"
#include "runtime/plc/driver_change.hpp"
#include "runtime/plc/events.hpp"
#include "runtime/plc/modbus_host.hpp"
#include "runtime/plc/project_versions.hpp"
#include "runtime/plc/store_link.hpp"
#include "runtime/plc/store_status.hpp"
#include "runtime/plc/supervisor_thread.hpp"
#include "runtime/plc/web_host.hpp"
#include "runtime/project/report.hpp"
#include "runtime/web/server.hpp"

namespace syncplc::plc {
namespace {

std::string diagnostics_text(const LoadResult& r) {
  std::string s;
  for (const auto& d : r.diagnostics.sorted()) s += (s.empty() ? "" : "\n") + d.text();
  return s;
}

}  // namespace

// --- the PLC's own participants in an online change ------------------------------

// The program and the Modbus server that readers (HTTP, the live screen,
// the control thread) use: from the commit on they are the new program's,
// held meanwhile so that nothing a reader queues can land in an old task
// that no longer takes its queue.
class ReadersChange final : public ChangeParticipant {
 public:
  ReadersChange(std::mutex& readers, Program*& current, std::unique_ptr<modbus::Server>& modbus,
                std::atomic<std::uint64_t>& generation, const PlcOptions& options, EventRecorder& audit,
                const modbus::StoreStatusSource& store_status)
      : readers_(readers), current_(current), modbus_(modbus), generation_(generation), options_(options),
        audit_(audit), store_status_(store_status) {}
  const char* name() const override { return "readers"; }
  void commit_begin(ChangeContext& c) override {
    lock_ = std::unique_lock(readers_);
    const ModbusConfig next_cfg = server_config(c.next.modbus.server, options_.modbus_port);
    keep_server_ = modbus_ && same_server(modbus_->config(), next_cfg);
    if (keep_server_) modbus_->hold();  // no request is taken between hold and replace
  }
  void commit(ChangeContext& c) override {
    Program& next = *c.next.program;
    // From the change on, the old tasks apply the new program's queues and
    // mirror their publications into it: readers use the new program at once.
    if (keep_server_) {
      modbus_->replace_program(next, c.next.modbus.places);
    } else if (modbus_ || server_config(c.next.modbus.server, options_.modbus_port).enabled) {
      modbus_.reset();  // changed settings: a new server (its clients reconnect)
      modbus_ = start_modbus(next, c.next.modbus, options_.modbus_port, &audit_, &store_status_, *options_.log);
    }
    current_ = &next;
    generation_.fetch_add(1, std::memory_order_acq_rel);
    lock_.unlock();
  }

 private:
  std::mutex& readers_;
  Program*& current_;
  std::unique_ptr<modbus::Server>& modbus_;
  std::atomic<std::uint64_t>& generation_;
  const PlcOptions& options_;
  EventRecorder& audit_;
  const modbus::StoreStatusSource& store_status_;
  std::unique_lock<std::mutex> lock_;
  bool keep_server_ = false;
};

// --- opening --------------------------------------------------------------------------

std::unique_ptr<Plc> Plc::open(PlcOptions o, std::vector<std::string>& notices, PlcFailure* failure) {
  std::unique_ptr<Plc> plc(new Plc);
  plc->options_ = std::move(o);
  PlcOptions& opt = plc->options_;
  if (!opt.log) opt.log = &std::cerr;
  // A PLC that did not open has nothing to stop (what it opened is closed
  // on the way out).
  auto fail = [&](int status, std::string why) {
    if (failure) *failure = PlcFailure{status, std::move(why)};
    plc->stopped_ = true;
    return nullptr;
  };
  LoadResult r = load_project(opt.project, opt.load);
  if (!r.ok()) {
    record_rejected_run(plc::database_path(opt.db, r.store, opt.project), project_load(r, opt.project, opt.origin, opt.source));
    if (failure) *failure = PlcFailure{opt.status_invalid, diagnostics_text(r), true};
    plc->stopped_ = true;
    return nullptr;
  }
  store::ProjectLoad start = project_load(r, opt.project, opt.origin, opt.source);
  plc->start_hash_ = start.content.hash;
  plc->program_ = std::move(r.program);
  plc->current_ = plc->program_.get();
  Program& program = *plc->program_;

  // The PLC's database first: a second instance on it stops here, before
  // anything binds or moves; retain values are in the images before the first scan.
  std::string err;
  const std::size_t before = notices.size();
  plc->store_ = StoreLink::open(plc::database_path(opt.db, r.store, opt.project), program, r, notices, &err, opt.start);
  if (!plc->store_) return fail(opt.status_invalid, err);
  for (std::size_t i = before; i < notices.size(); ++i) notices[i] = "warning: " + notices[i];  // shown loudly
  plc->store_->record(std::move(start));  // written when the store thread starts
  for (const auto& n : plc->store_->retain_notices()) notices.push_back(n);
  // Said at once, before the servers say where they listen (the log reads
  // in the order things happened).
  for (std::size_t i = before; i < notices.size(); ++i) *opt.log << "syncplc: " << notices[i] << "\n";
  plc->events_ = std::make_unique<EventRecorder>(*plc->store_);
  plc->store_registers_ = std::make_unique<StoreStatusRegisters>(*plc->store_);

  // A start that fails from here on still leaves its record: the project
  // store's version and a start-failed event with the reason, written by one
  // run of the store thread.
  auto start_failed = [&](int status, const std::string& why) {
    plc->events_->start_failed(why + " (exit status " + std::to_string(status) + ")");
    plc->store_->start();
    plc->store_->stop();
    return fail(status, why);
  };
  if (!program.open_drivers(&err)) return start_failed(opt.status_driver_failed, err);
  // The servers bind before any task runs: a port in use stops here, cleanly.
  plc->modbus_ = start_modbus(program, r.modbus, opt.modbus_port, plc->events_.get(), plc->store_registers_.get(), *opt.log);
  if (!plc->modbus_ && (opt.modbus_port || r.modbus.server.enabled)) {
    program.close_drivers();
    const ModbusConfig cfg = server_config(r.modbus.server, opt.modbus_port);
    return start_failed(opt.status_invalid, "the Modbus server could not listen on " + cfg.bind + ":" + std::to_string(cfg.port));
  }
  // The HTTP API and the HMI. A port given explicitly (or with TLS, or
  // --http-cpus) that cannot be bound stops here; the default one only
  // warns (the machine keeps its control program when another service
  // holds 8080).
  const StoreLink& st = *plc->store_;
  const std::string db_dir = st.on() && st.path() != store::kMemoryDatabase
                                 ? std::filesystem::path(st.path()).parent_path().string()
                                 : std::filesystem::path(default_database_path()).parent_path().string();
  plc->web_host_ = std::make_unique<WebHost>(*plc, opt.load, (std::filesystem::path(db_dir) / "uploads").string());
  plc->web_host_->set_project_hash(plc->start_hash_);
  if (opt.http.enabled) {
    plc->web_server_ = std::make_unique<web::Server>(opt.http, *plc->web_host_);
    std::string why;
    if (!plc->web_server_->start(&why)) {
      plc->web_server_.reset();
      if (opt.http.explicit_address || opt.http.tls() || !opt.http.cpus.empty()) {
        if (plc->modbus_) plc->modbus_->stop();
        program.close_drivers();
        return start_failed(opt.status_invalid, why);
      }
      plc->http_notice_ = "warning: " + why + "; running without the HTTP API and the HMI";
    } else {
      plc->http_notice_ = "HMI and HTTP API on " + plc->web_server_->url();
    }
  }
  plc->refresh_status();  // what /status says until the control thread's first turn
  return plc;
}

Plc::~Plc() {
  if (!stopped_) stop("the PLC object was destroyed");
}

// --- running ------------------------------------------------------------------------------

void Plc::start() {
  runner_ = std::make_unique<RealtimeRunner>(*program_, options_.runner);
  runner_->start();
  scheduler_ = std::make_unique<RealtimeScheduler>(*runner_);
  events_->set_epoch(runner_->epoch_ns());
  events_->started(options_.project, store_->path());
  store_->start();
  {
    std::lock_guard lock(readers_mutex_);  // HTTP threads read it through with_view
    supervisor_ = std::make_unique<Supervisor>(*program_, *runner_);
  }
  supervisor_thread_ = std::make_unique<SupervisorThread>(*supervisor_);
  started_ns_ = monotonic_ns();
  {
    std::lock_guard lock(control_mutex_);  // request_change reads it
    started_ = true;
  }
  control_ = std::thread([this] { control_loop(); });
}

// The threads that are not real-time (HTTP, store, supervisor, control) keep
// off the CPUs the program pins its tasks to (runtime/core/task_cpus.hpp),
// as the Modbus server does on its own: at the start and after every online
// change, which may pin or unpin a task. The modbus_client drivers' device
// threads stay where they are (any CPU): the scan wakes them every cycle
// (cycle_signal.hpp), and a wake across CPUs costs the scan an
// inter-processor interrupt; their one burst a cycle is small beside an
// HTTP flood. On the control thread only.
void Plc::keep_threads_off_tasks(const Program& p) {
  const TaskCpuChoice choice = cpus_off_tasks(process_cpus(), pinned_cpus(p));
  if (!choice.off && !threads_off_tasks_) return;  // nothing pinned, nothing to undo
  threads_off_tasks_ = choice.off;
  cpu_set_t off = process_cpus();  // the pinned CPUs they leave, for the log
  CPU_XOR(&off, &off, &choice.cpus);
  std::string why;
  auto keep = [&](const char* what, const std::string& failed) {
    if (!failed.empty() && why.empty()) why = std::string(what) + ": " + failed;
  };
  // --http-cpus: the HTTP server's threads stay where the setting put them.
  const bool http = web_server_ && options_.http.cpus.empty();
  if (http) keep("the HTTP server's threads", web_server_->keep_to(choice.cpus));
  if (store_->on()) keep("the store thread", store_->thread()->keep_to(choice.cpus));
  keep("the supervisor thread", supervisor_thread_->keep_to(choice.cpus));
  keep("the control thread", keep_thread_to(pthread_self(), choice.cpus));
  const char* who = http ? "the HTTP, store, supervisor and control threads" : "the store, supervisor and control threads";
  if (!why.empty()) *options_.log << "syncplc: warning: cannot keep " << why << "\n";
  else if (choice.off) *options_.log << "syncplc: " << who << " keep off CPU " << cpu_list(off) << " (pinned tasks)\n";
  else *options_.log << "syncplc: " << who << " are back on CPU " << cpu_list(choice.cpus) << "\n";
}

void Plc::request_change(ChangeRequest request, std::function<void(const ChangeResult&)> done) {
  {
    std::lock_guard lock(control_mutex_);
    if (!stopping_ && started_) {
      queue_.push_back(Pending{std::move(request), std::move(done)});
      control_cv_.notify_all();
      return;
    }
  }
  ChangeResult r;
  r.status = 409;
  r.summary = started_ ? "the PLC is stopping: no online change now" : "the PLC is not running yet: no online change now";
  if (done) done(r);
}

ChangeResult Plc::change(ChangeRequest request) {
  std::promise<ChangeResult> p;
  auto f = p.get_future();
  request_change(std::move(request), [&p](const ChangeResult& r) { p.set_value(r); });
  return f.get();
}

void Plc::with_view(const std::function<void(const View&)>& f) {
  std::lock_guard lock(readers_mutex_);
  f(View{*current_, modbus_.get(), supervisor_.get()});
}

bool Plc::all_stopped() const { return supervisor_ && supervisor_->all_stopped(); }

bool Plc::ended() const { return started_ && runner_ && (all_stopped() || !runner_->threads_alive()); }

std::int64_t Plc::epoch_ns() const { return runner_ ? runner_->epoch_ns() : -1; }

const std::string& Plc::database_path() const { return store_->path(); }

std::string Plc::http_url() const { return web_server_ ? web_server_->url() : std::string(); }

std::vector<std::string> Plc::runner_warnings() const { return runner_ ? runner_->warnings() : std::vector<std::string>{}; }

void Plc::emit(const std::string& line) {
  if (event_line_) event_line_(line);
}

// --- the control thread ----------------------------------------------------------------

void Plc::control_loop() {
  // Before the name: whoever sees "plc-control" sees the threads where they belong.
  keep_threads_off_tasks(*current_);
  pthread_setname_np(pthread_self(), "plc-control");
  std::int64_t next_status = 0;
  std::unique_lock lock(control_mutex_);
  while (!stopping_) {
    lock.unlock();
    if (!active_) start_next_change();
    if (active_) poll_change();
    // A change that waits for a thread stuck in a scan never completes: the
    // ones asked meanwhile are refused now, as before the change (not queued for good).
    if (active_ && supervisor_->any_hung()) {
      std::deque<Pending> refused;
      {
        std::lock_guard l(control_mutex_);
        refused.swap(queue_);
      }
      for (auto& p : refused) {
        ChangeResult r;
        r.status = 409;
        r.summary = "reload refused: a task's scan did not end and its thread cannot be stopped; restart syncplc";
        finish_request(p.done, r);
      }
    }
    route_events();
    store_->watch_health();
    if (const std::int64_t now = monotonic_ns(); now >= next_status) {
      refresh_status();
      next_status = now + 100'000'000;
    }
    lock.lock();
    // A change in progress is stepped every millisecond: its outcome (and the
    // next change) follows the last switch closely.
    control_cv_.wait_for(lock, std::chrono::milliseconds(active_ ? 1 : 20),
                         [this] { return stopping_ || (!active_ && !queue_.empty()); });
  }
}

void Plc::finish_request(std::function<void(const ChangeResult&)>& done, const ChangeResult& r) {
  events_->reloaded(r.accepted, r.summary, r.lines);
  // Every change's report (or errors), whoever asked, then its event line.
  for (const auto& line : r.lines) emit(line);
  const double at = static_cast<double>(runner_->now_ns()) * 1e-9;
  emit(fmt::format("[{:.6f}s] {:<14} {}", at, r.accepted ? "reload" : "reload-failed", r.summary));
  if (r.accepted) web_host_->set_project_hash(r.hash);
  if (done) done(r);
  done = nullptr;
}

bool Plc::start_next_change() {
  Pending p;
  {
    std::lock_guard lock(control_mutex_);
    if (queue_.empty()) return false;
    p = std::move(queue_.front());
    queue_.pop_front();
  }
  if (supervisor_->any_hung()) {
    // A stuck thread never reaches its switch: the change could not complete.
    ChangeResult r;
    r.status = 409;
    r.summary = "reload refused: a task's scan did not end and its thread cannot be stopped; restart syncplc";
    finish_request(p.done, r);
    return false;
  }
  drivers_change_ = std::make_unique<DriverChange>();
  supervisor_change_ = std::make_unique<SupervisorChange>(*supervisor_);
  readers_change_ = std::make_unique<ReadersChange>(readers_mutex_, current_, modbus_, generation_, options_, *events_,
                                                    *store_registers_);
  store_change_ = std::make_unique<StoreChange>(*store_);
  events_change_ = std::make_unique<EventsChange>([this](Program& old) { route_task_events(old); });
  // Order: drivers open first (they may refuse); the supervisor knows the new
  // tasks before any runs; readers and the store follow the new program at
  // the commit; the old program's last events are taken at completion.
  ChangeRunner::Setup setup{*program_, options_.project, options_.load, *store_, *scheduler_,
                            {drivers_change_.get(), supervisor_change_.get(), readers_change_.get(), store_change_.get(),
                             events_change_.get()}};
  active_ = std::make_unique<ChangeRunner>(p.request, setup, &cancel_);
  active_done_ = std::move(p.done);
  if (!active_->committed()) {  // refused: nothing ran differently
    finish_request(active_done_, *active_->result());
    active_.reset();
    return false;
  }
  keep_threads_off_tasks(*current_);  // the new program's pins (current_ since the commit)
  // The file the running program came from is the instance's project file
  // from now on: GET /status names it, and `reload` or SIGHUP reloads it
  // (an upload's copy beside the database, a rolled-back version's files),
  // not the file the instance was started with.
  options_.project = active_->project_file();
  return true;
}

void Plc::poll_change() {
  if (!active_->poll()) {
    // A task late for its switch: the outcome is given as it stands, the
    // change completes when the task gets there.
    if (active_->result() && active_done_) {
      refresh_status();
      finish_request(active_done_, *active_->result());
    }
    return;
  }
  // The old program goes: every task has left it, its events and trend
  // buckets were taken, its drivers handed over and closed. Then the answer.
  const ChangeResult result = *active_->result();
  std::unique_ptr<Program> old;
  {
    std::lock_guard lock(readers_mutex_);
    old = std::move(program_);
    program_ = active_->take_new_program();
  }
  active_.reset();
  old.reset();
  changes_completed_.fetch_add(1, std::memory_order_release);
  refresh_status();  // GET /status names the new project file once the answer is out
  if (active_done_) finish_request(active_done_, result);
}

void Plc::route_task_events(Program& p) {
  Event e;
  for (auto& t : p.tasks)
    while (t->pop_event(e)) {
      emit(format_event(p, e));
      events_->task_event(p, e);
    }
}

void Plc::route_events() {
  // The running program's tasks, and during a change the old program's too
  // (each task ring is read by this thread only).
  if (active_ && active_->transaction() && active_->committed() && !active_->complete())
    route_task_events(active_->transaction()->from());
  Program* current;
  {
    std::lock_guard lock(readers_mutex_);
    current = current_;
  }
  route_task_events(*current);
  SupervisorEvent se;
  while (supervisor_->pop_event(se)) {
    emit(format_event(se.task, se.event));
    events_->task_event(se.task, se.event);
  }
}

void Plc::refresh_status() {
  if (!web_server_) return;
  const double uptime = started_ns_ ? static_cast<double>(monotonic_ns() - started_ns_) * 1e-9 : 0;
  std::lock_guard lock(readers_mutex_);
  web_host_->set_status(runtime_status_json(options_.project, uptime, *store_, modbus_.get(), web_server_.get(),
                                            started_ ? events_->wall_at_epoch_ns() : 0, *current_, supervisor_.get()));
}

// --- stopping ------------------------------------------------------------------------------

StopReport Plc::stop(const std::function<std::string(const StopReport&)>& why) {
  StopReport report;
  if (stopped_) return report;
  stopped_ = true;
  std::deque<Pending> waiting;
  {
    std::lock_guard lock(control_mutex_);
    stopping_ = true;
    cancel_.store(true);
    waiting.swap(queue_);
  }
  control_cv_.notify_all();
  ChangeResult refused;
  refused.status = 409;
  refused.summary = "the PLC stopped before the change was made; nothing was changed";
  if (control_.joinable()) control_.join();  // a load under way gives up at its next stage
  if (active_done_) {
    // A change that waited for its tasks' switch: answered (and recorded) as it stands.
    ChangeResult r;
    r.status = 409;
    r.summary = "the PLC stopped before every task reached its switch: the change did not complete";
    finish_request(active_done_, r);
  }
  for (auto& p : waiting)
    if (p.done) finish_request(p.done, refused);
  web_host_->close();  // HTTP requests waiting for a change are answered: none comes now
  if (web_server_) web_server_->stop();
  {
    std::lock_guard lock(readers_mutex_);
    if (modbus_) modbus_->stop();
  }
  if (!started_) {  // opened, never started: what open() opened closes
    current_->close_drivers();
    store_->stop();
    return report;
  }
  supervisor_thread_->stop();
  // A thread stuck in a scan cannot be joined: its task's outputs are safe
  // (the supervisor), the others are stopped, and the process ends without it.
  report.joined = supervisor_->stop();
  report.any_hung = supervisor_->any_hung();
  report.all_stopped = supervisor_->all_stopped();
  if (!report.joined) {
    // A thread stuck in a scan is left where it is: what it may still touch
    // (its runner, its program, a change under way) is never freed, and no
    // destructor waits for it. The process is meant to end soon (run exits
    // with status 4).
    (void)runner_.release();
    (void)program_.release();
    (void)active_.release();
    scheduler_.reset();
  }
  if (report.joined) {
    runner_->join();
    if (active_ && active_->committed() && !active_->complete()) {
      // A change that never completed (a task that never reached its switch,
      // now joined): what the old program still holds is handed over and closed.
      ChangeContext c{active_->transaction()->from(), active_->transaction()->next(), active_->transaction()->change(),
                      active_->transaction()->source()};
      // Every thread is joined: the switches still due are made here, so the
      // drivers kept open move into the program whose drivers stop below.
      for (const auto& h : c.change.handovers)
        if (h->from && h->to && !h->done.load() && h->from->handover() == h.get()) {
          h->perform();
          h->finish();
        }
      drivers_change_->close_left_over(c);
      route_task_events(c.from);
    }
    current_->stop_drivers();  // a clean stop: the drivers' at_stop (keep or safe outputs), then closed
    store_->tasks_ended(*current_);  // the historian's buckets in progress, stored by the final run
  }
  route_events();
  events_->stopped(why(report));
  store_->watch_health();
  store_->stop();  // after the tasks: its jobs' final run takes their last snapshots (and writes the stop event)
  return report;
}

}  // namespace syncplc::plc
