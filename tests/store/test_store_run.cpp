// `syncplc run` and its database's files (docs/store.md, "One writer", "Bad
// files", "A read-only database"): the real binary, with the sqlite3 shell
// as the other process and as the reader of what was stored.
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <pwd.h>
#include <sys/stat.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>

#include "tests/store/store_test_util.hpp"

namespace syncplc::store {
// Named, not anonymous: unity builds put several test files in one
// translation unit (SYNCPLC_UNITY), where their helpers must not meet.
namespace store_run_test {

namespace fs = std::filesystem;
using ::testing::HasSubstr;
using ::testing::Not;
using testing::read_all;
using testing::run_syncplc;
using testing::ShellHolding;
using testing::sqlite_shell;

// A counter kept in a retained UNIT_DELAY and a persistent total: every run
// goes on from the stored values.
constexpr const char* kProject = R"(project: {name: store_files, version: 1.0.0}
store: {retain_interval: 100ms}
tasks: [{name: fast, period: 10ms}]
tags:
  - {name: total, type: DINT, persistent: true}
blocks:
  - {name: last, type: UNIT_DELAY, datatype: DINT, retain: true, task: fast}
  - {name: inc, type: ADD, datatype: DINT, task: fast, inputs: {IN2: 1}}
connections:
  - last.OUT -> inc.IN1
  - inc.OUT -> total
  - total -> last.IN
)";

struct Plc {
  std::string dir, project, db;
};

Plc make_plc(const std::string& name) {
  Plc p;
  p.dir = testing::fresh_dir(name);
  p.project = p.dir + "/p.yaml";
  p.db = p.dir + "/plc.db";
  std::ofstream(p.project) << kProject;
  return p;
}

testing::RunOutput run(const Plc& p, int uid = -1, int gid = -1) {
  return run_syncplc({"run", p.project, "--db", p.db, "--no-status", "-d", "300ms", "--http", "127.0.0.1:0"},
                     p.dir + "/run.out", uid, gid);
}

// The retained values as stored (what a scan counted is not asked: a
// loaded machine may end a 300 ms run before its first scan).
std::string stored_values(const std::string& db) {
  return sqlite_shell(db, "SELECT group_concat(name || '=' || shown, ', ') FROM (SELECT * FROM retain_value ORDER BY name)");
}

std::int64_t events(const std::string& db) { return std::stoll(sqlite_shell(db, "SELECT count(*) FROM events")); }

// The names in `dir` of files moved aside.
std::vector<std::string> moved_aside(const std::string& dir) {
  std::vector<std::string> v;
  for (const auto& e : fs::directory_iterator(dir))
    if (e.path().filename().string().find(".corrupt-") != std::string::npos) v.push_back(e.path().filename().string());
  return v;
}

unsigned mode_of(const std::string& path) { return static_cast<unsigned>(fs::status(path).permissions() & fs::perms::all); }

TEST(StoreRun, ADatabaseAnotherConnectionHoldsIsRefusedAfterTheBusyTimeoutAndKeptWhole) {
  const Plc p = make_plc("run_busy");
  auto first = run(p);
  ASSERT_EQ(first.status, 0) << first.output;
  const std::string values = stored_values(p.db);
  ASSERT_NE(values, "");
  const std::int64_t recorded = events(p.db);

  ShellHolding shell(p.db, "PRAGMA locking_mode=EXCLUSIVE; BEGIN EXCLUSIVE;");
  ASSERT_TRUE(shell.holding()) << shell.said();
  auto busy = run(p);
  EXPECT_EQ(busy.status, 2) << busy.output;
  EXPECT_THAT(busy.output, HasSubstr("is locked by another connection"));
  EXPECT_THAT(busy.output, HasSubstr("(SQLITE_BUSY)"));
  EXPECT_THAT(busy.output, Not(HasSubstr("moved to")));
  EXPECT_THAT(busy.output, Not(HasSubstr("Statistics"))) << "refused before anything ran";
  shell.release();

  EXPECT_TRUE(moved_aside(p.dir).empty()) << "nothing moved aside";
  EXPECT_EQ(stored_values(p.db), values) << "the values are in the live file";
  EXPECT_EQ(events(p.db), recorded);
}

// chmod 0444 on the database: run restores from it, says so, writes
// nothing, changes no mode, and leaves no file that stops a later start.
void read_only_run(const Plc& p, int uid, int gid) {
  auto first = run(p, uid, gid);
  ASSERT_EQ(first.status, 0) << first.output;
  ASSERT_NE(stored_values(p.db), "") << first.output;
  const std::int64_t recorded = events(p.db);
  // The shell's read-only connection left an empty WAL and its index (as
  // any reader may); gone, so the test sees what the runs leave.
  ASSERT_EQ(fs::file_size(p.db + "-wal"), 0u);
  fs::remove(p.db + "-wal");
  fs::remove(p.db + "-shm");
  fs::permissions(p.db, fs::perms::owner_read | fs::perms::group_read | fs::perms::others_read, fs::perm_options::replace);
  const std::string bytes = read_all(p.db);

  for (int i = 0; i < 2; ++i) {
    auto ro = run(p, uid, gid);
    EXPECT_EQ(ro.status, 0) << ro.output;
    EXPECT_THAT(ro.output, HasSubstr("warning: store READ-ONLY"));
    EXPECT_THAT(ro.output, HasSubstr("retain: warm start: 2 of 2 retained values restored"));
    EXPECT_THAT(ro.output, HasSubstr("Store: READ-ONLY"));
    EXPECT_EQ(mode_of(p.db), 0444u) << "the user's mode stays";
    EXPECT_FALSE(fs::exists(p.db + "-wal")) << "no WAL left beside a read-only database";
    EXPECT_FALSE(fs::exists(p.db + "-shm")) << "no WAL index left beside a read-only database";
    EXPECT_TRUE(read_all(p.db) == bytes) << "nothing recorded";
  }
  // A reader of the write-protected file leaves nothing beside it either.
  auto reader = run_syncplc({"events", "--db", p.db}, p.dir + "/events.out", uid, gid);
  EXPECT_EQ(reader.status, 0) << reader.output;
  EXPECT_THAT(reader.output, HasSubstr("start"));
  EXPECT_FALSE(fs::exists(p.db + "-wal"));
  EXPECT_FALSE(fs::exists(p.db + "-shm"));
  // Writable again: the next start records as before.
  fs::permissions(p.db, fs::perms::owner_read | fs::perms::owner_write, fs::perm_options::replace);
  auto again = run(p, uid, gid);
  EXPECT_EQ(again.status, 0) << again.output;
  EXPECT_THAT(again.output, Not(HasSubstr("READ-ONLY")));
  EXPECT_GT(events(p.db), recorded) << "it records again";
}

TEST(StoreRun, AReadOnlyDatabaseRunsTheStoreReadOnly) {
  const Plc p = make_plc("run_read_only");
  read_only_run(p, -1, -1);
}

// What the HTTP API's /status says of the store while run runs on a
// write-protected database (the HMI's overview shows the same).
TEST(StoreRun, StatusSaysTheStoreIsReadOnly) {
  const Plc p = make_plc("run_read_only_status");
  ASSERT_EQ(run(p).status, 0);
  fs::permissions(p.db, fs::perms::owner_read, fs::perm_options::replace);
  const std::string out = p.dir + "/long.out";
  const pid_t plc = testing::spawn_syncplc({"run", p.project, "--db", p.db, "--no-status", "-d", "60s", "--http", "127.0.0.1:0"}, out);
  // Until run says where its HTTP API listens.
  std::string url;
  for (int i = 0; i < 3000 && url.empty(); ++i) {
    const std::string text = read_all(out);
    const auto at = text.find("HMI and HTTP API on ");
    if (at != std::string::npos && text.find('\n', at) != std::string::npos)
      url = text.substr(at + 20, text.find('\n', at) - at - 20);
    else usleep(10'000);
  }
  std::string status;
  if (!url.empty())
    if (FILE* c = popen(("curl -s " + url + "api/v1/status").c_str(), "r")) {
      char buf[4096];
      while (std::size_t n = fread(buf, 1, sizeof buf, c)) status.append(buf, n);
      pclose(c);
    }
  kill(plc, SIGTERM);
  EXPECT_EQ(testing::wait_syncplc(plc), 0) << read_all(out);
  ASSERT_FALSE(url.empty()) << read_all(out);
  EXPECT_THAT(status, HasSubstr(R"("store":{"detail":"its mode is 0400","state":"read-only"})")) << status;
}

TEST(StoreRun, AReadOnlyDatabaseRunsTheStoreReadOnlyForAUserThePermissionsBind) {
  if (geteuid() != 0) GTEST_SKIP() << "needs root to run syncplc as another user";
  const passwd* nobody = getpwnam("nobody");
  ASSERT_NE(nobody, nullptr);
  const Plc p = make_plc("run_read_only_nobody");
  ASSERT_EQ(chown(p.dir.c_str(), nobody->pw_uid, nobody->pw_gid), 0);
  fs::permissions(p.project, fs::perms::others_read, fs::perm_options::add);
  fs::permissions(fs::path(p.dir).parent_path(), fs::perms::others_exec, fs::perm_options::add);
  read_only_run(p, static_cast<int>(nobody->pw_uid), static_cast<int>(nobody->pw_gid));
}

}  // namespace
}  // namespace syncplc::store
