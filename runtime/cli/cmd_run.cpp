#include <fmt/format.h>
#include <signal.h>
#include <time.h>
#include <unistd.h>

#include <cstdio>
#include <deque>
#include <fstream>
#include <iostream>
#include <set>
#include <sstream>

#include "runtime/cli/commands.hpp"
#include "runtime/core/realtime.hpp"
#include "runtime/modbus/server.hpp"
#include "runtime/cli/instance_file.hpp"
#include "runtime/cli/reload.hpp"
#include "runtime/cli/serve_modbus.hpp"
#include "runtime/project/report.hpp"

namespace syncplc::cli {
namespace {

// The live screen reads statistics (atomics) and published snapshots only:
// it never touches a task's image and never takes a lock a scan could wait on.
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

}  // namespace

int cmd_run(const std::string& project, const std::string& duration, const std::vector<std::string>& sets,
            bool no_status, int cpu_latency_us, std::optional<int> modbus_port, const std::string& pid_file_option) {
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
  sigaddset(&sigs, SIGUSR1);
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
  Reloader reloader(project, o, modbus_port);
  const bool live = !no_status && isatty(STDOUT_FILENO);
  const std::int64_t t0 = RealtimeRunner::monotonic_ns();
  std::deque<std::string> recent;
  bool warned = false;
  std::vector<bool> hung_reported(64, false);
  int stop_signal = 0;
  for (;;) {
    timespec wait{0, 250'000'000};
    int sig = sigtimedwait(&sigs, nullptr, &wait);
    if (sig == SIGINT || sig == SIGTERM) { stop_signal = sig; break; }
    // SIGHUP reloads a service (no live screen); for an interactive run it
    // means the terminal went away: stop cleanly rather than run on detached
    // holding the Modbus port. `syncplc reload` (SIGUSR1) reloads either.
    if (sig == SIGHUP && live) { stop_signal = sig; break; }
    Program& p = *program;
    if (sig == SIGHUP || sig == SIGUSR1) {
      // Online change: load and check the file first; only a good project replaces the running one.
      ReloadResult rr = reloader.reload(program, *runner, modbus_server, std::cerr);
      for (const auto& line : rr.lines) std::cerr << line << "\n";
      std::cerr << "syncplc: " << rr.summary << "\n";
      if (live) recent.push_back(rr.summary);
      write_reload_result(pid_file, rr);
      continue;
    }
    reloader.poll(*runner, std::cerr);
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
  if (stop_signal)
    std::cout << "\nStopped by "
              << (stop_signal == SIGINT ? "SIGINT" : stop_signal == SIGTERM ? "SIGTERM" : "SIGHUP (the terminal hung up)") << "\n";
  print_statistics(std::cout, *program, false);
  if (modbus_server) {
    std::cout << "\nModbus TCP on " << modbus_server->endpoint() << "\n";
    modbus::print_counters(std::cout, modbus_server->counters().summary());
  }
  return kExitOk;
}

}  // namespace syncplc::cli
