#include <fmt/format.h>
#include <signal.h>
#include <time.h>
#include <unistd.h>

#include <deque>
#include <iostream>
#include <set>
#include <sstream>

#include "runtime/cli/commands.hpp"
#include "runtime/core/realtime.hpp"
#include "runtime/modbus/server.hpp"
#include "runtime/project/online_change.hpp"
#include "runtime/project/report.hpp"

namespace syncplc::cli {
namespace {

// The live screen reads statistics (atomics) and published snapshots only:
// it never touches a task's image and never takes a lock a scan could wait on.
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

void draw_status(std::ostream& os, Program& p, double elapsed, const std::deque<std::string>& recent,
                 const modbus::Server* server) {
  std::ostringstream s;
  s << "\x1b[H\x1b[2J";
  s << fmt::format("syncplc run  {} {}  running {:.1f}s   (Ctrl-C stops; SIGHUP reloads the project file)\n\n", p.name, p.version, elapsed);
  print_statistics(s, p, false);
  if (server) {
    s << "\nModbus TCP on " << server->endpoint() << "\n";
    modbus::print_counters(s, server->counters().summary());
  }
  if (!p.watch.empty()) {
    s << "\nWatched tags\n";
    for (const auto& name : p.watch) {
      const Tag* t = p.find_tag(name);
      std::vector<Cell> v(t->length);
      p.read_tag(*t, v.data());
      std::string text;
      for (std::uint32_t i = 0; i < t->length && i < 8; ++i) text += (i ? ", " : "") + format_value(t->type, v[i]);
      if (t->length > 8) text += ", ...";
      s << fmt::format("  {:<20} {:<30} {}\n", name, text, t->unit);
    }
  }
  if (!recent.empty()) {
    s << "\nEvents\n";
    for (const auto& e : recent) s << "  " << e << "\n";
  }
  os << s.str() << std::flush;
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
    return kExitInvalid;
  }
  // The server binds before any task runs: a port in use stops here, cleanly.
  auto modbus_server = start_modbus(*program, modbus_port);
  if (!modbus_server && (modbus_port || program->modbus.enabled)) {
    program->close_drivers();
    return kExitInvalid;
  }
  auto runner = std::make_unique<RealtimeRunner>(*program, runner_options);
  runner->start();
  const bool live = !no_status && isatty(STDOUT_FILENO);
  const std::int64_t t0 = RealtimeRunner::monotonic_ns();
  std::deque<std::string> recent;
  bool warned = false;
  std::vector<bool> hung_reported(kMaxTasks, false);
  int stop_signal = 0;
  for (;;) {
    timespec wait{0, 250'000'000};
    int sig = sigtimedwait(&sigs, nullptr, &wait);
    if (sig == SIGINT || sig == SIGTERM) { stop_signal = sig; break; }
    Program& p = *program;
    if (sig == SIGHUP) {
      // Online change: load and check the file first; only a good project replaces the running one.
      auto next = load_project(project, o);
      if (!next.ok()) {
        for (const auto& d : next.diagnostics.sorted()) std::cerr << d.text() << "\n";
        std::cerr << "syncplc: reload failed; the running program continues unchanged\n";
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
            return kExitInvalid;
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
        }
        runner = std::make_unique<RealtimeRunner>(*program, runner_options);
        runner->start();
        warned = false;
      }
      continue;
    }
    if (!warned) {
      for (const auto& w : runner->warnings()) std::cerr << "syncplc: warning: " << w << "\n";
      warned = !runner->warnings().empty() || RealtimeRunner::monotonic_ns() - t0 > 1'000'000'000;
    }
    // A scan that has run past watchdog time × sensitivity is reported here:
    // its own watchdog only judges it when (if) it ends.
    for (std::size_t i = 0; i < p.tasks.size(); ++i) {
      const auto& c = p.tasks[i]->config();
      if (!c.watchdog) continue;
      std::int64_t running = runner->scan_running_ns(i);
      bool hung = running > c.watchdog_ns * c.sensitivity;
      if (hung && !hung_reported[i]) {
        std::string line = fmt::format("task {}: scan running for {} (watchdog {} x {}) and not finished; "
                                       "it cannot be interrupted: check the program", c.name, format_ns(running),
                                       format_duration(c.watchdog_ns), c.sensitivity);
        std::cerr << "syncplc: " << line << "\n";
        if (live) recent.push_back(line);
      }
      hung_reported[i] = hung;
    }
    for (auto& t : p.tasks) {
      Event e;
      while (t->pop_event(e)) {
        std::string line = format_event(p, e);
        if (live) {
          recent.push_back(line);
          if (recent.size() > 6) recent.pop_front();
        } else {
          std::cerr << line << "\n";
        }
      }
    }
    double elapsed = static_cast<double>(RealtimeRunner::monotonic_ns() - t0) * 1e-9;
    if (live) draw_status(std::cout, p, elapsed, recent, modbus_server.get());
    if (limit && RealtimeRunner::monotonic_ns() - t0 >= *limit) break;
    if (!runner->running()) {
      std::cerr << "syncplc: every task has stopped\n";
      break;
    }
  }
  if (modbus_server) modbus_server->stop();
  runner->request_stop();
  runner->join();
  program->close_drivers();
  print_events(std::cerr, *program);
  if (stop_signal) std::cout << "\nStopped by " << (stop_signal == SIGINT ? "SIGINT" : "SIGTERM") << "\n";
  print_statistics(std::cout, *program, false);
  if (modbus_server) {
    std::cout << "\nModbus TCP on " << modbus_server->endpoint() << "\n";
    modbus::print_counters(std::cout, modbus_server->counters().summary());
  }
  return kExitOk;
}

}  // namespace syncplc::cli
