// The `syncplc` command end to end: exit statuses, reports, reproducible
// simulation, user scan-cycle tests, signals.
#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <fstream>
#include <regex>
#include <sstream>
#include <thread>

#include "tests/support/cli_runner.hpp"
#include "tests/support/test_blocks.hpp"

namespace {

using syncplc::testing::write_temp_file;

using Result = syncplc::testing::CliResult;
using syncplc::testing::slurp;
using syncplc::testing::TakenPort;
using syncplc::testing::drop_realtime_priority;
using syncplc::testing::run_cli_without_realtime;
Result run(const std::string& args) { return syncplc::testing::run_cli(args); }

const std::string kSrc = SYNCPLC_SOURCE_DIR;
const std::string kDemo = kSrc + "/projects/bottle_line/bottle_line.yaml";
const std::string kDemoTests = kSrc + "/projects/bottle_line/tests.yaml";

TEST(Cli, CheckPrintsTaskTableExecutionOrderAndTagMap) {
  auto r = run("check " + kDemo);
  EXPECT_EQ(r.rc, 0) << r.err;
  EXPECT_NE(r.out.find("Tasks of bottle_line"), std::string::npos);
  EXPECT_NE(r.out.find("Execution order"), std::string::npos);
  EXPECT_NE(r.out.find("%QX0.0"), std::string::npos);
  EXPECT_NE(r.out.find("UNIT_DELAY<BOOL>"), std::string::npos);
  EXPECT_NE(r.out.find("Modbus TCP server: 127.0.0.1:5020, unit 1,"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("  holding registers 3000..3003  nominal_speed LREAL (explicit)  read/write\n"), std::string::npos)
      << r.out;
}

TEST(Cli, CheckOfABadProjectReportsEveryErrorWithItsPlaceAndExits2) {
  std::string bad = write_temp_file("bad.yaml", R"(tasks:
  - {name: t, period: 1ms}
tags:
  - {name: a, type: BOOL, address: "%QX0.0"}
  - {name: b, type: BOOL, address: "%QX0.0"}
blocks:
  - {name: x, type: NOPE}
connections:
  - a -> y.IN
)");
  auto r = run("check " + bad);
  EXPECT_EQ(r.rc, 2);
  EXPECT_NE(r.err.find(bad + ":5:36: address %QX0.0 of b overlaps"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find(bad + ":7:21: unknown block type 'NOPE'"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find(bad + ":9:10: unknown block instance 'y'"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("3 errors"), std::string::npos) << r.err;
  EXPECT_EQ(r.out, "");
}

TEST(Cli, CheckPrintsTheModbusServerSettingsAndExplicitPlaces) {
  std::string project = write_temp_file("modbus_check.yaml", R"(tasks: [{name: main, period: 1ms}]
tags:
  - {name: speed, type: LREAL, hmi: readwrite, modbus: {table: holding_register, address: 3000}}
  - {name: level, type: INT, address: "%IW2", hmi: read}
modbus:
  port: 5020
  idle_timeout: 60s
  word_order: low_first
  allowed_clients: [192.168.1.0/24, 10.0.0.7]
)");
  auto r = run("check " + project);
  ASSERT_EQ(r.rc, 0) << r.err;
  EXPECT_NE(r.out.find("\nModbus TCP server: 127.0.0.1:5020, unit 1, max 64 clients, idle timeout 60s, low word first, "
                       "read/write, clients: 192.168.1.0/24, 10.0.0.7\n"),
            std::string::npos)
      << r.out;
  EXPECT_NE(r.out.find("Modbus map (OpenPLC convention; 32/64-bit values low word first):\n"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("  holding registers 3000..3003  speed LREAL (explicit)  read/write\n"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("  input register 2  level INT at %IW2  read only\n"), std::string::npos) << r.out;

  std::string off = write_temp_file("modbus_off.yaml", "tasks: [{name: main, period: 1ms}]\nmodbus: {enabled: false}\n");
  auto o = run("check " + off);
  ASSERT_EQ(o.rc, 0) << o.err;
  EXPECT_NE(o.out.find("\nModbus TCP server: off (enabled: false)\n"), std::string::npos) << o.out;
  std::string none = write_temp_file("modbus_none.yaml", "tasks: [{name: main, period: 1ms}]\n");
  auto n = run("check " + none);
  EXPECT_NE(n.out.find("\nModbus TCP server: off (no modbus: section)\n"), std::string::npos) << n.out;
}

TEST(Cli, MissingFileAndUsageErrorsExit2) {
  EXPECT_EQ(run("check /nonexistent/x.yaml").rc, 2);
  EXPECT_EQ(run("frobnicate").rc, 2);
  EXPECT_EQ(run("sim " + kDemo).rc, 2);  // --duration is required
  EXPECT_EQ(run("sim " + kDemo + " --duration 10parsecs").rc, 2);
  EXPECT_EQ(run("sim " + kDemo + " -d 1s --set nonsense").rc, 2);
  EXPECT_EQ(run("sim " + kDemo + " -d 1s --set nosuch.param=1").rc, 2);
  EXPECT_EQ(run("--version").rc, 0);
}

TEST(Cli, SimTraceIsBitForBitReproducible) {
  std::string t1 = write_temp_file("trace1.csv", ""), t2 = write_temp_file("trace2.csv", "");
  auto a = run("sim " + kDemo + " --duration 6s --seed 7 --trace " + t1);
  auto b = run("sim " + kDemo + " --duration 6s --seed 7 --trace " + t2);
  ASSERT_EQ(a.rc, 0) << a.err;
  ASSERT_EQ(b.rc, 0) << b.err;
  std::string x = slurp(t1), y = slurp(t2);
  EXPECT_GT(x.size(), 100000u);
  EXPECT_EQ(x, y);
  EXPECT_EQ(x.substr(0, x.find('\n')),
            "time_s,conveyor_on,bottle_present,bottles,batch_done,fill_valve,line_speed,restart_delay.ET");
  // One row per instant at which a scan ran: 6000 line scans + 600 filler scans at other instants.
  EXPECT_EQ(std::count(x.begin(), x.end(), '\n'), 1 + 6000 + 600);
  EXPECT_NE(a.out.find("line                   6000"), std::string::npos) << a.out;
}

TEST(Cli, SimSetOverridesAnInitialValue) {
  std::string t = write_temp_file("trace_set.csv", "");
  auto r = run("sim " + kDemo + " -d 3s --set auto_mode=FALSE --trace " + t);
  ASSERT_EQ(r.rc, 0) << r.err;
  std::string csv = slurp(t);
  std::string last = csv.substr(csv.rfind('\n', csv.size() - 2) + 1);
  EXPECT_EQ(last.substr(0, last.find(',', last.find(',') + 1)), "2.999000000,0");  // conveyor never started
}

TEST(Cli, UserScanCycleTestsPassAndFail) {
  auto ok = run("test " + kDemo + " " + kDemoTests);
  EXPECT_EQ(ok.rc, 0) << ok.out << ok.err;
  EXPECT_NE(ok.out.find("6 passed, 0 failed"), std::string::npos) << ok.out;

  std::string failing = write_temp_file("failing.yaml", R"(cases:
  - name: passes
    steps:
      - {at: 1000ms, expect: {conveyor_on: TRUE}}
  - name: wrong on purpose
    steps:
      - at: 999ms
        expect: {conveyor_on: TRUE}
      - cycle: 3
        task: filler
        expect: {line_speed: {value: 1.0, tolerance: 0.5}}
)");
  std::string junit = write_temp_file("junit.xml", "");
  auto bad = run("test " + kDemo + " " + failing + " --junit " + junit);
  EXPECT_EQ(bad.rc, 1);
  EXPECT_NE(bad.out.find("1 passed, 1 failed"), std::string::npos) << bad.out;
  EXPECT_NE(bad.out.find(failing + ":8:31: case 'wrong on purpose' at 999ms: conveyor_on is FALSE, expected TRUE"),
            std::string::npos) << bad.out;
  EXPECT_NE(bad.out.find("cycle 3 of filler: line_speed is 0, expected 1"), std::string::npos) << bad.out;
  std::string xml = slurp(junit);
  EXPECT_NE(xml.find("<testsuite name=\"" + kDemo + "\" tests=\"2\" failures=\"1\""), std::string::npos) << xml;
  EXPECT_NE(xml.find("<failure message="), std::string::npos);

  std::string broken = write_temp_file("broken.yaml", R"(cases:
  - name: x
    steps:
      - {at: 1s, expect: {no_such_tag: TRUE}}
)");
  auto inv = run("test " + kDemo + " " + broken);
  EXPECT_EQ(inv.rc, 2);
  EXPECT_NE(inv.err.find(broken + ":4:40: unknown tag or instance.pin 'no_such_tag'"), std::string::npos) << inv.err;
}

TEST(Cli, BlocksListsDescribesAndGeneratesTheReference) {
  auto list = run("blocks");
  EXPECT_EQ(list.rc, 0);
  for (const char* b : {"TON", "TOF", "TP", "R_TRIG", "F_TRIG", "CTU", "CTD", "CTUD", "SR", "RS", "ADD", "SUB", "MUL",
                        "DIV", "LIMIT", "SEL", "MAX", "MIN", "GT", "GE", "EQ", "NE", "LE", "LT", "AND", "OR", "XOR",
                        "NOT", "MOVE", "UNIT_DELAY"})
    EXPECT_NE(list.out.find(std::string("  ") + b + " "), std::string::npos) << b;
  auto ton = run("blocks TON");
  EXPECT_EQ(ton.rc, 0);
  EXPECT_NE(ton.out.find("PT"), std::string::npos);
  EXPECT_EQ(run("blocks NOPE").rc, 2);
  // docs/blocks.md is generated: it must match what the binary prints.
  auto md = run("blocks --markdown");
  EXPECT_EQ(md.rc, 0);
  EXPECT_EQ(md.out, slurp(kSrc + "/docs/blocks.md")) << "regenerate: build/syncplc blocks --markdown > docs/blocks.md";
}

TEST(Cli, RunForADurationPrintsStatistics) {
  // Port 0: the project's 5020 may be taken on a test machine.
  auto r = run("run " + kDemo + " --duration 1s --no-status --modbus-port 0");
  EXPECT_EQ(r.rc, 0) << r.err;
  EXPECT_NE(r.out.find("Statistics (real time)"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("line"), std::string::npos);
  EXPECT_NE(r.err.find("syncplc: modbus: listening on 127.0.0.1:"), std::string::npos) << r.err;
  EXPECT_NE(r.out.find("\nModbus TCP on 127.0.0.1:"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("  requests 0, exceptions 0, values written 0\n"), std::string::npos) << r.out;
}

TEST(Cli, RunRefusesToStartWhenItsModbusPortIsTaken) {
  // A second server on the same port: a clear error, exit status 2, no PLC half running.
  std::string path = write_temp_file("modbus_port.yaml", "tasks: [{name: main, period: 1ms}]\n"
                                     "tags: [{name: x, type: INT, address: \"%MW0\", hmi: read}]\nmodbus: {port: 0}\n");
  TakenPort taken;
  ASSERT_GT(taken.port, 0);
  auto r = run("run " + path + " --duration 1s --no-status --modbus-port " + std::to_string(taken.port));
  taken.release();
  EXPECT_EQ(r.rc, 2);
  EXPECT_NE(r.err.find("syncplc: modbus: cannot listen on 127.0.0.1:" + std::to_string(taken.port) +
                       ": Address already in use"), std::string::npos) << r.err;
}

TEST(Cli, RunStopsCleanlyOnSigterm) {
  std::string o = write_temp_file("sigterm.out", "");
  pid_t pid = fork();
  ASSERT_GE(pid, 0);
  if (pid == 0) {
    FILE* f = std::freopen(o.c_str(), "w", stdout);
    FILE* g = std::freopen((o + ".err").c_str(), "w", stderr);
    (void)f;
    (void)g;
    execl(SYNCPLC_BINARY, SYNCPLC_BINARY, "run", kDemo.c_str(), "--no-status", "--modbus-port", "0", "--http",
          "127.0.0.1:0", static_cast<char*>(nullptr));
    _exit(127);
  }
  ASSERT_TRUE(syncplc::testing::wait_for_text(o + ".err", syncplc::testing::kRunTakesSignals)) << slurp(o + ".err");
  std::this_thread::sleep_for(std::chrono::milliseconds(700));
  kill(pid, SIGTERM);
  int status = 0;
  auto t0 = std::chrono::steady_clock::now();
  waitpid(pid, &status, 0);
  // Only a run that ignored the signal (and ran on) reaches this guard.
  EXPECT_LT(std::chrono::steady_clock::now() - t0, std::chrono::seconds(60));
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 0);
  std::string out = slurp(o);
  EXPECT_NE(out.find("Stopped by SIGTERM"), std::string::npos) << out;
  EXPECT_NE(out.find("Statistics (real time)"), std::string::npos) << out;
}

}  // namespace

namespace {

TEST(Cli, SighupReloadsAGoodProjectAndKeepsRunningOnABadOne) {
  const std::string good = R"(tasks: [{name: t, period: 1ms}]
tags:
  - {name: level, type: LREAL, init: 3.5}
  - {name: out, type: LREAL}
blocks: [{name: m, type: MOVE}]
connections: [level -> m.IN, m.OUT -> out]
)";
  std::string path = write_temp_file("reload.yaml", good);
  std::string o = path + ".out", e = path + ".err";
  pid_t pid = fork();
  ASSERT_GE(pid, 0);
  if (pid == 0) {
    FILE* f1 = std::freopen(o.c_str(), "w", stdout);
    FILE* f2 = std::freopen(e.c_str(), "w", stderr);
    (void)f1;
    (void)f2;
    execl(SYNCPLC_BINARY, SYNCPLC_BINARY, "run", path.c_str(), "--no-status", "--http", "127.0.0.1:0",
          static_cast<char*>(nullptr));
    _exit(127);
  }
  // The line, however long a loaded machine takes (the minute only ends a hang).
  auto wait_for = [&](const std::string& text) { return syncplc::testing::wait_for_text(e, text, 60); };
  ASSERT_TRUE(syncplc::testing::wait_for_text(e, syncplc::testing::kRunTakesSignals)) << slurp(e);
  write_temp_file("reload.yaml", "tasks: [{name: t, period: 1ms}]\nblocks: [{name: m, type: NOPE}]\n");
  kill(pid, SIGHUP);
  EXPECT_TRUE(wait_for("rejected (1 error); the running program continues unchanged")) << slurp(e);
  EXPECT_NE(slurp(e).find("reload.yaml:2:26: unknown block type 'NOPE'"), std::string::npos) << slurp(e);
  EXPECT_EQ(waitpid(pid, nullptr, WNOHANG), 0);  // still running
  write_temp_file("reload.yaml", good + "  # edited\n");
  kill(pid, SIGHUP);
  EXPECT_TRUE(wait_for("instances: 1 kept, 0 retuned, 0 rewired, 0 new, 0 removed; tasks: 1 kept; 2 tag values carried over")) << slurp(e);
  EXPECT_NE(slurp(e).find("  m (MOVE, task t): kept"), std::string::npos) << slurp(e);
  kill(pid, SIGTERM);
  int status = 0;
  waitpid(pid, &status, 0);
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 0);
  EXPECT_NE(slurp(o).find("Stopped by SIGTERM"), std::string::npos);
}

}  // namespace

namespace {

TEST(Cli, RunGivesUpOnAScanThatDoesNotEndAndExits4) {
  // The only task's scan runs past its watchdog's limit (100 ms) and on: the
  // supervisor stops the task, every task has then stopped, and the process
  // ends without the thread, which is still burning (status 4).
  std::string path = write_temp_file("hang.yaml", R"(tasks:
  - {name: stuck, period: 10ms, watchdog: {time: 50ms, sensitivity: 2, action: stop}}
blocks: [{name: b, type: BURN, inputs: {EXEC: 1h}}]
)");
  auto r = run_cli_without_realtime("run " + path + " --duration 5s --no-status");
  EXPECT_EQ(r.rc, 4) << r.err;
  EXPECT_NE(r.err.find("scan-hung      stuck: scan did not end: task stopped by the supervisor"), std::string::npos)
      << r.err;
  EXPECT_NE(r.err.find("syncplc: every task has stopped"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("exiting without its thread (status 4)"), std::string::npos) << r.err;
  EXPECT_NE(r.out.find("STOPPED"), std::string::npos) << r.out;
}

// Starts `syncplc run ARGS...` with stdout and stderr to files, at normal
// priority (its scans never end: see drop_realtime_priority).
pid_t spawn_run(const std::vector<std::string>& args, const std::string& out, const std::string& err) {
  pid_t pid = fork();
  if (pid == 0) {
    drop_realtime_priority();
    FILE* f1 = std::freopen(out.c_str(), "w", stdout);
    FILE* f2 = std::freopen(err.c_str(), "w", stderr);
    (void)f1;
    (void)f2;
    std::vector<char*> argv{const_cast<char*>(SYNCPLC_BINARY), const_cast<char*>("run")};
    for (const auto& a : args) argv.push_back(const_cast<char*>(a.c_str()));
    argv.push_back(nullptr);
    execv(SYNCPLC_BINARY, argv.data());
    _exit(127);
  }
  return pid;
}

TEST(Cli, SigtermEndsARunWhoseScanNeverEndsAfterTheStopGrace) {
  // A scan that never ends in one task (a 1 h BURN), a healthy one beside it.
  // SIGTERM: the stuck task's outputs are driven to their safe values and the
  // process exits without joining its thread, after the stop grace of 0.5 s
  // and the store's final commit (about 0.6 s on a quiet machine). The bound
  // is loose on purpose: it tells "did not wait for the scan" from "waited",
  // and ctest -j2 beside a build can hold the exit up for a second or more.
  std::string path = write_temp_file("never.yaml", R"(tasks:
  - {name: stuck, period: 10ms, watchdog: {time: 5s, action: safe_stop}}
  - {name: fine, period: 10ms}
tags:
  - {name: motor, type: BOOL, init: TRUE, safe: FALSE}
blocks:
  - {name: b, type: BURN, task: stuck, inputs: {EXEC: 1h}}
  - {name: m, type: MOVE, datatype: BOOL, task: stuck}
connections: [motor -> m.IN]
drivers:
  - {name: io, type: memory, task: stuck, channels: [{name: motor, dir: out, type: BOOL}], bind: {motor: motor}}
)");
  const std::string o = path + ".out", e = path + ".err";
  pid_t pid = spawn_run({path, "--no-status", "--http", "127.0.0.1:0"}, o, e);
  ASSERT_GT(pid, 0);
  ASSERT_TRUE(syncplc::testing::wait_for_text(e, syncplc::testing::kRunTakesSignals)) << slurp(e);
  std::this_thread::sleep_for(std::chrono::milliseconds(700));
  ASSERT_EQ(waitpid(pid, nullptr, WNOHANG), 0) << "still running: the healthy task keeps it up\n" << slurp(e);
  const auto t0 = std::chrono::steady_clock::now();
  kill(pid, SIGTERM);
  int status = 0;
  waitpid(pid, &status, 0);
  // Only a run that waited for the stuck scan (1 h) reaches this guard.
  EXPECT_LT(std::chrono::steady_clock::now() - t0, std::chrono::seconds(60));
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 4);
  const std::string out = slurp(o), err = slurp(e);
  EXPECT_NE(err.find("scan-hung      stuck: scan still running at the stop: the process ends without it"),
            std::string::npos) << err;
  EXPECT_NE(err.find("safe-state     stuck: outputs driven to their safe values by the supervisor"), std::string::npos)
      << err;
  EXPECT_NE(out.find("Stopped by SIGTERM"), std::string::npos) << out;
  EXPECT_NE(out.find("Statistics (real time)"), std::string::npos) << out;
}

TEST(Cli, AReloadIsRefusedWhileAScanThatDidNotEndHoldsItsThread) {
  // Stopping the tasks for the reload would wait for the stuck thread forever.
  std::string path = write_temp_file("hung_reload.yaml", R"(tasks:
  - {name: stuck, period: 10ms, watchdog: {time: 20ms, action: stop}}
  - {name: fine, period: 10ms}
blocks: [{name: b, type: BURN, task: stuck, inputs: {EXEC: 1h}}]
)");
  const std::string o = path + ".out", e = path + ".err";
  pid_t pid = spawn_run({path, "--no-status", "--duration", "20s", "--http", "127.0.0.1:0"}, o, e);
  ASSERT_GT(pid, 0);
  // The line, however long a loaded machine takes (the minute only ends a hang).
  auto wait_for = [&](const std::string& text) { return syncplc::testing::wait_for_text(e, text, 60); };
  EXPECT_TRUE(wait_for("stuck: scan did not end: task stopped by the supervisor")) << slurp(e);
  ASSERT_TRUE(syncplc::testing::wait_for_text(e, syncplc::testing::kRunTakesSignals)) << slurp(e);
  kill(pid, SIGHUP);
  EXPECT_TRUE(wait_for("syncplc: reload refused: a task's scan did not end")) << slurp(e);
  kill(pid, SIGTERM);
  int status = 0;
  waitpid(pid, &status, 0);
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 4) << slurp(e);
}

TEST(Cli, RunWhoseEveryTaskIsStoppedByItsWatchdogExits3) {
  // Every scan overruns (7 ms > 5 ms) and the tenth in a row trips the
  // watchdog; no scan comes near the supervisor's hang limit (10 × 5 ms), so
  // however the supervisor's checks fall, the task ends by its watchdog.
  std::string path = write_temp_file("watchdog_stop.yaml", R"(tasks:
  - {name: slow, period: 50ms, watchdog: {time: 5ms, sensitivity: 10, action: stop}}
blocks: [{name: b, type: BURN, inputs: {EXEC: 7ms}}]
)");
  auto r = run("run " + path + " --duration 10s --no-status");
  EXPECT_EQ(r.rc, 3) << r.err;
  EXPECT_NE(r.err.find("task stopped by its watchdog"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("syncplc: every task has stopped"), std::string::npos) << r.err;
}

TEST(Cli, RunOfOneSecondMakesAThousandScansOfAOneMillisecondTask) {
  // --duration counts from the first release (after the start delay): exactly
  // the releases 0, 1 ms, ..., 999 ms. A release that got no scan is counted
  // as skipped.
  std::string path = write_temp_file("thousand.yaml", "tasks: [{name: t, period: 1ms}]\n");
  auto r = run("run " + path + " --duration 1s --no-status");
  ASSERT_EQ(r.rc, 0) << r.err;
  std::smatch m;
  ASSERT_TRUE(std::regex_search(r.out, m, std::regex(R"(\n  t +(\d+) +(\d+) +(\d+) )"))) << r.out;
  const long scans = std::stol(m[1]), skipped = std::stol(m[3]);
  EXPECT_LE(scans, 1000) << r.out;
  EXPECT_GE(scans + skipped, 1000) << r.out;
  EXPECT_LE(scans + skipped, 1002) << r.out;
}

}  // namespace
