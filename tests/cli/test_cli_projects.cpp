// The project store from the command line: `run` records its project
// (accepted or rejected), `syncplc projects` lists and shows versions (also
// while the PLC runs), `syncplc reload --version N` rolls a running instance
// back by online change, and `run` without a file starts the last accepted
// project. The stored files are checked with the sqlite3 shell.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <thread>

#include "tests/support/cli_runner.hpp"
#include "tests/support/test_blocks.hpp"

namespace {

using syncplc::testing::run_cli;
using syncplc::testing::slurp;
using syncplc::testing::write_temp_file;
using syncplc::testing::TakenPort;

std::string project_text(double level) {
  return "project: {name: tank, version: '" + std::to_string(static_cast<int>(level)) + "'}\n" +
         "tasks: [{name: t, period: 1ms}]\ntags:\n  - {name: level, type: LREAL, init: " + std::to_string(level) +
         "}\n  - {name: out, type: LREAL}\nblocks: [{name: m, type: MOVE}]\nconnections: [level -> m.IN, m.OUT -> out]\n";
}

// A database path in this process's temporary directory (no file yet).
std::string temp_db(const std::string& name) {
  return (std::filesystem::path(write_temp_file(name + ".marker", "")).parent_path() / (name + ".db")).string();
}

// The sqlite3 shell's answer to one statement.
std::string sqlite3(const std::string& db, const std::string& sql) {
  const std::string out = write_temp_file("sqlite3.out", "");
  const int rc = std::system(("sqlite3 -readonly " + db + " \"" + sql + "\" >" + out + " 2>&1").c_str());
  EXPECT_EQ(rc, 0) << slurp(out);
  return slurp(out);
}

// A `syncplc run` in the background, its stderr in a file.
struct Instance {
  pid_t pid = -1;
  std::string err;
  explicit Instance(std::vector<std::string> args, const std::string& name) {
    err = write_temp_file(name + ".err", "");
    const std::string out = err + ".out";
    args.insert(args.begin(), {SYNCPLC_BINARY, "run"});
    pid = fork();
    if (pid == 0) {
      FILE* f1 = std::freopen(out.c_str(), "w", stdout);
      FILE* f2 = std::freopen(err.c_str(), "w", stderr);
      (void)f1;
      (void)f2;
      std::vector<char*> argv;
      for (auto& a : args) argv.push_back(a.data());
      argv.push_back(nullptr);
      execv(SYNCPLC_BINARY, argv.data());
      _exit(127);
    }
  }
  // The line, however long a loaded machine takes (the minute only ends a hang).
  bool wait_for(const std::string& text) const { return syncplc::testing::wait_for_text(err, text, 60); }
  int stop() {
    kill(pid, SIGTERM);
    int status = 0;
    waitpid(pid, &status, 0);
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  }
};

// Polls `syncplc projects` until its listing has `text` (the store thread
// writes soon after the start; the minute's guard only ends a hang).
bool projects_show(const std::string& db, const std::string& text, std::string* listing) {
  const auto guard = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  while (std::chrono::steady_clock::now() < guard) {
    *listing = run_cli("projects --db " + db).out;
    if (listing->find(text) != std::string::npos) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  return false;
}

TEST(CliProjects, RunRecordsAcceptedAndRejectedProjectsAndProjectsListsAndShowsThem) {
  const std::string db = temp_db("list");
  const std::string path = write_temp_file("list.yaml", project_text(3));
  auto r = run_cli("run " + path + " --no-status --duration 200ms --db " + db);
  ASSERT_EQ(r.rc, 0) << r.err;
  write_temp_file("list.yaml", "tasks: [{name: t, period: 1ms}]\nblocks: [{name: m, type: NOPE}]\n");
  r = run_cli("run " + path + " --no-status --duration 200ms --db " + db);
  ASSERT_EQ(r.rc, 2) << r.err;
  r = run_cli("projects --db " + db);
  ASSERT_EQ(r.rc, 0) << r.err;
  EXPECT_NE(r.out.find("   #  time (UTC)           origin    outcome   project"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("run       accepted  tank 3"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("run       rejected  -"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("list.yaml:2:26: unknown block type 'NOPE'"), std::string::npos) << r.out;
  r = run_cli("projects show 1 --file list.yaml --db " + db);
  ASSERT_EQ(r.rc, 0) << r.err;
  EXPECT_EQ(r.out, project_text(3));
  r = run_cli("projects show 2 --db " + db);
  EXPECT_NE(r.out.find("version 2: run (no project name)"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("error: "), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("==> list.yaml <==\ntasks: [{name: t, period: 1ms}]"), std::string::npos) << r.out;
  r = run_cli("projects show 3 --db " + db);
  EXPECT_EQ(r.rc, 2);
  EXPECT_NE(r.err.find("no version 3"), std::string::npos) << r.err;
  // The sqlite3 shell reads the same: one file per content, the text as written.
  EXPECT_EQ(sqlite3(db, "PRAGMA integrity_check"), "ok\n");
  EXPECT_EQ(sqlite3(db, "SELECT origin, accepted FROM project_versions ORDER BY number"), "run|1\nrun|0\n");
  EXPECT_EQ(sqlite3(db, "SELECT f.name, f.data = CAST(f.data AS BLOB) FROM project_versions v JOIN project_files f "
                        "ON f.hash = v.hash WHERE v.number = 1"),
            "list.yaml|1\n");
  EXPECT_EQ(sqlite3(db, "SELECT f.data FROM project_versions v JOIN project_files f ON f.hash = v.hash "
                        "WHERE v.number = 1"),
            project_text(3) + "\n");  // the shell ends each row with a newline
}

// A start that fails after the project loaded (here: its Modbus port is
// taken) is on record: the version as accepted (it loaded: a later `run`
// without a file boots it) and a start-failed event with the reason.
TEST(CliProjects, ARunThatFailsBeforeItsFirstScanIsRecorded) {
  const std::string db = temp_db("start_failed");
  const std::string path = write_temp_file("start_failed.yaml", project_text(4));
  TakenPort taken;
  ASSERT_GT(taken.port, 0);
  const std::string port = std::to_string(taken.port);
  auto r = run_cli("run " + path + " --no-status --duration 1s --modbus-port " + port + " --db " + db);
  taken.release();
  ASSERT_EQ(r.rc, 2) << r.err;
  EXPECT_EQ(sqlite3(db, "SELECT origin, accepted FROM project_versions"), "run|1\n");
  EXPECT_EQ(sqlite3(db, "SELECT kind || ': ' || message FROM events WHERE kind = 'start-failed'"),
            "start-failed: the Modbus server could not listen on 127.0.0.1:" + port + " (exit status 2)\n");
  EXPECT_EQ(sqlite3(db, "SELECT count(*) FROM events WHERE kind IN ('start', 'stop')"), "0\n") << "it never ran";
  EXPECT_EQ(sqlite3(db, "PRAGMA integrity_check"), "ok\n");
}

TEST(CliProjects, ProjectsWithoutADatabaseSaysSo) {
  auto r = run_cli("projects --db /nonexistent/plc.db");
  EXPECT_EQ(r.rc, 2);
  EXPECT_NE(r.err.find("no database at /nonexistent/plc.db"), std::string::npos) << r.err;
}

TEST(CliProjects, RunWithoutAFileStartsTheLastAcceptedProject) {
  const std::string db = temp_db("boot");
  auto r = run_cli("run --no-status --duration 100ms --db " + db);
  EXPECT_EQ(r.rc, 2);
  EXPECT_NE(r.err.find("no database at " + db), std::string::npos) << r.err;
  const std::string path = write_temp_file("boot.yaml", project_text(7));
  ASSERT_EQ(run_cli("run " + path + " --no-status --duration 100ms --db " + db).rc, 0);
  write_temp_file("boot.yaml", "tasks: [{name: t, period: 1ms}]\nblocks: [{name: m, type: NOPE}]\n");
  ASSERT_EQ(run_cli("run " + path + " --no-status --duration 100ms --db " + db).rc, 2);  // rejected: not the boot project
  const std::string pid = write_temp_file("boot.pid", "");
  Instance plc({"--no-status", "--db", db, "--pid-file", pid}, "boot");
  EXPECT_TRUE(plc.wait_for("syncplc: starting version 1 of " + db)) << slurp(plc.err);
  std::string listing;
  EXPECT_TRUE(projects_show(db, "boot      accepted  tank 7", &listing)) << listing;
  // Its pid file works as any: a reload loads the extracted project file again.
  r = run_cli("reload --pid-file " + pid);
  EXPECT_EQ(r.rc, 0) << r.out << r.err;
  EXPECT_NE(r.out.find("accepted: reloaded "), std::string::npos) << r.out;
  EXPECT_EQ(plc.stop(), 0) << slurp(plc.err);
  EXPECT_EQ(sqlite3(db, "SELECT origin, source FROM project_versions WHERE number = 3"), "boot|version 1\n");
}

TEST(CliProjects, RunWithoutAFileRefusesADatabaseWithNoAcceptedProject) {
  const std::string db = temp_db("noboot");
  const std::string path = write_temp_file("noboot.yaml", "tasks: [{name: t, period: 1ms}]\nblocks: [{name: m, type: NOPE}]\n");
  ASSERT_EQ(run_cli("run " + path + " --no-status --duration 100ms --db " + db).rc, 2);
  auto r = run_cli("run --no-status --duration 100ms --db " + db);
  EXPECT_EQ(r.rc, 2);
  EXPECT_NE(r.err.find("holds no accepted project yet: give a project file"), std::string::npos) << r.err;
}

TEST(CliProjects, ReloadVersionRollsARunningInstanceBackByOnlineChange) {
  const std::string db = temp_db("rollback");
  const std::string path = write_temp_file("rollback.yaml", project_text(1));
  const std::string pid = write_temp_file("rollback.pid", "");
  Instance plc({path, "--no-status", "--db", db, "--pid-file", pid}, "rollback");
  std::string listing;
  ASSERT_TRUE(projects_show(db, "run       accepted  tank 1", &listing)) << listing << slurp(plc.err);
  write_temp_file("rollback.yaml", project_text(2));
  auto r = run_cli("reload --pid-file " + pid);
  ASSERT_EQ(r.rc, 0) << r.out << r.err;
  write_temp_file("rollback.yaml", "tasks: [{name: t, period: 1ms}]\nblocks: [{name: m, type: NOPE}]\n");
  r = run_cli("reload --pid-file " + pid);
  EXPECT_EQ(r.rc, 1) << r.out;
  ASSERT_TRUE(projects_show(db, "reload    rejected", &listing)) << listing;
  // Back to version 1 while the file on disk is broken.
  r = run_cli("reload --pid-file " + pid + " --version 1");
  ASSERT_EQ(r.rc, 0) << r.out << r.err;
  EXPECT_NE(r.out.find("accepted: reloaded version 1 ("), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("tag values carried over"), std::string::npos) << r.out;
  ASSERT_TRUE(projects_show(db, "rollback  accepted  tank 1", &listing)) << listing;
  // A rejected version and a missing one are refused; the program runs on.
  r = run_cli("reload --pid-file " + pid + " --version 3");
  EXPECT_EQ(r.rc, 1);
  EXPECT_NE(r.out.find("rejected: rollback refused: version 3 was rejected"), std::string::npos) << r.out;
  r = run_cli("reload --pid-file " + pid + " --version 99");
  EXPECT_EQ(r.rc, 1);
  EXPECT_NE(r.out.find("there is no version 99"), std::string::npos) << r.out;
  EXPECT_EQ(waitpid(plc.pid, nullptr, WNOHANG), 0);  // still running
  EXPECT_EQ(plc.stop(), 0) << slurp(plc.err);
  EXPECT_EQ(sqlite3(db, "SELECT number, origin, accepted, source FROM project_versions WHERE origin = 'rollback'"),
            "4|rollback|1|version 1\n");
  // The rollback's content is version 1's, stored once.
  EXPECT_EQ(sqlite3(db, "SELECT count(DISTINCT hash) FROM project_versions WHERE number IN (1, 4)"), "1\n");
  // The files it ran from: beside the database given with --db (as its
  // uploads are), not under $XDG_STATE_HOME, and private to the user.
  const auto dir = std::filesystem::path(db).parent_path() / "projects";
  ASSERT_TRUE(std::filesystem::exists(dir)) << dir;
  EXPECT_EQ(std::filesystem::status(dir).permissions() & std::filesystem::perms::all, std::filesystem::perms::owner_all);
  for (const auto& e : std::filesystem::directory_iterator(dir))
    EXPECT_EQ(e.status().permissions() & std::filesystem::perms::all, std::filesystem::perms::owner_all) << e.path();
}

}  // namespace
