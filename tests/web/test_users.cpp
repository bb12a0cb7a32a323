// The users of the HTTP API (runtime/web/users.hpp): adding, checking and
// changing them, what the table holds (read with Debian's sqlite3 shell:
// salted Argon2id hashes, never a password), a write beside another
// connection's transaction, damaged rows.
#include <SQLiteCpp/Database.h>
#include <SQLiteCpp/Statement.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <sodium.h>
#include <time.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <thread>

#include "runtime/store/database.hpp"
#include "runtime/web/users.hpp"
#include "tests/store/store_test_util.hpp"

namespace syncplc::web {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;
using ::testing::StartsWith;
using store::testing::fresh_dir;
using store::testing::sqlite_shell;

constexpr const char* kPassword = "correct horse battery";

std::unique_ptr<UserStore> open_users(const std::string& path) {
  std::string err;
  auto users = UserStore::open(path, &err);
  EXPECT_TRUE(users) << err;
  return users;
}

std::string read_all(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(f), {});
}

TEST(Users, ThereIsNoUserUntilOneIsAddedAndAnAddedOneVerifies) {
  auto users = open_users(fresh_dir("users-add") + "/plc.db");
  ASSERT_TRUE(users);
  EXPECT_EQ(users->count(), 0u) << "no default user, ever";
  EXPECT_TRUE(users->list().empty());
  EXPECT_FALSE(users->verify("admin", "adminadmin"));

  std::string err;
  ASSERT_TRUE(users->add("alice", kPassword, Role::Engineer, &err)) << err;
  EXPECT_EQ(users->count(), 1u);
  auto alice = users->verify("alice", kPassword);
  ASSERT_TRUE(alice);
  EXPECT_EQ(alice->name, "alice");
  EXPECT_EQ(alice->role, Role::Engineer);
  EXPECT_GT(alice->created_ns, 1'700'000'000'000'000'000) << "wall time, ns since 1970";

  EXPECT_FALSE(users->verify("alice", "correct horse battery ")) << "a wrong password";
  EXPECT_FALSE(users->verify("alice", "Correct horse battery"));
  EXPECT_FALSE(users->verify("bob", kPassword)) << "an unknown user";
  EXPECT_FALSE(users->verify("Alice", kPassword)) << "names are case-sensitive";
}

TEST(Users, RefusesAnExistingNameAndNamesOrPasswordsOutsideTheRules) {
  auto users = open_users(fresh_dir("users-refuse") + "/plc.db");
  ASSERT_TRUE(users);
  std::string err;
  ASSERT_TRUE(users->add("op.1@line-2_b", kPassword, Role::Operator, &err)) << err;
  EXPECT_FALSE(users->add("op.1@line-2_b", "another password", Role::Viewer, &err));
  EXPECT_THAT(err, HasSubstr("the user 'op.1@line-2_b' exists already"));
  EXPECT_EQ(users->verify("op.1@line-2_b", kPassword)->role, Role::Operator) << "the first one unchanged";

  EXPECT_FALSE(users->add("", kPassword, Role::Viewer, &err));
  EXPECT_EQ(err, "the user name is empty");
  EXPECT_FALSE(users->add(std::string(65, 'a'), kPassword, Role::Viewer, &err));
  EXPECT_EQ(err, "a user name has at most 64 characters; this one has 65");
  EXPECT_TRUE(users->add(std::string(64, 'a'), kPassword, Role::Viewer, &err)) << err;
  EXPECT_FALSE(users->add("a b", kPassword, Role::Viewer, &err));
  EXPECT_EQ(err, "a user name is made of A-Z a-z 0-9 _ . @ -; this one has a space");
  EXPECT_FALSE(users->add("a;b", kPassword, Role::Viewer, &err));
  EXPECT_THAT(err, HasSubstr("this one has ';'"));
  EXPECT_FALSE(users->add("j\xc3\xb6rg", kPassword, Role::Viewer, &err));
  EXPECT_THAT(err, HasSubstr("the byte 0xc3"));

  EXPECT_FALSE(users->add("carol", "1234567", Role::Viewer, &err));
  EXPECT_EQ(err, "a password has at least 8 bytes; this one has 7");
  EXPECT_FALSE(users->add("carol", std::string(1025, 'x'), Role::Viewer, &err));
  EXPECT_EQ(err, "a password has at most 1024 bytes; this one has 1025");
  EXPECT_TRUE(users->add("carol", "12345678", Role::Viewer, &err)) << err;
  EXPECT_TRUE(users->add("dave", std::string(1024, 'x'), Role::Viewer, &err)) << err;
  EXPECT_TRUE(users->verify("dave", std::string(1024, 'x')));
  EXPECT_EQ(users->count(), 4u);
}

TEST(Users, RemoveSetPasswordAndSetRoleChangeWhatVerifyAndListSee) {
  auto users = open_users(fresh_dir("users-change") + "/plc.db");
  ASSERT_TRUE(users);
  std::string err;
  ASSERT_TRUE(users->add("alice", kPassword, Role::Viewer, &err)) << err;
  ASSERT_TRUE(users->add("bob", kPassword, Role::Operator, &err)) << err;

  ASSERT_TRUE(users->set_password("alice", "a new password", &err)) << err;
  EXPECT_FALSE(users->verify("alice", kPassword)) << "the old password no longer works";
  EXPECT_TRUE(users->verify("alice", "a new password"));
  EXPECT_FALSE(users->set_password("alice", "short", &err));
  EXPECT_EQ(err, "a password has at least 8 bytes; this one has 5");
  EXPECT_FALSE(users->set_password("zoe", "a new password", &err));
  EXPECT_EQ(err, "there is no user 'zoe'");

  ASSERT_TRUE(users->set_role("alice", Role::Engineer, &err)) << err;
  EXPECT_EQ(users->verify("alice", "a new password")->role, Role::Engineer);
  EXPECT_EQ(users->find("alice")->role, Role::Engineer);
  EXPECT_FALSE(users->set_role("zoe", Role::Engineer, &err));
  EXPECT_EQ(err, "there is no user 'zoe'");

  auto all = users->list();
  ASSERT_EQ(all.size(), 2u);
  EXPECT_EQ(all[0].name, "alice");
  EXPECT_EQ(all[0].role, Role::Engineer);
  EXPECT_EQ(all[1].name, "bob");
  EXPECT_EQ(all[1].role, Role::Operator);

  ASSERT_TRUE(users->remove("bob", &err)) << err;
  EXPECT_FALSE(users->verify("bob", kPassword));
  EXPECT_FALSE(users->find("bob"));
  EXPECT_FALSE(users->exists("bob"));
  EXPECT_FALSE(users->remove("bob", &err));
  EXPECT_EQ(err, "there is no user 'bob'");
  EXPECT_EQ(users->count(), 1u);
}

TEST(Users, EveryChangeOfCredentialsGivesANewStampAndANameAddedAgainAnotherOne) {
  // What a session is bound to (sessions.hpp): the tokens survived
  // a password change, and a name removed and added again inherited them.
  auto users = open_users(fresh_dir("users-stamp") + "/plc.db");
  ASSERT_TRUE(users);
  std::string err;
  ASSERT_TRUE(users->add("alice", kPassword, Role::Operator, &err)) << err;
  ASSERT_TRUE(users->add("bob", kPassword, Role::Operator, &err)) << err;
  const std::int64_t first = users->find("alice")->stamp;
  EXPECT_NE(first, users->find("bob")->stamp) << "random: two users, two stamps";
  EXPECT_EQ(users->verify("alice", kPassword)->stamp, first) << "the login sees the row's stamp";

  ASSERT_TRUE(users->set_password("alice", "a new password", &err)) << err;
  const std::int64_t after_passwd = users->find("alice")->stamp;
  EXPECT_NE(after_passwd, first);
  ASSERT_TRUE(users->set_role("alice", Role::Operator, &err)) << err;  // the same role: still a change of the row
  const std::int64_t after_role = users->find("alice")->stamp;
  EXPECT_NE(after_role, after_passwd);
  ASSERT_TRUE(users->remove("alice", &err)) << err;
  ASSERT_TRUE(users->add("alice", "a new password", Role::Operator, &err)) << err;
  EXPECT_NE(users->find("alice")->stamp, after_role) << "the same name, password and role: another user";
  const std::int64_t bob = users->find("bob")->stamp;
  EXPECT_EQ(users->find("bob")->stamp, bob) << "reading changes nothing";
}

TEST(Users, ATableOfVersionOneGetsAStampForEveryRow) {
  const std::string path = fresh_dir("users-v1") + "/plc.db";
  {
    // The table as syncplc made it before the stamp (version 1).
    SQLite::Database raw(path, SQLite::OPEN_READWRITE | SQLite::OPEN_CREATE);
    raw.exec("CREATE TABLE schema (part TEXT PRIMARY KEY, version INTEGER NOT NULL)");
    raw.exec("INSERT INTO schema VALUES ('users', 1)");
    raw.exec("CREATE TABLE users (name TEXT PRIMARY KEY, role TEXT NOT NULL, hash TEXT NOT NULL,"
             " created_ns INTEGER NOT NULL, changed_ns INTEGER NOT NULL)");
    raw.exec(std::string("INSERT INTO users VALUES ('old', 'engineer', '") + hash_password(kPassword) + "', 1, 1)");
  }
  auto users = open_users(path);
  ASSERT_TRUE(users);
  auto old = users->verify("old", kPassword);
  ASSERT_TRUE(old) << "the user from before still logs in";
  EXPECT_EQ(old->role, Role::Engineer);
  EXPECT_EQ(sqlite_shell(path, "SELECT version FROM schema WHERE part = 'users'"), "2");
}

TEST(Users, UsersSurviveTheConnectionAndAreSharedWithAnotherOne) {
  const std::string path = fresh_dir("users-reopen") + "/plc.db";
  std::string err;
  {
    auto users = open_users(path);
    ASSERT_TRUE(users);
    ASSERT_TRUE(users->add("alice", kPassword, Role::Operator, &err)) << err;
  }
  auto again = open_users(path);
  auto other = open_users(path);
  ASSERT_TRUE(again && other);
  EXPECT_EQ(again->verify("alice", kPassword)->role, Role::Operator);
  ASSERT_TRUE(other->set_role("alice", Role::Viewer, &err)) << err;
  EXPECT_EQ(again->find("alice")->role, Role::Viewer) << "no cache: each look is the table's";
}

TEST(Users, TheTableHoldsSaltedArgon2idHashesAndNoPasswordAsTheSqliteShellShows) {
  const std::string path = fresh_dir("users-hash") + "/plc.db";
  auto users = open_users(path);
  ASSERT_TRUE(users);
  std::string err;
  ASSERT_TRUE(users->add("alice", kPassword, Role::Engineer, &err)) << err;
  ASSERT_TRUE(users->add("bob", kPassword, Role::Viewer, &err)) << err;

  const std::string rows = sqlite_shell(path, "SELECT name, role, hash, created_ns, changed_ns FROM users ORDER BY name");
  EXPECT_THAT(rows, HasSubstr("alice|engineer|$argon2id$v=19$m=65536,t=2,p=1$"));
  EXPECT_THAT(rows, HasSubstr("bob|viewer|$argon2id$v=19$m=65536,t=2,p=1$"));
  EXPECT_THAT(rows, ::testing::Not(HasSubstr(kPassword)));
  const std::string a = sqlite_shell(path, "SELECT hash FROM users WHERE name = 'alice'");
  const std::string b = sqlite_shell(path, "SELECT hash FROM users WHERE name = 'bob'");
  EXPECT_THAT(a, StartsWith("$argon2id$"));
  EXPECT_THAT(b, StartsWith("$argon2id$"));
  EXPECT_NE(a, b) << "the same password hashes differently (a salt each)";
  EXPECT_EQ(sqlite_shell(path, "SELECT count(*) FROM users WHERE created_ns = changed_ns AND created_ns > 0"), "2");
  EXPECT_EQ(sqlite_shell(path, "SELECT version FROM schema WHERE part = 'users'"), "2");

  // Nor anywhere in the file and its journal.
  users.reset();
  for (const char* suffix : {"", "-wal", "-journal"})
    EXPECT_EQ(read_all(path + suffix).find(kPassword), std::string::npos) << suffix;
  EXPECT_EQ(fs::status(path).permissions() & fs::perms::all, fs::perms::owner_read | fs::perms::owner_write);
}

TEST(Users, TheDummyHashHasTheParametersOfARealOne) {
  const std::string dummy(dummy_password_hash());
  EXPECT_THAT(dummy, StartsWith("$argon2id$"));
  EXPECT_EQ(crypto_pwhash_str_needs_rehash(dummy.c_str(), crypto_pwhash_OPSLIMIT_INTERACTIVE,
                                           crypto_pwhash_MEMLIMIT_INTERACTIVE),
            0)
      << "an unknown name must cost what a known one does";
  const std::string real = hash_password(kPassword);
  EXPECT_EQ(real.substr(0, real.find('$', 15)), dummy.substr(0, dummy.find('$', 15))) << real << " / " << dummy;
}

// Without the dummy hash an unknown name would answer in microseconds and
// a known one in about 0.1 s. Measured in this thread's CPU time (the hash
// is all computation): a loaded machine that takes the CPU away makes the
// wall time longer, not the CPU time, so only the missing hash fails it.
TEST(Users, VerifyOfAnUnknownNameTakesAsLongAsAWrongPassword) {
  auto users = open_users(fresh_dir("users-timing") + "/plc.db");
  ASSERT_TRUE(users);
  std::string err;
  ASSERT_TRUE(users->add("alice", kPassword, Role::Viewer, &err)) << err;
  auto fastest = [&](const std::string& name) {
    auto best = std::chrono::nanoseconds::max();
    const auto cpu = [] {
      timespec ts{};
      clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
      return std::chrono::seconds(ts.tv_sec) + std::chrono::nanoseconds(ts.tv_nsec);
    };
    for (int i = 0; i < 3; ++i) {
      const auto t0 = cpu();
      EXPECT_FALSE(users->verify(name, "not the password"));
      best = std::min(best, std::chrono::duration_cast<std::chrono::nanoseconds>(cpu() - t0));
    }
    return best;
  };
  const auto known = fastest("alice");
  const auto unknown = fastest("mallory");
  EXPECT_GT(unknown * 3, known) << "unknown " << unknown.count() << " ns, known " << known.count() << " ns";
  EXPECT_GT(known * 3, unknown) << "unknown " << unknown.count() << " ns, known " << known.count() << " ns";
}

// `syncplc user add` beside a running PLC: the store thread holds a write
// transaction; the add waits for its commit (busy timeout) instead of failing.
TEST(Users, AWriteWaitsForAnotherConnectionsTransactionAndSucceedsAfterItCommits) {
  const std::string path = fresh_dir("users-busy") + "/plc.db";
  std::string err;
  auto plc = store::Database::open(path, nullptr, &err);  // as `run` holds it: the lock, WAL
  ASSERT_TRUE(plc) << err;
  auto users = open_users(path);
  ASSERT_TRUE(users);

  plc->sql().exec("CREATE TABLE busy (x INTEGER)");
  plc->sql().exec("BEGIN IMMEDIATE");
  plc->sql().exec("INSERT INTO busy VALUES (1)");
  constexpr auto kHeld = std::chrono::milliseconds(1500);
  const auto t0 = std::chrono::steady_clock::now();
  std::thread committer([&] {
    std::this_thread::sleep_for(kHeld);
    plc->sql().exec("COMMIT");
  });
  const bool added = users->add("alice", kPassword, Role::Operator, &err);
  const auto took = std::chrono::steady_clock::now() - t0;
  committer.join();
  ASSERT_TRUE(added) << err;
  EXPECT_GE(took, kHeld) << "the insert waited for the commit";
  EXPECT_TRUE(users->verify("alice", kPassword));
  EXPECT_EQ(plc->sql().execAndGet("SELECT count(*) FROM users").getInt(), 1) << "the PLC's connection sees it";
}

TEST(Users, AWriteThatWaitsLongerThanTheBusyTimeoutFailsWithAClearError) {
  const std::string path = fresh_dir("users-timeout") + "/plc.db";
  auto users = open_users(path);
  ASSERT_TRUE(users);
  std::string err;
  ASSERT_TRUE(users->add("alice", kPassword, Role::Operator, &err)) << err;
  SQLite::Database holder(path, SQLite::OPEN_READWRITE);
  holder.exec("BEGIN EXCLUSIVE");
  const auto t0 = std::chrono::steady_clock::now();
  EXPECT_FALSE(users->set_role("alice", Role::Engineer, &err));
  EXPECT_GE(std::chrono::steady_clock::now() - t0, std::chrono::milliseconds(kUsersBusyTimeoutMs - 100));
  EXPECT_THAT(err, HasSubstr("cannot write the role of 'alice' to " + path + ": database is locked"));
  holder.exec("ROLLBACK");
  EXPECT_TRUE(users->set_role("alice", Role::Engineer, &err)) << err;
}

TEST(Users, ADamagedRowGivesNoUserAndALogLineNeverACrash) {
  const std::string path = fresh_dir("users-damaged") + "/plc.db";
  auto users = open_users(path);
  ASSERT_TRUE(users);
  std::vector<std::string> logged;
  users->set_log([&](const std::string& m) { logged.push_back(m); });
  std::string err;
  ASSERT_TRUE(users->add("good", kPassword, Role::Viewer, &err)) << err;
  const std::string real = hash_password(kPassword);
  {
    SQLite::Database raw(path, SQLite::OPEN_READWRITE);
    SQLite::Statement ins(raw, "INSERT INTO users VALUES (?, ?, ?, 1, 1, 1)");
    auto row = [&](const char* name, const char* role, const std::string& hash) {
      ins.reset();
      ins.bind(1, name);
      ins.bind(2, role);
      ins.bind(3, hash);
      ins.exec();
    };
    row("garbage", "viewer", "not a hash at all");
    row("empty", "viewer", "");
    row("cut", "viewer", real.substr(0, 40));  // within the salt
    row("long", "viewer", real + std::string(300, 'A'));
    row("nul", "viewer", std::string("$argon2id$\0v=19", 15));
    row("badrole", "admin", real);
    raw.exec("INSERT INTO users VALUES ('blob', 'viewer', x'00ff00ff', 1, 1, 1)");
    raw.exec("INSERT INTO users VALUES ('introle', 7, 'x', 1, 1, 1)");
  }
  for (const char* name : {"garbage", "empty", "cut", "long", "nul", "badrole", "blob", "introle"}) {
    logged.clear();
    EXPECT_FALSE(users->verify(name, kPassword)) << name;
    ASSERT_FALSE(logged.empty()) << name << ": the log says why";
    EXPECT_THAT(logged.front(), HasSubstr("'" + std::string(name) + "'"));
    EXPECT_THAT(logged.front(), HasSubstr("damaged"));
  }
  logged.clear();
  EXPECT_FALSE(users->verify("badrole", kPassword));
  EXPECT_EQ(logged, std::vector<std::string>{"the role of user 'badrole' in the database is damaged (not viewer, "
                                             "operator or engineer); set it with `syncplc user role badrole ROLE`"});

  logged.clear();
  const auto all = users->list();
  std::vector<std::string> names;
  for (const auto& u : all) names.push_back(u.name);
  EXPECT_EQ(names, (std::vector<std::string>{"blob", "cut", "empty", "garbage", "good", "long", "nul"}))
      << "rows whose role cannot be read are left out";
  EXPECT_EQ(logged.size(), 9u) << ::testing::PrintToString(logged);  // introle: its role and its hash
  EXPECT_EQ(users->count(), 9u);
  EXPECT_TRUE(users->verify("good", kPassword)) << "the others still work";

  // The repairs the log names.
  ASSERT_TRUE(users->set_password("garbage", "a fresh password", &err)) << err;
  EXPECT_TRUE(users->verify("garbage", "a fresh password"));
  ASSERT_TRUE(users->set_role("badrole", Role::Operator, &err)) << err;
  EXPECT_EQ(users->verify("badrole", kPassword)->role, Role::Operator);
}

TEST(Users, AFileThatIsNotADatabaseIsRefusedWithAClearError) {
  const std::string path = fresh_dir("users-notdb") + "/plc.db";
  std::ofstream(path) << std::string(4096, 'x');
  std::string err;
  EXPECT_FALSE(UserStore::open(path, &err));
  EXPECT_THAT(err, HasSubstr("cannot open the users in the database " + path));
  EXPECT_THAT(err, HasSubstr("file is not a database"));
  EXPECT_EQ(read_all(path), std::string(4096, 'x')) << "left as it was";
}

TEST(Users, ADirectoryThatCannotBeMadeIsAClearError) {
  const std::string file = fresh_dir("users-nodir") + "/file";
  std::ofstream(file) << "x";
  std::string err;
  EXPECT_FALSE(UserStore::open(file + "/plc.db", &err));
  EXPECT_THAT(err, HasSubstr("cannot open the users in the database " + file + "/plc.db"));
}

TEST(Users, MakesTheDirectoryAndFileForTheOwnerOnly) {
  const std::string dir = fresh_dir("users-mode") + "/state/syncplc";
  auto users = open_users(dir + "/plc.db");
  ASSERT_TRUE(users);
  EXPECT_EQ(fs::status(dir).permissions() & fs::perms::all, fs::perms::owner_all);
  EXPECT_EQ(fs::status(dir + "/plc.db").permissions() & fs::perms::all,
            fs::perms::owner_read | fs::perms::owner_write);
}

TEST(Users, ATableFromANewerSyncplcIsRefused) {
  const std::string path = fresh_dir("users-newer") + "/plc.db";
  { ASSERT_TRUE(open_users(path)); }
  {
    SQLite::Database raw(path, SQLite::OPEN_READWRITE);
    raw.exec("UPDATE schema SET version = 9 WHERE part = 'users'");
  }
  std::string err;
  EXPECT_FALSE(UserStore::open(path, &err));
  EXPECT_THAT(err, HasSubstr("the database's users tables are version 9, newer than this syncplc knows (2)"));
}

TEST(Users, ThreadsVerifyAndChangeAtOnce) {
  auto users = open_users(fresh_dir("users-threads") + "/plc.db");
  ASSERT_TRUE(users);
  std::string err;
  ASSERT_TRUE(users->add("alice", kPassword, Role::Viewer, &err)) << err;
  std::atomic<int> verified{0};
  std::vector<std::thread> threads;
  for (int t = 0; t < 2; ++t)
    threads.emplace_back([&] {
      for (int i = 0; i < 2; ++i)
        if (users->verify("alice", kPassword)) ++verified;
    });
  threads.emplace_back([&] {
    for (int i = 0; i < 20; ++i) {
      std::string e;
      EXPECT_TRUE(users->set_role("alice", i % 2 ? Role::Operator : Role::Engineer, &e)) << e;
      EXPECT_FALSE(users->list().empty());
    }
  });
  for (auto& t : threads) t.join();
  EXPECT_EQ(verified.load(), 4);
}

}  // namespace
}  // namespace syncplc::web
