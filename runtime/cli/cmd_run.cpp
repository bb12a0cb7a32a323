#include <fmt/format.h>
#include <signal.h>
#include <time.h>
#include <unistd.h>

#include <algorithm>
#include <cstdlib>
#include <iostream>
#include <set>

#include "runtime/cli/commands.hpp"
#include "runtime/cli/live_screen.hpp"
#include "runtime/core/realtime.hpp"
#include "runtime/core/supervisor.hpp"
#include "runtime/modbus/server.hpp"
#include "runtime/project/online_change.hpp"
#include "runtime/project/report.hpp"

namespace syncplc::cli {
namespace {

// The settings a running server cannot change without a restart.
bool same_server(const ModbusConfig& a, const ModbusConfig& b) {
  auto key = [](const ModbusConfig& c) {
    std::string nets;
    for (const auto& n : c.allowed_clients) nets += std::to_string(n.address) + "/" + std::to_string(n.prefix) + ",";
    return std::make_tuple(c.enabled, c.port, c.bind, c.unit_id, c.max_clients, c.idle_timeout_ns, c.word_order, nets,
                           c.read_only, c.cpus);
  };
  return key(a) == key(b);
}

std::unique_ptr<modbus::Server> start_modbus(Program& p, std::optional<int> port_override) {
  ModbusConfig cfg = p.modbus;
  if (port_override) {
    cfg.enabled = true;
    cfg.port = *port_override;
  }
  if (!cfg.enabled) return nullptr;
  auto server = std::make_unique<modbus::Server>(p, cfg);
  std::string err;
  if (!server->start(&err)) {
    std::cerr << "syncplc: modbus: " << err << "\n";
    return nullptr;
  }
  std::cerr << "syncplc: modbus: listening on " << server->endpoint() << " (unit " << cfg.unit_id << ", "
            << server->handler_map_size() << " values mapped)\n";
  if (server->off_task_cpus()) {
    std::set<int> pinned;
    for (const auto& t : p.tasks)
      if (t->config().cpu >= 0) pinned.insert(t->config().cpu);
    std::string cpus;
    for (int c : pinned) cpus += (cpus.empty() ? "" : ", ") + std::to_string(c);
    std::cerr << "syncplc: modbus: the server thread keeps off CPU " << cpus << " (pinned tasks)\n";
  }
  if (!server->warning().empty()) std::cerr << "syncplc: modbus: warning: " << server->warning() << "\n";
  return server;
}

// How long the main thread waits for a signal: a tenth of a second (the
// supervisor's and the live screen's pace), or up to
// the end of the --duration when that is nearer.
timespec main_wait(std::int64_t epoch_ns, const std::optional<std::int64_t>& limit) {
  std::int64_t ns = 100'000'000;
  if (limit) ns = std::clamp<std::int64_t>(epoch_ns + *limit - RealtimeRunner::monotonic_ns(), 1'000'000, ns);
  return timespec{0, static_cast<long>(ns)};
}

// The tasks' events and the supervisor's, one formatted line each.
template <class F>
void for_each_event(Program& p, Supervisor& supervisor, F&& f) {
  Event e;
  for (auto& t : p.tasks)
    while (t->pop_event(e)) f(format_event(p, e));
  while (supervisor.pop_event(e)) f(format_event(p, e));
}

// Why `run` ended (commands.hpp): a requested stop is 0.
int run_exit_status(bool joined, bool all_stopped, bool any_hung) {
  if (!joined || (all_stopped && any_hung)) return kExitHungScan;
  if (all_stopped) return kExitWatchdogStopped;
  return kExitOk;
}

}  // namespace

int cmd_run(const std::string& project, const std::string& duration, const std::vector<std::string>& sets,
            bool no_status, int cpu_latency_us, std::optional<int> modbus_port) {
  RealtimeRunner::Options runner_options;
  runner_options.cpu_latency_us = cpu_latency_us;
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
  if (!parse_sets(sets, o)) return kExitInvalid;
  auto r = load_or_report(project, o);
  if (!r.ok()) return kExitInvalid;
  std::unique_ptr<Program> program = std::move(r.program);

  // SIGINT/SIGTERM (stop) and SIGHUP (reload) are taken synchronously by this
  // thread only; task threads inherit the blocked mask and never see them.
  sigset_t sigs;
  sigemptyset(&sigs);
  sigaddset(&sigs, SIGINT);
  sigaddset(&sigs, SIGTERM);
  sigaddset(&sigs, SIGHUP);
  pthread_sigmask(SIG_BLOCK, &sigs, nullptr);
  signal(SIGPIPE, SIG_IGN);  // a Modbus client that goes away must not end the PLC

  std::string err;
  if (!program->open_drivers(&err)) {
    std::cerr << "syncplc: " << err << "\n";
    return kExitDriverFailed;
  }
  // The server binds before any task runs: a port in use stops here, cleanly.
  auto modbus_server = start_modbus(*program, modbus_port);
  if (!modbus_server && (modbus_port || program->modbus.enabled)) {
    program->close_drivers();
    return kExitInvalid;
  }
  auto runner = std::make_unique<RealtimeRunner>(*program, runner_options);
  runner->start();
  Supervisor supervisor(*program, *runner);
  const bool live = !no_status && isatty(STDOUT_FILENO);
  LiveScreen screen(std::cout, live);  // the alternate screen, given back on every way out (live_screen.hpp)
  const std::int64_t t0 = runner->epoch_ns();  // the first release: --duration counts from here
  bool warned = false;
  int stop_signal = 0;
  bool all_stopped = false;
  for (;;) {
    const timespec wait = main_wait(t0, limit);
    int sig = sigtimedwait(&sigs, nullptr, &wait);
    if (sig == SIGINT || sig == SIGTERM) { stop_signal = sig; break; }
    Program& p = *program;
    if (sig == SIGHUP && supervisor.any_hung()) {  // a stuck thread cannot be stopped: a reload would wait forever
      std::cerr << "syncplc: reload refused: a task's scan did not end and its thread cannot be stopped; "
                   "restart syncplc\n";
      screen.set_reload_result(false, "refused: a task's scan did not end (restart syncplc)");
      continue;
    }
    if (sig == SIGHUP) {
      // Online change: load and check the file first; only a good project replaces the running one.
      auto next = load_project(project, o);
      if (!next.ok()) {
        std::vector<std::string> errors;
        for (const auto& d : next.diagnostics.sorted()) {
          std::cerr << d.text() << "\n";
          errors.push_back(d.text());
        }
        std::cerr << "syncplc: reload failed; the running program continues unchanged\n";
        screen.set_reload_result(false, fmt::format("{} error{} in {}", errors.size(), errors.size() == 1 ? "" : "s",
                                                    project), errors);
      } else {
        // No request is taken from here until the server has the program to
        // serve: a write acknowledged before reaches the old queues, which are
        // applied to the old image and so carried over with the tags.
        if (modbus_server) modbus_server->hold();
        runner->request_stop();
        runner->join();
        p.close_drivers();
        print_events(std::cerr, p);
        for (auto& t : p.tasks) t->flush_queued_writes();
        std::size_t kept = carry_over_tags(p, *next.program);
        if (!next.program->open_drivers(&err)) {
          std::cerr << "syncplc: reload: " << err << "; restarting the previous program\n";
          if (!p.open_drivers(&err)) {
            std::cerr << "syncplc: " << err << "\n";
            return kExitDriverFailed;
          }
          if (modbus_server) modbus_server->replace_program(p);  // the same program again
        } else {
          // The server lets go of the old program before it is destroyed;
          // changed server settings mean a new server (clients reconnect).
          ModbusConfig next_cfg = next.program->modbus;
          if (modbus_port) { next_cfg.enabled = true; next_cfg.port = *modbus_port; }
          if (modbus_server && same_server(modbus_server->config(), next_cfg)) {
            modbus_server->replace_program(*next.program);
          } else {
            modbus_server.reset();
            modbus_server = start_modbus(*next.program, modbus_port);
          }
          program = std::move(next.program);
          std::cerr << "syncplc: reloaded " << project << " (" << kept << " tag values carried over)\n";
          screen.set_reload_result(true, fmt::format("{} ({} tag values carried over)", project, kept));
        }
        runner = std::make_unique<RealtimeRunner>(*program, runner_options);
        runner->start();
        supervisor.attach(*program, *runner);
        warned = false;
      }
      continue;
    }
    if (!warned) {
      for (const auto& w : runner->warnings()) {
        if (live) screen.add_event("warning: " + w);
        else std::cerr << "syncplc: warning: " << w << "\n";
      }
      warned = !runner->warnings().empty() || RealtimeRunner::monotonic_ns() - t0 > 1'000'000'000;
    }
    supervisor.check();  // a scan that does not end: safe outputs, task stopped (supervisor.hpp)
    for_each_event(p, supervisor, [&](const std::string& line) {
      if (live) screen.add_event(line);
      else std::cerr << line << "\n";
    });
    double elapsed = static_cast<double>(std::max<std::int64_t>(0, RealtimeRunner::monotonic_ns() - t0)) * 1e-9;
    screen.draw(p, elapsed, modbus_server.get(), &supervisor);
    if (limit && RealtimeRunner::monotonic_ns() - t0 >= *limit) break;
    if (supervisor.all_stopped()) {  // by their watchdogs, or given up on by the supervisor
      std::cerr << "syncplc: every task has stopped\n";
      all_stopped = true;
      break;
    }
    if (!runner->running()) break;  // the threads end by themselves after the --duration's last release
  }
  screen.leave();  // the statistics go to the normal screen
  if (modbus_server) modbus_server->stop();
  // A thread stuck in a scan cannot be joined: its task's outputs are safe
  // (the supervisor), the others are stopped, and the process ends without it.
  const bool joined = supervisor.stop();
  if (joined) {
    runner->join();
    program->close_drivers();
  }
  for_each_event(*program, supervisor, [](const std::string& line) { std::cerr << line << "\n"; });
  const int status = run_exit_status(joined, all_stopped, supervisor.any_hung());
  if (!joined)
    std::cerr << "syncplc: a scan did not end; its task's outputs are in their safe state; exiting without its "
                 "thread (status " << status << ")\n";
  if (stop_signal) std::cout << "\nStopped by " << (stop_signal == SIGINT ? "SIGINT" : "SIGTERM") << "\n";
  print_statistics(std::cout, *program, false);
  if (modbus_server) {
    std::cout << "\nModbus TCP on " << modbus_server->endpoint() << "\n";
    modbus::print_counters(std::cout, modbus_server->counters().summary());
  }
  if (!joined) {
    // Destructors would join the stuck thread (forever): end here.
    std::cout.flush();
    std::cerr.flush();
    std::_Exit(status);
  }
  return status;
}

}  // namespace syncplc::cli
