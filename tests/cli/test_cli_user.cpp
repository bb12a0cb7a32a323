// `syncplc user` end to end: users added with --password-stdin, listed,
// changed and removed in the database the command line names (--db, a
// project's store: path), refusals with their messages and exit status 2,
// and a user added while `syncplc run` holds the same database.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <optional>
#include <sstream>
#include <thread>

#include "runtime/web/users.hpp"
#include "tests/support/cli_runner.hpp"
#include "tests/support/test_blocks.hpp"

namespace {

namespace fs = std::filesystem;
using syncplc::testing::run_cli;
using syncplc::testing::run_cli_input;
using syncplc::testing::write_temp_file;
using syncplc::web::Role;
using syncplc::web::UserStore;

// A fresh directory of this process for one test's database.
std::string fresh_dir(const std::string& name) {
  const fs::path dir = fs::path(write_temp_file(name + ".marker", "")).parent_path() / name;
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir.string();
}

// Whether `password` is `name`'s in the database at `db` (and with which role).
std::optional<Role> verified_role(const std::string& db, const std::string& name, const std::string& password) {
  std::string err;
  auto users = UserStore::open(db, &err);
  EXPECT_TRUE(users) << err;
  if (!users) return std::nullopt;
  auto u = users->verify(name, password);
  return u ? std::optional<Role>(u->role) : std::nullopt;
}

TEST(CliUser, AddWithPasswordStdinThenListShowsTheUsersAndTheirRoles) {
  const std::string db = fresh_dir("user-add") + "/plc.db";
  auto r = run_cli_input("user add alice --role engineer --password-stdin --db " + db, "alice's secret\n");
  ASSERT_EQ(r.rc, 0) << r.err;
  EXPECT_EQ(r.out, "user 'alice' added as engineer to " + db + "\n");
  EXPECT_EQ(r.err, "");
  r = run_cli_input("user add bob --role operator --password-stdin --db " + db, "bob's secret\r\n");
  ASSERT_EQ(r.rc, 0) << r.err;
  r = run_cli_input("user add carol --role viewer --password-stdin --db " + db, "no line end here");
  ASSERT_EQ(r.rc, 0) << r.err;

  EXPECT_EQ(verified_role(db, "alice", "alice's secret"), Role::Engineer) << "the line end is not the password's";
  EXPECT_EQ(verified_role(db, "bob", "bob's secret"), Role::Operator) << "nor a CRLF";
  EXPECT_EQ(verified_role(db, "carol", "no line end here"), Role::Viewer);
  EXPECT_FALSE(verified_role(db, "alice", "alice's secret\n"));

  r = run_cli("user list --db " + db);
  ASSERT_EQ(r.rc, 0) << r.err;
  const auto lines = [&] {
    std::vector<std::string> out;
    std::istringstream in(r.out);
    for (std::string l; std::getline(in, l);) out.push_back(l);
    return out;
  }();
  ASSERT_EQ(lines.size(), 4u) << r.out;
  EXPECT_EQ(lines[0], "name                      role      created (UTC)");
  EXPECT_EQ(lines[1].substr(0, 36), "alice                     engineer  ");
  EXPECT_EQ(lines[2].substr(0, 36), "bob                       operator  ");
  EXPECT_EQ(lines[3].substr(0, 36), "carol                     viewer    ");
  EXPECT_EQ(r.out.find("secret"), std::string::npos);
}

TEST(CliUser, ListOfAnEmptyOrMissingDatabaseSaysHowToAddTheFirstUser) {
  const std::string dir = fresh_dir("user-empty");
  const std::string db = dir + "/plc.db";
  auto r = run_cli("user list --db " + dir + "/typo/plc.db");
  ASSERT_EQ(r.rc, 0) << r.err;
  EXPECT_EQ(r.out, "no users: no database at " + dir + "/typo/plc.db yet; add the first with: syncplc user add NAME "
                   "--role engineer\n");
  EXPECT_FALSE(fs::exists(dir + "/typo")) << "only add makes a database";
  r = run_cli("user remove alice --db " + dir + "/typo/plc.db");
  EXPECT_EQ(r.rc, 2);
  EXPECT_EQ(r.err, "syncplc: user: there is no user 'alice': no database at " + dir + "/typo/plc.db\n");
  EXPECT_FALSE(fs::exists(dir + "/typo"));

  ASSERT_EQ(run_cli_input("user add alice --role viewer --password-stdin --db " + db, "long enough\n").rc, 0);
  ASSERT_EQ(run_cli("user remove alice --db " + db).rc, 0);
  r = run_cli("user list --db " + db);
  ASSERT_EQ(r.rc, 0) << r.err;
  EXPECT_EQ(r.out, "no users in " + db + "; add the first with: syncplc user add NAME --role engineer\n");
}

TEST(CliUser, ABadRoleAShortPasswordOrAnExistingUserIsRefusedWithExitStatus2) {
  const std::string db = fresh_dir("user-refuse") + "/plc.db";
  auto r = run_cli_input("user add alice --role admin --password-stdin --db " + db, "long enough\n");
  EXPECT_EQ(r.rc, 2);
  EXPECT_EQ(r.err, "syncplc: user: unknown role 'admin': viewer, operator or engineer\n");

  r = run_cli_input("user add alice --role viewer --password-stdin --db " + db, "short\n");
  EXPECT_EQ(r.rc, 2);
  EXPECT_EQ(r.err, "syncplc: user: a password has at least 8 bytes; this one has 5\n");

  r = run_cli_input("user add alice --role viewer --password-stdin --db " + db, "");
  EXPECT_EQ(r.rc, 2);
  EXPECT_EQ(r.err, "syncplc: user: --password-stdin: no password on standard input\n");

  r = run_cli_input("user add 'al ice' --role viewer --password-stdin --db " + db, "long enough\n");
  EXPECT_EQ(r.rc, 2);
  EXPECT_EQ(r.err, "syncplc: user: a user name is made of A-Z a-z 0-9 _ . @ -; this one has a space\n");

  ASSERT_EQ(run_cli_input("user add alice --role viewer --password-stdin --db " + db, "long enough\n").rc, 0);
  r = run_cli_input("user add alice --role engineer --password-stdin --db " + db, "another one\n");
  EXPECT_EQ(r.rc, 2);
  EXPECT_EQ(r.err, "syncplc: user: the user 'alice' exists already (change it with `syncplc user passwd` or `role`)\n");
  EXPECT_EQ(verified_role(db, "alice", "long enough"), Role::Viewer) << "unchanged";

  r = run_cli("user role alice boss --db " + db);
  EXPECT_EQ(r.rc, 2);
  EXPECT_EQ(r.err, "syncplc: user: unknown role 'boss': viewer, operator or engineer\n");
  r = run_cli("user add bob --db " + db);
  EXPECT_EQ(r.rc, 2) << "--role is required";
  EXPECT_NE(r.err.find("--role"), std::string::npos) << r.err;
}

TEST(CliUser, WithoutATerminalOrPasswordStdinItSaysHowToGiveThePassword) {
  const std::string db = fresh_dir("user-notty") + "/plc.db";
  auto r = run_cli("user add alice --role viewer --db " + db);  // stdin: /dev/null
  EXPECT_EQ(r.rc, 2);
  EXPECT_EQ(r.err, "syncplc: user: standard input is not a terminal to ask the password on; give it as one line "
                   "with --password-stdin\n");
  EXPECT_EQ(run_cli("user list --db " + db).out.find("alice"), std::string::npos);
}

TEST(CliUser, PasswdRoleAndRemoveChangeTheUser) {
  const std::string db = fresh_dir("user-change") + "/plc.db";
  ASSERT_EQ(run_cli_input("user add alice --role viewer --password-stdin --db " + db, "first password\n").rc, 0);

  auto r = run_cli_input("user passwd alice --password-stdin --db " + db, "second password\n");
  ASSERT_EQ(r.rc, 0) << r.err;
  EXPECT_EQ(r.out, "password of 'alice' changed in " + db + "\n");
  EXPECT_FALSE(verified_role(db, "alice", "first password"));
  EXPECT_EQ(verified_role(db, "alice", "second password"), Role::Viewer);
  r = run_cli_input("user passwd alice --password-stdin --db " + db, "tiny\n");
  EXPECT_EQ(r.rc, 2);
  EXPECT_EQ(r.err, "syncplc: user: a password has at least 8 bytes; this one has 4\n");
  r = run_cli_input("user passwd zoe --password-stdin --db " + db, "second password\n");
  EXPECT_EQ(r.rc, 2);
  EXPECT_EQ(r.err, "syncplc: user: there is no user 'zoe' in " + db + "\n");

  r = run_cli("user role alice operator --db " + db);
  ASSERT_EQ(r.rc, 0) << r.err;
  EXPECT_EQ(r.out, "user 'alice' is now operator in " + db + "\n");
  EXPECT_NE(run_cli("user list --db " + db).out.find("alice                     operator"), std::string::npos);
  r = run_cli("user role zoe operator --db " + db);
  EXPECT_EQ(r.rc, 2);
  EXPECT_EQ(r.err, "syncplc: user: there is no user 'zoe'\n");

  r = run_cli("user remove alice --db " + db);
  ASSERT_EQ(r.rc, 0) << r.err;
  EXPECT_EQ(r.out, "user 'alice' removed from " + db + "\n");
  EXPECT_FALSE(verified_role(db, "alice", "second password"));
  r = run_cli("user remove alice --db " + db);
  EXPECT_EQ(r.rc, 2);
  EXPECT_EQ(r.err, "syncplc: user: there is no user 'alice'\n");
}

TEST(CliUser, TheDatabaseIsTheProjectsStorePathOrTheDefaultAsForRun) {
  const std::string dir = fresh_dir("user-project");
  const std::string project = dir + "/line.yaml";
  write_temp_file("user-project/line.yaml", "tasks: [{name: t, period: 1ms}]\nstore: {path: state/line.db}\n");
  auto r = run_cli_input("user add alice --role operator --password-stdin " + project, "a good password\n");
  ASSERT_EQ(r.rc, 0) << r.err;
  EXPECT_EQ(r.out, "user 'alice' added as operator to " + dir + "/state/line.db\n");
  EXPECT_EQ(verified_role(dir + "/state/line.db", "alice", "a good password"), Role::Operator);
  EXPECT_NE(run_cli("user list " + project).out.find("alice"), std::string::npos);

  // No project, no --db: the default database (this test process's XDG_STATE_HOME).
  r = run_cli_input("user add dora --role viewer --password-stdin", "a good password\n");
  ASSERT_EQ(r.rc, 0) << r.err;
  const std::string fallback = std::string(std::getenv("XDG_STATE_HOME")) + "/syncplc/plc.db";
  EXPECT_EQ(r.out, "user 'dora' added as viewer to " + fallback + "\n");
  EXPECT_EQ(run_cli("user remove dora").rc, 0);

  write_temp_file("user-project/broken.yaml", "tasks: [{name: t, period: 1xs}]\n");
  r = run_cli("user list " + dir + "/broken.yaml");
  EXPECT_EQ(r.rc, 2);
  EXPECT_NE(r.err.find("syncplc: user: the project " + dir + "/broken.yaml does not load"), std::string::npos) << r.err;
}

// The store thread of a running PLC writes the same file (the historian
// every second, besides the start's records); `user add` waits for its
// transactions and needs no instance lock.
TEST(CliUser, AddsAUserWhileSyncplcRunHoldsTheDatabase) {
  const std::string dir = fresh_dir("user-beside-run");
  const std::string db = dir + "/plc.db";
  const std::string project = write_temp_file("user-beside-run.yaml",
                                              "tasks: [{name: main, period: 1ms}]\n"
                                              "tags: [{name: pos, type: LREAL, trend: {rate: 10ms}}]\n"
                                              "blocks: [{name: ref, type: COSINE_TRAJECTORY, task: main, params: "
                                              "{amplitude: 10, omega: 3, cycles: 0}, inputs: {enable: TRUE}}]\n"
                                              "connections: [ref.x -> pos]\n");
  const std::string out = dir + "/run.out";
  pid_t pid = fork();
  ASSERT_GE(pid, 0);
  if (pid == 0) {
    FILE* f = std::freopen(out.c_str(), "w", stdout);
    FILE* g = std::freopen((out + ".err").c_str(), "w", stderr);
    (void)f;
    (void)g;
    execl(SYNCPLC_BINARY, SYNCPLC_BINARY, "run", project.c_str(), "--no-status", "--duration", "3s", "--db", db.c_str(),
          static_cast<char*>(nullptr));
    _exit(127);
  }
  for (int i = 0; i < 100 && !fs::exists(db); ++i) std::this_thread::sleep_for(std::chrono::milliseconds(20));
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  auto r = run_cli_input("user add alice --role engineer --password-stdin --db " + db, "beside the PLC\n");
  auto list = run_cli("user list --db " + db);
  int status = 0;
  waitpid(pid, &status, 0);
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 0) << syncplc::testing::slurp(out + ".err");
  ASSERT_EQ(r.rc, 0) << r.err;
  EXPECT_NE(list.out.find("alice                     engineer"), std::string::npos) << list.out << list.err;
  EXPECT_EQ(verified_role(db, "alice", "beside the PLC"), Role::Engineer);
}

}  // namespace
