// The subcommands of `syncplc`. Each returns the process exit status:
// 0 success, 1 test failure, 2 invalid input or usage; `run` says why it
// ended with the statuses below (docs/user-guide.md, "Exit statuses").
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "runtime/cli/api_client.hpp"
#include "runtime/project/loader.hpp"
#include "runtime/web/web_config.hpp"

namespace syncplc::cli {

constexpr int kExitOk = 0;
constexpr int kExitTestFailed = 1;
constexpr int kExitInvalid = 2;
// `syncplc run` ended by itself because every task was stopped by its
// watchdog: a failure, so that a service manager restarts it.
constexpr int kExitWatchdogStopped = 3;
// A scan that did not end forced the end of `run`: its task's outputs were
// put in their safe state and the process exited without its thread.
constexpr int kExitHungScan = 4;
// An I/O driver failed (it could not be opened).
constexpr int kExitDriverFailed = 5;
// An online command found no `syncplc run` answering at its URL, or lost
// it (a script tells "the PLC is down" from "the PLC said no", which is 2).
constexpr int kExitUnreachable = 6;

// Loads a project, printing every diagnostic to stderr on failure.
LoadResult load_or_report(const std::string& path, const LoadOptions& options);
bool parse_sets(const std::vector<std::string>& sets, LoadOptions& options);

int cmd_check(const std::string& project);
int cmd_blocks(const std::string& name, bool markdown, const std::string& project = "");
int cmd_sim(const std::string& project, const std::string& duration, std::optional<std::uint64_t> seed,
            const std::string& trace, const std::vector<std::string>& sets, bool quiet, const std::string& metrics_path);
struct RunOptions {
  std::string project;            // "" : the last accepted project in the database
  std::string duration;           // --duration; "" until stopped
  std::vector<std::string> sets;  // --set
  bool no_status = false;
  int cpu_latency_us = 0;
  std::string align;  // --align: the grid anchored to CLOCK_REALTIME ("" : not)
  std::optional<int> modbus_port;
  std::string pid_file;  // "" : default_pid_file(project)
  std::string db;        // --db: the PLC's database ("" : the project's store: path, else the default; docs/store.md)
  std::string start = "warm";  // --start warm|cold|origin: which retained values come back (docs/store.md)
  web::WebConfig http;         // --http ...: the HTTP API and the HMI (docs/http-api.md)
};
int cmd_run(const RunOptions& options);
// With an API URL (--url or $SYNCPLC_URL in `online`), through the API:
// POST /projects/reload, or /projects/rollback for a version.
int cmd_reload(const std::string& project, const std::string& pid_file, std::int64_t version,
               const OnlineOptions& online);
int reload_through_api(std::int64_t version, const OnlineOptions& online);
// `syncplc projects`: the project store's versions; with `show`, version
// `show`'s files (all, or the one named `file`).
int cmd_projects(const std::string& db, std::int64_t show, const std::string& file);
struct EventsOptions {
  std::string db;                  // "" : the default database (docs/store.md)
  std::string since;               // --since: "10m", "2026-11-25T10:00:00"; "" : all
  bool follow = false;             // keep printing new events until Ctrl-C
  std::vector<std::string> kinds;  // --kind (repeatable); empty: all
  OnlineOptions online;            // with a URL (--url or $SYNCPLC_URL) and no --db: GET /events
};
int cmd_events(const EventsOptions& options);
// `syncplc reset cold|origin [PROJECT] [--db PATH]`: deletes stored retain values (docs/store.md).
int cmd_reset(const std::string& kind, const std::string& project, const std::string& db);
struct TrendOptions {
  std::vector<std::string> tags;  // labels ("pos[2]") or tags (all their elements)
  std::string db;                 // "" : the default database (docs/store.md)
  std::string since, until;       // "" : unbounded (wall_time.hpp: parse_when)
  bool csv = false;
};
int cmd_trend(const TrendOptions& options);
// syncplc design-compensator (cmd_design.cpp).
struct DesignOptions {
  std::string loop;                       // the loop file (YAML)
  double loss = 0;                        // Bernoulli dropout rate
  int order = 4;                          // taps of the compensator
  std::vector<std::vector<double>> taps;  // more compensators to compare (--taps a1,a2,...)
  bool json = false;
};
int cmd_design_compensator(const DesignOptions& options);
int cmd_test(const std::string& project, const std::string& tests, const std::string& junit);
// `syncplc user add|passwd|role|remove|list`: the users of the HTTP API and
// the HMI in the PLC's database (docs/user-guide.md).
struct UserOptions {
  std::string action;           // add, passwd, role, remove, list
  std::string name;             // NAME (all but list)
  std::string role;             // add: --role; role: ROLE
  bool password_stdin = false;  // add, passwd: one line of stdin instead of asking on the terminal
  std::string db;               // --db; "" : the project's store: path, else the default (docs/store.md)
  std::string project;          // PROJECT: whose store: path names the database
};
int cmd_user(const UserOptions& options);

// The online commands: a running `syncplc run` through its HTTP API
// (docs/http-api.md; docs/user-guide.md, "Online commands").
int cmd_status(const OnlineOptions& o);
int cmd_read(const std::vector<std::string>& refs, const OnlineOptions& o);
int cmd_write(const std::string& tag, const std::string& value, const OnlineOptions& o);
int cmd_force(const std::string& ref, const std::string& value, const OnlineOptions& o);
int cmd_unforce(const std::string& ref, bool all, const OnlineOptions& o);
struct WatchOptions {
  std::vector<std::string> refs;
  int rate = 10;            // updates per second, 1..50
  std::optional<int> count; // stop after this many updates
};
int cmd_watch(const WatchOptions& w, const OnlineOptions& o);
// `syncplc load PROJECT [--check]`: the project's files uploaded and
// loaded by online change (or only checked).
int cmd_load(const std::string& project, bool check_only, const OnlineOptions& o);
int cmd_rollback(std::int64_t version, const OnlineOptions& o);
// `syncplc events --url`: the event log through GET /events.
int events_through_api(const EventsOptions& options);

}  // namespace syncplc::cli
