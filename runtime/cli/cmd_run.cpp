// `syncplc run`: the command line over the PLC instance (runtime/plc/plc.hpp):
// its arguments, the terminal (the live screen) and the signals. Everything
// the running PLC does, the instance does.
#include <fmt/format.h>
#include <signal.h>
#include <time.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <deque>
#include <fstream>
#include <iostream>
#include <mutex>

#include "runtime/cli/commands.hpp"
#include "runtime/cli/instance_file.hpp"
#include "runtime/cli/live_screen.hpp"
#include "runtime/core/monotonic_clock.hpp"
#include "runtime/plc/plc.hpp"
#include "runtime/plc/project_versions.hpp"
#include "runtime/plc/store_link.hpp"
#include "runtime/plc/store_status.hpp"
#include "runtime/project/report.hpp"

namespace syncplc::cli {
namespace {

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

// The outcome of a reload, for `syncplc reload` (written whole, then renamed).
void write_reload_result(const std::string& pid_file, const plc::ChangeResult& r) {
  const std::string path = reload_result_file(pid_file), tmp = path + ".tmp";
  {
    std::ofstream f(tmp, std::ios::trunc);
    f << (r.accepted ? "accepted: " : "rejected: ") << r.summary << "\n";
    for (const auto& line : r.lines) f << line << "\n";
  }
  std::rename(tmp.c_str(), path.c_str());
}

// What the PLC's threads hand the main thread: event lines and change
// outcomes, shown at the next turn of its loop (the screen is the main thread's).
class Inbox {
 public:
  void line(std::string l) {
    std::lock_guard lock(mutex_);
    lines_.push_back(std::move(l));
  }
  void result(plc::ChangeResult r) {
    std::lock_guard lock(mutex_);
    results_.push_back(std::move(r));
  }
  template <class L, class R>
  void drain(L&& on_line, R&& on_result) {
    std::deque<std::string> lines;
    std::deque<plc::ChangeResult> results;
    {
      std::lock_guard lock(mutex_);
      lines.swap(lines_);
      results.swap(results_);
    }
    for (auto& l : lines) on_line(l);
    for (auto& r : results) on_result(r);
  }

 private:
  std::mutex mutex_;
  std::deque<std::string> lines_;
  std::deque<plc::ChangeResult> results_;
};

}  // namespace

int cmd_run(const RunOptions& options) {
  plc::PlcOptions po;
  // Without a project file: the last accepted project in the database, as a
  // boot project (docs/store.md, "Projects"); it keeps that database.
  po.project = options.project;
  po.db = options.db;
  if (po.project.empty()) {
    std::string why;
    const std::string db = po.db.empty() ? plc::default_database_path() : po.db;
    auto boot = plc::extract_version(db, 0, &why);
    if (!boot) {
      std::cerr << "syncplc: run: " << why << "\n";
      return kExitInvalid;
    }
    po.project = boot->project_file;
    po.db = db;
    po.origin = "boot";
    po.source = "version " + std::to_string(boot->number);
    std::cerr << "syncplc: starting version " << boot->number << " of " << db << " (" << po.project << ")\n";
  }
  std::optional<std::int64_t> limit;
  if (!options.duration.empty()) {
    std::string err;
    limit = parse_duration_ns(options.duration, &err);
    if (!limit || *limit <= 0) {
      std::cerr << "syncplc: --duration: " << (limit ? "must be positive" : err) << "\n";
      return kExitInvalid;
    }
    po.runner.duration_ns = *limit;  // counted from the first release, not from here
  }
  po.runner.cpu_latency_us = options.cpu_latency_us;
  if (!options.align.empty()) {
    std::string err;
    const auto a = parse_duration_ns(options.align, &err);
    if (!a || *a <= 0) {
      std::cerr << "syncplc: --align: " << (a ? "must be positive" : err) << "\n";
      return kExitInvalid;
    }
    po.runner.align_ns = *a;
  }
  if (!parse_sets(options.sets, po.load)) return kExitInvalid;
  const auto start = store::parse_start_mode(options.start);
  po.start = start.value_or(store::StartMode::Warm);
  po.modbus_port = options.modbus_port;
  po.http = options.http;
  po.log = &std::cerr;
  po.status_invalid = kExitInvalid;
  po.status_driver_failed = kExitDriverFailed;

  // SIGINT/SIGTERM (stop) and SIGHUP/SIGUSR1 (reload) are taken synchronously
  // by this thread only: blocked before the PLC starts any thread, so every
  // thread it starts inherits the mask and never sees them.
  sigset_t sigs;
  sigemptyset(&sigs);
  sigaddset(&sigs, SIGINT);
  sigaddset(&sigs, SIGTERM);
  sigaddset(&sigs, SIGHUP);
  sigaddset(&sigs, SIGUSR1);
  pthread_sigmask(SIG_BLOCK, &sigs, nullptr);
  signal(SIGPIPE, SIG_IGN);  // a Modbus or HTTP client that goes away must not end the PLC

  std::vector<std::string> notices;
  plc::PlcFailure failure;
  auto plc = plc::Plc::open(po, notices, &failure);  // says its notices on po.log as they come
  if (!plc) {
    if (failure.load_errors) {
      const auto n = static_cast<std::size_t>(std::count(failure.why.begin(), failure.why.end(), '\n')) + 1;
      std::cerr << failure.why << "\n" << po.project << ": " << n << (n == 1 ? " error" : " errors") << ", project not loaded\n";
    } else {
      std::cerr << "syncplc: " << failure.why << "\n";
    }
    return failure.status;
  }
  // `syncplc reload` finds this instance through its pid file.
  const std::string pid_file = options.pid_file.empty() ? default_pid_file(po.project) : options.pid_file;
  std::string err;
  if (!write_instance_file(pid_file, po.project, &err))
    std::cerr << "syncplc: warning: " << err << " (`syncplc reload` cannot find this instance)\n";
  struct RemovePidFile {
    std::string path;
    ~RemovePidFile() {
      std::remove(path.c_str());
      std::remove(reload_result_file(path).c_str());
    }
  } remove_pid_file{pid_file};

  Inbox inbox;
  plc->on_event_line([&inbox](const std::string& l) { inbox.line(l); });
  const bool live = !options.no_status && isatty(STDOUT_FILENO);
  plc->start();
  LiveScreen screen(std::cout, live);  // the alternate screen, given back on every way out (live_screen.hpp)
  if (!plc->http_notice().empty()) {
    if (live) screen.add_event(plc->http_notice());
    else std::cerr << "syncplc: " << plc->http_notice() << "\n";
  }
  const std::int64_t t0 = plc->epoch_ns();  // the first release: --duration counts from here
  bool warned = false;
  int stop_signal = 0;
  for (;;) {
    // A tenth of a second (the live screen's pace), or up to the end of the
    // --duration when that is nearer.
    std::int64_t wait_ns = 100'000'000;
    if (limit) wait_ns = std::clamp<std::int64_t>(t0 + *limit - monotonic_ns(), 1'000'000, wait_ns);
    const timespec wait{0, static_cast<long>(wait_ns)};
    const int sig = sigtimedwait(&sigs, nullptr, &wait);
    if (sig == SIGINT || sig == SIGTERM) { stop_signal = sig; break; }
    // SIGHUP reloads a service (no live screen); for an interactive run it
    // means the terminal went away: stop cleanly rather than run on detached
    // holding the Modbus port. `syncplc reload` (SIGUSR1) reloads either.
    if (sig == SIGHUP && live) { stop_signal = sig; break; }
    if (sig == SIGHUP || sig == SIGUSR1) {
      // `syncplc reload --version N`: that stored version, by online change.
      plc::ChangeRequest req;
      if (const std::int64_t version = sig == SIGUSR1 ? plc::take_reload_request(pid_file) : 0) {
        req.kind = plc::ChangeRequest::Kind::Rollback;
        req.version = version;
      }
      // Carried out by the PLC's control thread: this thread goes on taking
      // signals (a SIGTERM during a change ends the run at once).
      plc->request_change(req, [&inbox, pid_file](const plc::ChangeResult& r) {
        write_reload_result(pid_file, r);
        inbox.result(r);
      });
    }
    inbox.drain(
        [&](const std::string& line) {
          // Events ("[t] kind ...") on the screen; a change's report lines on
          // stderr, where they stay readable.
          if (live && !line.empty() && line[0] == '[') screen.add_event(line);
          else std::cerr << line << "\n";
        },
        [&](const plc::ChangeResult& r) {
          // A change the PLC's state refused (a scan that did not end, a
          // version that cannot be extracted) is said on its own line too.
          if (!r.accepted && r.status == 409) std::cerr << "syncplc: " << r.summary << "\n";
          if (r.accepted) screen.set_reload_result(true, r.summary);
          else screen.set_reload_result(false, r.summary, r.lines);
        });
    if (!warned) {
      for (const auto& w : plc->runner_warnings()) {
        if (live) screen.add_event("warning: " + w);
        else std::cerr << "syncplc: warning: " << w << "\n";
      }
      warned = !plc->runner_warnings().empty() || monotonic_ns() - t0 > 1'000'000'000;
    }
    const double elapsed = static_cast<double>(std::max<std::int64_t>(0, monotonic_ns() - t0)) * 1e-9;
    if (live) screen.set_store(plc::store_status_line(plc::store_status(plc->store()), plc->store().path()));
    plc->with_view([&](const plc::Plc::View& v) { screen.draw(v.program, elapsed, v.modbus, v.supervisor); });
    if (limit && monotonic_ns() - t0 >= *limit) break;
    if (plc->all_stopped()) {  // by their watchdogs, or given up on by the supervisor
      std::cerr << "syncplc: every task has stopped\n";
      break;
    }
    if (plc->ended()) break;  // the threads end by themselves after the --duration's last release
  }
  screen.leave();  // the statistics go to the normal screen
  const bool all_stopped = plc->all_stopped();
  // The reason is known once the threads are joined (or given up on): the
  // stop records it then.
  plc::StopReport report;
  int status = kExitOk;
  report = plc->stop([&](const plc::StopReport& r) {
    status = run_exit_status(r.joined, all_stopped || r.all_stopped, r.any_hung);
    return stop_reason(stop_signal, r.joined, all_stopped || r.all_stopped, status);
  });
  inbox.drain([](const std::string& line) { std::cerr << line << "\n"; }, [](const plc::ChangeResult&) {});
  if (!report.joined)
    std::cerr << "syncplc: a scan did not end; its task's outputs are in their safe state; exiting without its "
                 "thread (status " << status << ")\n";
  if (stop_signal)
    std::cout << "\nStopped by "
              << (stop_signal == SIGINT ? "SIGINT" : stop_signal == SIGTERM ? "SIGTERM" : "SIGHUP (the terminal hung up)") << "\n";
  plc->with_view([&](const plc::Plc::View& v) {
    print_statistics(std::cout, v.program, false);
    print_driver_counters(std::cout, v.program);
    if (v.modbus) {
      std::cout << "\nModbus TCP on " << v.modbus->endpoint() << "\n";
      modbus::print_counters(std::cout, v.modbus->counters().summary());
    }
  });
  plc::print_store_status(std::cout, plc->store());
  if (!report.joined) {
    // Destructors would join the stuck thread (forever): end here.
    std::cout.flush();
    std::cerr.flush();
    std::_Exit(status);
  }
  return status;
}

}  // namespace syncplc::cli
