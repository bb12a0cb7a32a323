// syncplc: a soft-PLC for synchronized multi-axis motion.
#include <CLI/CLI.hpp>
#include <cmath>
#include <cstdlib>
#include <sstream>

#include <iostream>

#include "runtime/cli/commands.hpp"

namespace {

// What every online command takes: where the PLC is and who asks.
void add_online_options(CLI::App* cmd, syncplc::cli::OnlineOptions& o) {
  cmd->add_option("--url", o.url, "the PLC's HTTP API (default: $SYNCPLC_URL, else http://127.0.0.1:8080)");
  cmd->add_option("--cacert", o.cacert, "the certificate that signs an https URL's (a self-signed one itself)");
  cmd->add_option("--user", o.user, "log in as this user (default: $SYNCPLC_USER; none: anonymous reads)");
  cmd->add_flag("--password-stdin", o.password_stdin,
                "read the password from stdin's first line (else $SYNCPLC_PASSWORD, else asked on the terminal)");
}

}  // namespace

int main(int argc, char** argv) {
  using namespace syncplc::cli;
  CLI::App app{"syncplc - an IEC 61131-3 function-block soft-PLC for synchronized multi-axis motion"};
  app.require_subcommand(1);
  app.set_version_flag("--version", "syncplc 0.1.0");

  std::string project, duration, trace, tests, junit, block, metrics, pid_file, db, start = "warm", reset_kind;
  std::optional<std::uint64_t> seed;
  std::vector<std::string> sets;
  bool markdown = false, quiet = false, no_status = false;
  int cpu_latency_us = 0;
  std::optional<int> modbus_port;

  auto* check = app.add_subcommand("check", "validate a project; print its task table, execution order and tag map");
  check->add_option("PROJECT", project, "project file (YAML), or a system file (every node and their topics)")->required();

  auto* blocks = app.add_subcommand("blocks", "list the block library, or describe one block type");
  blocks->add_option("TYPE", block, "a block type, e.g. TON");
  blocks->add_flag("--markdown", markdown, "print the library as Markdown (docs/blocks.md)");
  std::string blocks_project;
  blocks->add_option("--project,-p", blocks_project, "also the project's Structured Text FUNCTION_BLOCKs and PROGRAMs");

  auto* sim = app.add_subcommand("sim", "run a project in virtual time, as fast as the CPU allows");
  sim->add_option("PROJECT", project, "project file (YAML), or a system file listing the nodes of a distributed project (docs/dds.md)")->required();
  sim->add_option("--duration,-d", duration, "virtual time to simulate, e.g. 10s")->required();
  sim->add_option("--seed", seed, "seed for drivers and blocks that use randomness");
  sim->add_option("--trace", trace, "write the traced pins to this CSV file");
  sim->add_option("--set", sets, "override a parameter: instance.param=value, of a system node.instance.param=value (repeatable)");
  sim->add_option("--metrics", metrics, "write statistics, motion metrics (Track/Sync-RSME) and driver counters as JSON");
  sim->add_flag("--quiet,-q", quiet, "no progress display");

  DesignOptions design;
  std::vector<std::string> design_taps;
  auto* design_cmd = app.add_subcommand("design-compensator",
                                        "Ling & Lemmon's optimal dropout compensator for a loop: the taps that minimise "
                                        "its output power under Bernoulli dropouts (OPTIMAL_COMPENSATOR design 1)");
  design_cmd->add_option("LOOP", design.loop, "loop file (YAML): plant, controller, delay, input_variance")->required();
  design_cmd->add_option("--loss", design.loss, "dropout rate, 0 <= rate < 1")->required();
  design_cmd->add_option("--order", design.order, "taps of the compensator, 1..16")->check(CLI::Range(1, 16));
  design_cmd->add_option("--taps", design_taps, "also compare these taps, comma-separated a1,a2,... (repeatable)");
  design_cmd->add_flag("--json", design.json, "print JSON");

  auto* run = app.add_subcommand("run", "run a project in real time");
  run->add_option("PROJECT", project, "project file (YAML); none: the last accepted project in the database");
  run->add_option("--duration,-d", duration, "stop after this time, e.g. 60s (default: until Ctrl-C or SIGTERM)");
  run->add_option("--set", sets, "override a parameter: instance.param=value (repeatable)");
  run->add_flag("--no-status", no_status, "no live status screen, even on a terminal");
  run->add_option("--cpu-latency", cpu_latency_us,
                  "hold /dev/cpu_dma_latency at this many us while running (default 0; -1 leaves idle states alone)")
      ->check(CLI::Range(-1, 1000000));
  std::string align;
  run->add_option("--align", align,
                  "start the tasks' grid at a whole multiple of this duration on CLOCK_REALTIME (e.g. 1s): nodes whose "
                  "clocks agree scan in phase (docs/dds.md)");
  run->add_option("--modbus-port", modbus_port,
                  "serve Modbus TCP on this port (0: any free port), even without a modbus: section")
      ->check(CLI::Range(0, 65535));
  run->add_option("--db", db, "the PLC's database: retain values, projects, events, trends (default: the project's "
                              "store: path, else $XDG_STATE_HOME/syncplc/plc.db; :memory: keeps nothing)");
  run->add_option("--start", start, "which retained values come back: warm (retain and persistent; retain only "
                                    "if the project is unchanged), cold (persistent only), origin (none; all deleted)")
      ->check(CLI::IsMember({"warm", "cold", "origin"}));
  run->add_option("--pid-file", pid_file, "where `syncplc reload` finds this instance (default: one per project file in "
                                          "$XDG_RUNTIME_DIR/syncplc or /tmp/syncplc-UID)");

  syncplc::web::WebConfig http;
  std::string http_address, http_anonymous;
  run->add_option("--http", http_address, "serve the HTTP API and the HMI on ADDR:PORT or PORT (default 127.0.0.1:8080; "
                                          "off: no HTTP server)");
  run->add_option("--http-cert", http.tls_cert, "HTTPS: the certificate (PEM)");
  run->add_option("--http-key", http.tls_key, "HTTPS: the certificate's private key (PEM)");
  run->add_flag("--http-insecure", http.allow_plain_remote, "allow plain HTTP on an address beyond this machine");
  run->add_option("--http-anonymous-read", http_anonymous, "reads without a login: on or off (default: on for a loopback "
                                                           "address, off otherwise)")
      ->check(CLI::IsMember({"on", "off"}));
  run->add_option("--http-max-connections", http.max_connections,
                  "HTTP connections open at once (default 256; more are refused with 503, and never more than "
                  "half the file descriptors beyond 128, so Modbus and the drivers keep theirs)")
      ->check(CLI::Range(1, 100000));
  run->add_option("--http-cpus", http.cpus,
                  "the CPUs of the HTTP server's threads, e.g. 0 or 0,2 (default: every CPU no task is pinned to)")
      ->delimiter(',')
      ->check(CLI::Range(0, 1023));
  run->add_option("--hmi-dir", http.hmi_dir, "serve the HMI from this directory (default: the installed copy, PREFIX/share/syncplc/hmi "
                                          "for PREFIX/bin/syncplc, else the build's hmi_web/dist)");

  auto* reload = app.add_subcommand("reload", "online change: the running `syncplc run` of PROJECT loads its file again "
                                              "and switches to it without a stop; prints what changed");
  reload->add_option("PROJECT", project, "the project file the instance runs (default: the only one running)");
  reload->add_option("--pid-file", pid_file, "the instance's pid file (as given to run --pid-file)");
  std::int64_t version = 0;
  reload->add_option("--version", version, "load this version of the project store instead (rollback; see syncplc projects)")
      ->check(CLI::PositiveNumber);
  OnlineOptions reload_online;
  add_online_options(reload, reload_online);

  auto* projects = app.add_subcommand("projects", "the projects loaded onto the PLC: every version, its origin and outcome");
  projects->add_option("--db", db, "the PLC's database (default: $XDG_STATE_HOME/syncplc/plc.db)");
  auto* projects_show = projects->add_subcommand("show", "print a stored version's files");
  std::int64_t show = 0;
  std::string show_file;
  projects_show->add_option("N", show, "the version number")->required()->check(CLI::PositiveNumber);
  projects_show->add_option("--file", show_file, "only this file, as it is named in the version");
  projects_show->add_option("--db", db, "the PLC's database");

  EventsOptions events_options;
  auto* events = app.add_subcommand("events", "the PLC's event log: starts, stops, reloads, faults, HMI writes with "
                                              "the client's address; also while the PLC runs");
  events->add_option("--db", events_options.db, "the PLC's database (default: $XDG_STATE_HOME/syncplc/plc.db)");
  events->add_option("--since", events_options.since, "from this long ago (10m, 2h) or this local time "
                                                      "(2026-11-25T10:00:00)");
  events->add_flag("--follow,-f", events_options.follow, "keep printing new events until Ctrl-C");
  events->add_option("--kind", events_options.kinds, "only events of this kind (repeatable): start, stop, reload, "
                                                     "reload-failed, hmi-write, modbus-refused, watchdog, ...");
  add_online_options(events, events_options.online);

  auto* reset = app.add_subcommand("reset", "delete stored retain values while the PLC is stopped: cold (retain "
                                            "values; persistent ones stay) or origin (every stored value)");
  reset->add_option("KIND", reset_kind, "cold or origin")->required()->check(CLI::IsMember({"cold", "origin"}));
  reset->add_option("PROJECT", project, "the project whose store: path names the database");
  reset->add_option("--db", db, "the PLC's database (default: as for run)");

  auto* test = app.add_subcommand("test", "run scan-cycle tests against a project in virtual time");
  test->add_option("PROJECT", project, "project file (YAML), or a system file (targets then node.tag)")->required();
  test->add_option("TESTS", tests, "tests file (YAML)")->required();
  test->add_option("--junit", junit, "write a JUnit XML report to this file");

  TrendOptions trend_options;
  auto* trend = app.add_subcommand("trend", "print the historian's points of trended tags (also while the PLC runs)");
  trend->add_option("TAG", trend_options.tags, "a trended tag (all its elements) or one element, e.g. pos[2]")->required();
  trend->add_option("--db", trend_options.db, "the PLC's database (default: $XDG_STATE_HOME/syncplc/plc.db)");
  trend->add_option("--since", trend_options.since, "from this time: 2026-11-25T04:00:00Z (UTC), or a duration ago: 10m");
  trend->add_option("--until", trend_options.until, "before this time (same forms as --since)");
  trend->add_flag("--csv", trend_options.csv, "CSV: time,tag,min,max,mean,count");

  UserOptions user_options;
  auto* user = app.add_subcommand("user", "the users of the HTTP API and the HMI: add, passwd, role, remove, list "
                                          "(also while the PLC runs)");
  user->require_subcommand(1);
  // Every action names the database as run does: --db, else PROJECT's store: path, else the default.
  auto database_options = [&](CLI::App* a) {
    a->add_option("PROJECT", user_options.project, "the project whose store: path names the database");
    a->add_option("--db", user_options.db, "the PLC's database (default: as for run)");
  };
  auto* user_add = user->add_subcommand("add", "add a user; the password is asked twice (or --password-stdin)");
  user_add->add_option("NAME", user_options.name, "1 to 64 of A-Z a-z 0-9 _ . @ -")->required();
  user_add->add_option("--role", user_options.role, "viewer, operator or engineer")->required();
  user_add->add_flag("--password-stdin", user_options.password_stdin, "read the password as one line of standard input");
  database_options(user_add);
  auto* user_passwd = user->add_subcommand("passwd", "give a user a new password");
  user_passwd->add_option("NAME", user_options.name, "the user")->required();
  user_passwd->add_flag("--password-stdin", user_options.password_stdin,
                        "read the password as one line of standard input");
  database_options(user_passwd);
  auto* user_role = user->add_subcommand("role", "give a user another role");
  user_role->add_option("NAME", user_options.name, "the user")->required();
  user_role->add_option("ROLE", user_options.role, "viewer, operator or engineer")->required();
  database_options(user_role);
  auto* user_remove = user->add_subcommand("remove", "remove a user");
  user_remove->add_option("NAME", user_options.name, "the user")->required();
  database_options(user_remove);
  auto* user_list = user->add_subcommand("list", "list the users with their roles");
  database_options(user_list);

  // The online commands: a running `syncplc run` through its HTTP API.
  OnlineOptions online;
  std::vector<std::string> refs;
  std::string ref, value;
  auto* status = app.add_subcommand("status", "a running PLC's state: its program, tasks and their timing, forces");
  add_online_options(status, online);
  status->add_flag("--json", online.json, "print the API's answer (GET /status) as it comes");

  auto* read = app.add_subcommand("read", "read tags, elements (pos[2]) and block pins (pid.out) of a running PLC");
  read->add_option("REF", refs, "a tag, an element or instance.pin")->required();
  add_online_options(read, online);
  read->add_flag("--json", online.json, "print the API's answer (GET /values) as it comes");

  auto* write = app.add_subcommand("write", "write a tag (with hmi: readwrite; the operator role) or a variable of an ST instance "
                                               "(once, at its task's next scan; the engineer role) of a running PLC");
  write->add_option("TAG", ref, "a tag, an element or instance.var, e.g. speed, levels[2], cell.recipe.speed")->required();
  write->add_option("VALUE", value, "a number, TRUE/FALSE, or IEC text: T#5ms, 16#FF, \"1500 mm\"")->required();
  add_online_options(write, online);

  auto* force = app.add_subcommand("force", "hold a tag, element or pin at a value until unforced; needs the engineer role");
  force->add_option("REF", ref, "a tag element or instance.pin")->required();
  force->add_option("VALUE", value, "a number, TRUE/FALSE, or IEC text: T#5ms, 16#FF, \"1500 mm\"")->required();
  add_online_options(force, online);

  bool unforce_all = false;
  auto* unforce = app.add_subcommand("unforce", "release a force, or every force (--all); needs the engineer role");
  unforce->add_option("REF", ref, "the forced element");
  unforce->add_flag("--all", unforce_all, "release every force");
  add_online_options(unforce, online);

  WatchOptions watch_options;
  auto* watch = app.add_subcommand("watch", "live values of a running PLC until Ctrl-C (GET /stream)");
  watch->add_option("REF", watch_options.refs, "a tag, an element or instance.pin")->required();
  watch->add_option("--rate", watch_options.rate, "updates per second (1..50, default 10)")->check(CLI::Range(1, 50));
  watch->add_option("--count", watch_options.count, "stop after this many updates")->check(CLI::PositiveNumber);
  add_online_options(watch, online);

  bool check_only = false;
  auto* load = app.add_subcommand("load", "send a project (its file and every file it includes) to a running PLC and "
                                          "switch to it by online change; needs the engineer role");
  load->add_option("PROJECT", project, "the project's main file (YAML)")->required();
  load->add_flag("--check", check_only, "only check it on the PLC: nothing changes");
  add_online_options(load, online);

  std::int64_t rollback_version = 0;
  auto* rollback = app.add_subcommand("rollback", "switch a running PLC back to a stored project version by online "
                                                  "change (see syncplc projects); needs the engineer role");
  rollback->add_option("N", rollback_version, "the version number")->required()->check(CLI::PositiveNumber);
  add_online_options(rollback, online);

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    int rc = app.exit(e);
    return rc == 0 ? kExitOk : kExitInvalid;
  }
  try {
    if (*check) return cmd_check(project);
    if (*blocks) return cmd_blocks(block, markdown, blocks_project);
    if (*design_cmd) {
      for (const auto& t : design_taps) {
        std::vector<double> a;
        std::stringstream ss(t);
        std::string item;
        while (std::getline(ss, item, ',')) {
          char* end = nullptr;
          const double v = std::strtod(item.c_str(), &end);
          if (item.empty() || end != item.c_str() + item.size() || !std::isfinite(v)) {
            std::cerr << "--taps " << t << ": '" << item << "' is not a finite number\n";
            return kExitInvalid;
          }
          a.push_back(v);
        }
        if (a.size() > 16) {
          std::cerr << "--taps " << t << ": at most 16 taps\n";
          return kExitInvalid;
        }
        design.taps.push_back(a);
      }
      return cmd_design_compensator(design);
    }
    if (*sim) return cmd_sim(project, duration, seed, trace, sets, quiet, metrics);
    if (*run) {
      RunOptions o;
      o.project = project;
      o.duration = duration;
      o.sets = sets;
      o.no_status = no_status;
      o.cpu_latency_us = cpu_latency_us;
      o.align = align;
      o.modbus_port = modbus_port;
      o.pid_file = pid_file;
      o.db = db;
      o.start = start;
      o.http = http;
      if (!http_address.empty()) {
        std::string why;
        if (!syncplc::web::parse_http_address(http_address, o.http, &why)) {
          std::cerr << "syncplc: " << why << "\n";
          return kExitInvalid;
        }
      }
      if (!http_anonymous.empty()) o.http.anonymous_read = http_anonymous == "on";
      return cmd_run(o);
    }
    if (*reload) return cmd_reload(project, pid_file, version, reload_online);
    if (*projects) return cmd_projects(db, *projects_show ? show : 0, show_file);
    if (*test) return cmd_test(project, tests, junit);
    if (*events) return cmd_events(events_options);
    if (*reset) return cmd_reset(reset_kind, project, db);
    if (*trend) return cmd_trend(trend_options);
    if (*user) {
      user_options.action = user->get_subcommands().front()->get_name();
      return cmd_user(user_options);
    }

    if (*status) return cmd_status(online);
    if (*read) return cmd_read(refs, online);
    if (*write) return cmd_write(ref, value, online);
    if (*force) return cmd_force(ref, value, online);
    if (*unforce) return cmd_unforce(ref, unforce_all, online);
    if (*watch) return cmd_watch(watch_options, online);
    if (*load) return cmd_load(project, check_only, online);
    if (*rollback) return cmd_rollback(rollback_version, online);
  } catch (const std::exception& e) {
    std::cerr << "syncplc: " << e.what() << "\n";
    return kExitInvalid;
  }
  return kExitInvalid;
}
