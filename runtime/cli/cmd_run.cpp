#include <fmt/format.h>
#include <signal.h>
#include <time.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iostream>
#include <filesystem>
#include <set>

#include "runtime/cli/commands.hpp"
#include "runtime/cli/live_screen.hpp"
#include "runtime/core/realtime.hpp"
#include "runtime/core/supervisor.hpp"
#include "runtime/modbus/server.hpp"
#include "runtime/cli/instance_file.hpp"
#include "runtime/cli/plc_store.hpp"
#include "runtime/cli/project_versions.hpp"
#include "runtime/cli/reload.hpp"
#include "runtime/cli/run_events.hpp"
#include "runtime/cli/store_status.hpp"
#include "runtime/cli/serve_modbus.hpp"
#include "runtime/cli/web_host.hpp"
#include "runtime/web/server.hpp"
#include "runtime/project/report.hpp"

namespace syncplc::cli {
namespace {

// How long the main thread waits for a signal: a tenth of a second (the
// supervisor's and the live screen's pace), or up to
// the end of the --duration when that is nearer.
timespec main_wait(std::int64_t epoch_ns, const std::optional<std::int64_t>& limit) {
  std::int64_t ns = 100'000'000;
  if (limit) ns = std::clamp<std::int64_t>(epoch_ns + *limit - RealtimeRunner::monotonic_ns(), 1'000'000, ns);
  return timespec{0, static_cast<long>(ns)};
}

// The tasks' events and the supervisor's, one formatted line each, each
// also recorded in the event log.
template <class F>
void for_each_event(Program& p, Supervisor& supervisor, RunEvents& log, F&& f) {
  Event e;
  for (auto& t : p.tasks)
    while (t->pop_event(e)) {
      f(format_event(p, e));
      log.task_event(p, e);
    }
  while (supervisor.pop_event(e)) {
    f(format_event(p, e));
    log.task_event(p, e);
  }
}

// Why `run` ended, in words, for the event log.
std::string stop_reason(int stop_signal, bool joined, bool all_stopped, int status) {
  std::string why = stop_signal == SIGINT    ? "stopped by SIGINT"
                    : stop_signal == SIGTERM ? "stopped by SIGTERM"
                    : stop_signal == SIGHUP  ? "stopped: the terminal hung up (SIGHUP)"
                    : !joined                ? "a scan did not end: exiting without its thread"
                    : all_stopped            ? "every task has stopped"
                                             : "the run ended (--duration)";
  return why + " (exit status " + std::to_string(status) + ")";
}

// Why `run` ended (commands.hpp): a requested stop is 0.
int run_exit_status(bool joined, bool all_stopped, bool any_hung) {
  if (!joined || (all_stopped && any_hung)) return kExitHungScan;
  if (all_stopped) return kExitWatchdogStopped;
  return kExitOk;
}

}  // namespace

namespace {

// The outcome of a reload, for `syncplc reload` (written whole, then renamed).
void write_reload_result(const std::string& pid_file, const ReloadResult& r) {
  const std::string path = reload_result_file(pid_file), tmp = path + ".tmp";
  {
    std::ofstream f(tmp, std::ios::trunc);
    f << (r.accepted ? "accepted: " : "rejected: ") << r.summary << "\n";
    for (const auto& line : r.lines) f << line << "\n";
  }
  std::rename(tmp.c_str(), path.c_str());
}

// What the HTTP API's /status says of the runtime, taken each main loop turn.
nlohmann::json runtime_json(const std::string& project, double uptime_s, const PlcStore& store,
                            const modbus::Server* modbus, const web::Server* http, std::int64_t epoch_wall_ns,
                            const Program& p, const Supervisor* supervisor) {
  const StoreStatus st = store_status(store);
  nlohmann::json states = nlohmann::json::object();
  for (std::size_t i = 0; i < p.tasks.size(); ++i) {
    const Task& t = *p.tasks[i];
    if (supervisor && supervisor->hung(i))
      states[t.config().name] = {{"state", "hung"}, {"stop_reason", "a scan did not end: its outputs are safe, its thread given up"}};
    else if (t.stopped())
      states[t.config().name] = {{"state", "stopped"},
                                 {"stop_reason", t.stats.watchdog_trips.load() > 0 ? "its watchdog stopped it"
                                                                                   : "a driver's reaction stopped it"}};
  }
  return {{"version", "0.1.0"},
          {"project_file", project},
          {"uptime_s", uptime_s},
          {"epoch_wall_ns", epoch_wall_ns},
          {"store", {{"state", store_state_name(st.state)},
                     {"detail", st.error.empty() ? nlohmann::json(store.path()) : nlohmann::json(st.error)}}},
          {"modbus", modbus ? nlohmann::json(modbus->endpoint()) : nlohmann::json()},
          {"http", http ? nlohmann::json(http->url()) : nlohmann::json()},
          {"task_states", states}};
}

// A reload's result as the HTTP API answers it.
web::ChangeOutcome change_outcome(const ReloadResult& rr) {
  web::ChangeOutcome o;
  o.accepted = rr.accepted;
  o.summary = rr.summary;
  o.lines = rr.lines;
  o.status = rr.accepted ? 200 : (rr.summary.find("rejected (") != std::string::npos ? 400 : 409);
  nlohmann::json report{{"kept", nlohmann::json::array()}, {"retuned", nlohmann::json::array()},
                        {"new", nlohmann::json::array()}, {"removed", nlohmann::json::array()}};
  for (const auto& i : rr.instances) report[std::string(instance_fate_name(i.fate))].push_back(i.name);
  o.report = report;
  return o;
}

}  // namespace

int cmd_run(const RunOptions& options) {
  // Without a project file: the last accepted project in the database, as a
  // boot project (docs/store.md, "Projects"); it keeps that database.
  std::string project = options.project, db_option = options.db, origin = "run", source;
  if (project.empty()) {
    std::string why;
    const std::string db = db_option.empty() ? default_database_path() : db_option;
    auto boot = extract_version(db, 0, &why);
    if (!boot) {
      std::cerr << "syncplc: run: " << why << "\n";
      return kExitInvalid;
    }
    project = boot->project_file;
    db_option = db;
    origin = "boot";
    source = "version " + std::to_string(boot->number);
    std::cerr << "syncplc: starting version " << boot->number << " of " << db << " (" << project << ")\n";
  }
  const std::string& duration = options.duration;
  const bool no_status = options.no_status;
  const std::optional<int> modbus_port = options.modbus_port;
  const std::string& pid_file_option = options.pid_file;
  RealtimeRunner::Options runner_options;
  runner_options.cpu_latency_us = options.cpu_latency_us;
  std::optional<std::int64_t> limit;
  if (!duration.empty()) {
    std::string err;
    limit = parse_duration_ns(duration, &err);
    if (!limit || *limit <= 0) {
      std::cerr << "syncplc: --duration: " << (limit ? "must be positive" : err) << "\n";
      return kExitInvalid;
    }
    runner_options.duration_ns = *limit;  // counted from the first release, not from here
  }
  LoadOptions o;
  if (!parse_sets(options.sets, o)) return kExitInvalid;
  auto r = load_or_report(project, o);
  if (!r.ok()) {
    record_rejected_run(db_option.empty() ? default_database_path() : db_option, project_load(r, project, origin, source));
    return kExitInvalid;
  }
  store::ProjectLoad start = project_load(r, project, origin, source);  // before the program moves out of r
  const std::string start_hash = start.content.hash;
  std::unique_ptr<Program> program = std::move(r.program);

  // The PLC's database first: a second instance on it stops here, before
  // anything binds or moves; retain values are in the images before the first scan.
  std::string err;
  std::vector<std::string> notices;
  auto plc_store = PlcStore::open(database_path(db_option, r.store, project), *program, r, notices, &err,
                                  store::parse_start_mode(options.start).value_or(store::StartMode::Warm));
  if (!plc_store) {
    std::cerr << "syncplc: " << err << "\n";
    return kExitInvalid;
  }
  plc_store->record(std::move(start));  // written when the store thread starts
  for (const auto& n : notices) std::cerr << "syncplc: warning: " << n << "\n";
  for (const auto& n : plc_store->retain_notices()) std::cerr << "syncplc: " << n << "\n";
  RunEvents run_events(*plc_store);  // the event log and the Modbus audit trail

  // SIGINT/SIGTERM (stop) and SIGHUP (reload) are taken synchronously by this
  // thread only; task threads inherit the blocked mask and never see them.
  sigset_t sigs;
  sigemptyset(&sigs);
  sigaddset(&sigs, SIGINT);
  sigaddset(&sigs, SIGTERM);
  sigaddset(&sigs, SIGHUP);
  sigaddset(&sigs, SIGUSR1);
  sigaddset(&sigs, SIGUSR2);  // an online change asked for over HTTP (web_host.hpp)
  pthread_sigmask(SIG_BLOCK, &sigs, nullptr);
  signal(SIGPIPE, SIG_IGN);  // a Modbus client that goes away must not end the PLC

  // A start that fails from here on still leaves its record: the project
  // store's version (the project loaded: it stays a boot project) and a
  // start-failed event with the reason, written by one run of the store
  // thread (its retain job stores the values the PLC would have started with).
  auto start_failed = [&](const std::string& why, int status) {
    run_events.start_failed(why + " (exit status " + std::to_string(status) + ")");
    plc_store->start();
    plc_store->stop();
    return status;
  };
  if (!program->open_drivers(&err)) {
    std::cerr << "syncplc: " << err << "\n";
    return start_failed(err, kExitDriverFailed);
  }
  // The server binds before any task runs: a port in use stops here, cleanly.
  StoreStatusRegisters store_registers(*plc_store);
  auto modbus_server = start_modbus(*program, r.modbus, modbus_port, &run_events, &store_registers);
  if (!modbus_server && (modbus_port || r.modbus.server.enabled)) {
    program->close_drivers();
    const ModbusConfig cfg = server_config(r.modbus.server, modbus_port);
    return start_failed("the Modbus server could not listen on " + cfg.bind + ":" + std::to_string(cfg.port), kExitInvalid);
  }
  // The HTTP API and the HMI, bound before any task runs. A port given
  // with --http that is taken stops here; the default one only warns (the
  // machine keeps its control program when another service holds 8080).
  // Uploads beside the PLC's database (the default's directory when it keeps none).
  const std::string db_dir = plc_store->on() && plc_store->path() != store::kMemoryDatabase
                                 ? std::filesystem::path(plc_store->path()).parent_path().string()
                                 : std::filesystem::path(default_database_path()).parent_path().string();
  RunWebHost web_host(program.get(), *plc_store, o, (std::filesystem::path(db_dir) / "uploads").string());
  web_host.set_project_hash(start_hash);
  std::unique_ptr<web::Server> web_server;
  // However run ends, HTTP requests that wait for a change are answered
  // before the server's threads are joined (declared after web_server, so
  // it runs first).
  struct CloseWebHost {
    RunWebHost& host;
    ~CloseWebHost() { host.close(); }
  } close_web_host{web_host};
  std::string web_notice;  // where it listens, or why not: shown once the screen is up
  if (options.http.enabled) {
    web_server = std::make_unique<web::Server>(options.http, web_host);
    std::string why;
    if (!web_server->start(&why)) {
      web_server.reset();
      if (options.http.explicit_address || options.http.tls()) {
        std::cerr << "syncplc: " << why << "\n";
        if (modbus_server) modbus_server->stop();
        program->close_drivers();
        return start_failed(why, kExitInvalid);
      }
      web_notice = "warning: " + why + "; running without the HTTP API and the HMI";
    } else {
      web_notice = "HMI and HTTP API on " + web_server->url();
      // What /status says until the main loop's first turn.
      web_host.set_status(runtime_json(project, 0, *plc_store, modbus_server.get(), web_server.get(), 0, *program, nullptr));
    }
  }
  // `syncplc reload` finds this instance through its pid file.
  const std::string pid_file = pid_file_option.empty() ? default_pid_file(project) : pid_file_option;
  if (!write_instance_file(pid_file, project, &err)) std::cerr << "syncplc: warning: " << err << " (`syncplc reload` cannot find this instance)\n";
  struct RemovePidFile {
    std::string path;
    ~RemovePidFile() {
      std::remove(path.c_str());
      std::remove(reload_result_file(path).c_str());
    }
  } remove_pid_file{pid_file};
  auto runner = std::make_unique<RealtimeRunner>(*program, runner_options);
  runner->start();
  run_events.set_epoch(runner->epoch_ns());
  run_events.started(project, plc_store->path());
  plc_store->start();
  Reloader reloader(project, o, modbus_port);
  reloader.set_event_log(&run_events);
  reloader.set_store_status(&store_registers);
  // The HTTP threads go over to the new program when the change begins, as
  // the Modbus server does; the old one is never theirs again.
  reloader.set_readers([&web_host] { return web_host.hold(); }, [&web_host](Program& next) { web_host.set_program(&next); });
  Supervisor supervisor(*program, *runner);
  const bool live = !no_status && isatty(STDOUT_FILENO);
  LiveScreen screen(std::cout, live);  // the alternate screen, given back on every way out (live_screen.hpp)
  if (!web_notice.empty()) {
    if (live) screen.add_event(web_notice);
    else std::cerr << "syncplc: " << web_notice << "\n";
  }
  const std::int64_t t0 = runner->epoch_ns();  // the first release: --duration counts from here
  bool warned = false;
  int stop_signal = 0;
  bool all_stopped = false;
  for (;;) {
    const timespec wait = main_wait(t0, limit);
    int sig = sigtimedwait(&sigs, nullptr, &wait);
    if (sig == SIGINT || sig == SIGTERM) { stop_signal = sig; break; }
    // SIGHUP reloads a service (no live screen); for an interactive run it
    // means the terminal went away: stop cleanly rather than run on detached
    // holding the Modbus port. `syncplc reload` (SIGUSR1) reloads either.
    if (sig == SIGHUP && live) { stop_signal = sig; break; }
    Program& p = *program;
    if ((sig == SIGHUP || sig == SIGUSR1) && supervisor.any_hung()) {
      // A stuck thread never reaches its switch: the change could not complete.
      ReloadResult rr;
      rr.summary = "reload refused: a task's scan did not end and its thread cannot be stopped; restart syncplc";
      std::cerr << "syncplc: " << rr.summary << "\n";
      screen.set_reload_result(false, "refused: a task's scan did not end (restart syncplc)");
      run_events.reloaded(false, rr.summary, rr.lines);
      write_reload_result(pid_file, rr);
      continue;
    }
    // Online change: load and check the file first; only a good project
    // replaces the running one.
    auto apply_reload = [&](const ReloadFrom& from) {
      ReloadResult rr;
      rr = reloader.reload(program, *runner, modbus_server, plc_store.get(), std::cerr, from);
      if (rr.accepted) web_host.set_project_hash(rr.hash);
      for (const auto& line : rr.lines) std::cerr << line << "\n";
      run_events.reloaded(rr.accepted, rr.summary, rr.lines);
      // An event like the tasks' (the time on the tasks' axis), kept on the
      // live screen with the other events; the result stays apart until the next.
      const std::string event = fmt::format("[{:.6f}s] {:<14} {}", static_cast<double>(runner->now_ns()) * 1e-9,
                                            rr.accepted ? "reload" : "reload-failed", rr.summary);
      if (live) screen.add_event(event);
      else std::cerr << event << "\n";
      if (rr.accepted) screen.set_reload_result(true, rr.summary);
      else screen.set_reload_result(false, rr.summary, rr.lines);
      supervisor.attach(*program, *runner);
      return rr;
    };
    if (sig == SIGHUP || sig == SIGUSR1) {
      // `syncplc reload --version N`: that stored version, extracted, by online change.
      ReloadFrom from;
      if (const std::int64_t version = sig == SIGUSR1 ? take_reload_request(pid_file) : 0) {
        std::string why;
        auto v = extract_version(plc_store->path(), version, &why);
        if (!v) {
          ReloadResult refused;
          refused.summary = "rollback refused: " + why + "; the running program continues unchanged";
          std::cerr << "syncplc: " << refused.summary << "\n";
          write_reload_result(pid_file, refused);
          continue;
        }
        from = {v->project_file, "rollback", "version " + std::to_string(v->number)};
      }
      write_reload_result(pid_file, apply_reload(from));
      continue;
    }
    // Online changes asked for over HTTP (load, reload, rollback), one at a time.
    bool changed = false;
    for (web::ChangeRequest req; web_host.take_change(req); changed = true) {
      if (supervisor.any_hung()) {
        web::ChangeOutcome o;
        o.status = 409;
        o.summary = "reload refused: a task's scan did not end and its thread cannot be stopped; restart syncplc";
        web_host.finish_change(o);
        continue;
      }
      ReloadFrom from;
      const std::string by = " by " + req.user + " from " + req.client;
      if (req.kind == web::ChangeRequest::Kind::Load) {
        from = {req.project_file, "upload", "an upload" + by};
      } else if (req.kind == web::ChangeRequest::Kind::Rollback) {
        std::string why;
        auto v = extract_version(plc_store->path(), req.version, &why);
        if (!v) {
          web::ChangeOutcome o;
          o.status = 409;
          o.summary = "rollback refused: " + why + "; the running program continues unchanged";
          web_host.finish_change(o);
          continue;
        }
        from = {v->project_file, "rollback", "version " + std::to_string(v->number) + by};
      }
      const ReloadResult rr = apply_reload(from);
      // The status shows the new program before the HTTP client hears the change is done.
      web_host.set_status(runtime_json(project, static_cast<double>(RealtimeRunner::monotonic_ns() - t0) * 1e-9,
                                       *plc_store, modbus_server.get(), web_server.get(), run_events.wall_at_epoch_ns(),
                                       *program, &supervisor));
      web_host.finish_change(change_outcome(rr));
    }
    if (changed) continue;  // `p` was the program before the change
    reloader.poll(*runner, std::cerr, plc_store.get());
    if (!warned) {
      for (const auto& w : runner->warnings()) {
        if (live) screen.add_event("warning: " + w);
        else std::cerr << "syncplc: warning: " << w << "\n";
      }
      warned = !runner->warnings().empty() || RealtimeRunner::monotonic_ns() - t0 > 1'000'000'000;
    }
    supervisor.check();  // a scan that does not end: safe outputs, task stopped (supervisor.hpp)
    plc_store->watch_health();
    for_each_event(p, supervisor, run_events, [&](const std::string& line) {
      if (live) screen.add_event(line);
      else std::cerr << line << "\n";
    });
    double elapsed = static_cast<double>(std::max<std::int64_t>(0, RealtimeRunner::monotonic_ns() - t0)) * 1e-9;
    if (live) screen.set_store(store_status_line(store_status(*plc_store), plc_store->path()));
    screen.draw(p, elapsed, modbus_server.get(), &supervisor);
    if (web_server)
      web_host.set_status(runtime_json(project, elapsed, *plc_store, modbus_server.get(), web_server.get(),
                                       run_events.wall_at_epoch_ns(), p, &supervisor));
    if (limit && RealtimeRunner::monotonic_ns() - t0 >= *limit) break;
    if (supervisor.all_stopped()) {  // by their watchdogs, or given up on by the supervisor
      std::cerr << "syncplc: every task has stopped\n";
      all_stopped = true;
      break;
    }
    if (!runner->threads_alive()) break;  // the threads end by themselves after the --duration's last release
  }
  screen.leave();  // the statistics go to the normal screen
  web_host.close();  // HTTP requests waiting for a change are answered: none comes now
  if (web_server) web_server->stop();
  if (modbus_server) modbus_server->stop();
  // A thread stuck in a scan cannot be joined: its task's outputs are safe
  // (the supervisor), the others are stopped, and the process ends without it.
  const bool joined = supervisor.stop();
  if (joined) {
    runner->join();
    program->stop_drivers();  // a clean stop: the drivers' at_stop (keep or safe outputs), then closed
    plc_store->tasks_ended(*program);  // the historian's buckets in progress, stored by the final run
  }
  for_each_event(*program, supervisor, run_events, [](const std::string& line) { std::cerr << line << "\n"; });
  const int status = run_exit_status(joined, all_stopped, supervisor.any_hung());
  run_events.stopped(stop_reason(stop_signal, joined, all_stopped, status));
  plc_store->watch_health();
  plc_store->stop();  // after the tasks: its jobs' final run takes their last snapshots (and writes the stop event)
  if (!joined)
    std::cerr << "syncplc: a scan did not end; its task's outputs are in their safe state; exiting without its "
                 "thread (status " << status << ")\n";
  if (stop_signal)
    std::cout << "\nStopped by "
              << (stop_signal == SIGINT ? "SIGINT" : stop_signal == SIGTERM ? "SIGTERM" : "SIGHUP (the terminal hung up)") << "\n";
  print_statistics(std::cout, *program, false);
  print_driver_counters(std::cout, *program);
  if (modbus_server) {
    std::cout << "\nModbus TCP on " << modbus_server->endpoint() << "\n";
    modbus::print_counters(std::cout, modbus_server->counters().summary());
  }
  print_store_status(std::cout, *plc_store);
  if (!joined) {
    // Destructors would join the stuck thread (forever): end here.
    std::cout.flush();
    std::cerr.flush();
    std::_Exit(status);
  }
  return status;
}

}  // namespace syncplc::cli
