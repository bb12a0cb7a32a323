// The database's files against other processes (docs/store.md, "One
// writer", "Bad files"): a lock held by another connection is SQLite's BUSY,
// never damage; a damaged database is moved aside with its -wal and -shm
// byte for byte; the instance lock holds whatever path names the file.
// The other process is Debian's sqlite3 shell where it can be.
#include <SQLiteCpp/Statement.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <thread>

#include "runtime/store/database.hpp"
#include "tests/store/store_test_util.hpp"

namespace syncplc::store {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;
using testing::open_in_another_process;
using testing::read_all;
using testing::ShellHolding;
using testing::sqlite_shell;
using testing::sqlite_shell_script;

// The names in `dir` of files moved aside.
std::vector<std::string> moved_aside(const std::string& dir) {
  std::vector<std::string> v;
  for (const auto& e : fs::directory_iterator(dir))
    if (e.path().filename().string().find(".corrupt-") != std::string::npos) v.push_back(e.path().filename().string());
  return v;
}

// A database the store wrote, with a row to find again.
void make_database(const std::string& path) {
  std::string err;
  auto db = Database::open(path, nullptr, &err);
  ASSERT_TRUE(db) << err;
  db->sql().exec("CREATE TABLE history (v TEXT); INSERT INTO history VALUES ('the plant''s history')");
}


// The sqlite3 shell's way to keep every other connection out of a WAL
// database: exclusive locking mode, then a write transaction.
constexpr const char* kHoldExclusive = "PRAGMA locking_mode=EXCLUSIVE; BEGIN EXCLUSIVE;";

TEST(DatabaseFiles, ALockHeldByAnotherConnectionIsBusyNotDamageAndNothingIsMoved) {
  const std::string dir = testing::fresh_dir("busy");
  const std::string path = dir + "/plc.db";
  make_database(path);
  const std::string bytes = read_all(path);
  ShellHolding shell(path, kHoldExclusive);
  ASSERT_TRUE(shell.holding()) << shell.said();

  OpenReport report;
  std::string err;
  auto db = Database::open(path, &report, &err, OpenOptions{200});
  EXPECT_FALSE(db) << "a database another connection holds is not opened as new";
  EXPECT_TRUE(report.busy);
  EXPECT_FALSE(report.locked) << "not the instance lock: SQLite's";
  EXPECT_TRUE(report.moved_aside.empty()) << report.moved_aside;
  EXPECT_THAT(err, HasSubstr("is locked by another connection"));
  EXPECT_THAT(err, HasSubstr("SQLITE_BUSY"));
  EXPECT_TRUE(moved_aside(dir).empty()) << "nothing moved";
  EXPECT_TRUE(read_all(path) == bytes) << "the file untouched";

  shell.release();
  EXPECT_EQ(sqlite_shell(path, "SELECT v FROM history"), "the plant's history");
}

TEST(DatabaseFiles, OpeningWaitsForABusyDatabaseUntilTheLockGoes) {
  const std::string dir = testing::fresh_dir("busy_wait");
  const std::string path = dir + "/plc.db";
  make_database(path);
  ShellHolding shell(path, kHoldExclusive);
  ASSERT_TRUE(shell.holding()) << shell.said();
  // The other connection lets go while the open waits (its busy timeout
  // is far longer than this).
  std::thread let_go([&] {
    std::this_thread::sleep_for(std::chrono::milliseconds(300));
    shell.release();
  });
  OpenReport report;
  std::string err;
  auto db = Database::open(path, &report, &err, OpenOptions{30'000});
  let_go.join();
  ASSERT_TRUE(db) << err;
  EXPECT_FALSE(report.created);
  EXPECT_TRUE(report.moved_aside.empty());
  EXPECT_EQ(db->sql().execAndGet("SELECT v FROM history").getString(), "the plant's history");
}

// A damaged database whose last transaction is only in its WAL (the shell
// closes without the checkpoint), as after a crash: the three files.
void make_damaged_database_with_wal(const std::string& path) {
  sqlite_shell_script(path,
                      "PRAGMA journal_mode=WAL;\n"
                      "CREATE TABLE t (k INTEGER PRIMARY KEY, v TEXT); CREATE INDEX t_v ON t (v);\n"
                      "WITH RECURSIVE c(i) AS (SELECT 1 UNION ALL SELECT i + 1 FROM c WHERE i < 3000)"
                      " INSERT INTO t (v) SELECT 'value ' || (i * 7919) FROM c;\n"
                      "PRAGMA wal_checkpoint(TRUNCATE);\n");
  sqlite_shell_script(path, ".dbconfig no_ckpt_on_close on\nINSERT INTO t (v) VALUES ('only in the wal');\n");
  std::fstream f(path, std::ios::in | std::ios::out | std::ios::binary);
  f.seekp(4096 * 3 + 100);
  const std::string noise(4096 * 4, '\x5a');
  f.write(noise.data(), static_cast<std::streamsize>(noise.size()));
}

TEST(DatabaseFiles, ADamagedDatabaseIsMovedAsideWithItsWalAndShmByteForByteWithoutACheckpoint) {
  const std::string dir = testing::fresh_dir("damaged_wal");
  const std::string path = dir + "/plc.db";
  make_damaged_database_with_wal(path);
  ASSERT_GT(fs::file_size(path + "-wal"), 0u) << "the shell left its last transaction in the WAL";
  ASSERT_TRUE(fs::exists(path + "-shm"));
  const std::string db_bytes = read_all(path), wal_bytes = read_all(path + "-wal"), shm_bytes = read_all(path + "-shm");

  OpenReport report;
  std::string err;
  auto db = Database::open(path, &report, &err);
  ASSERT_TRUE(db) << err;
  ASSERT_FALSE(report.moved_aside.empty()) << "quick_check finds the damage";
  EXPECT_THAT(report.problem, HasSubstr("quick_check"));
  const std::string& aside = report.moved_aside;
  EXPECT_TRUE(read_all(aside) == db_bytes) << "the database as it was: the WAL was not checkpointed into it";
  ASSERT_TRUE(fs::exists(aside + "-wal")) << "its WAL went with it";
  EXPECT_TRUE(read_all(aside + "-wal") == wal_bytes) << "the WAL byte for byte";
  ASSERT_TRUE(fs::exists(aside + "-shm"));
  EXPECT_TRUE(read_all(aside + "-shm") == shm_bytes) << "the WAL index byte for byte";
  // The new database is a new one, with no file of the old one beside it.
  EXPECT_FALSE(db->sql().tableExists("t"));
  EXPECT_EQ(db->sql().execAndGet("PRAGMA quick_check").getString(), "ok");
  db.reset();
  EXPECT_EQ(sqlite_shell(path, "SELECT count(*) FROM sqlite_master WHERE name = 't'"), "0");
}

TEST(DatabaseFiles, TheInstanceLockHoldsThroughASymlinkEitherWay) {
  const std::string dir = testing::fresh_dir("symlink");
  const std::string real = dir + "/real/plc.db", link = dir + "/plc-link.db";
  fs::create_directories(dir + "/real");
  make_database(real);
  fs::create_symlink(real, link);
  std::string err;
  {
    auto first = Database::open(real, nullptr, &err);
    ASSERT_TRUE(first) << err;
    EXPECT_THAT(open_in_another_process(link), HasSubstr("locked: the database " + link + " is in use by another syncplc instance"));
  }
  {
    auto first = Database::open(link, nullptr, &err);
    ASSERT_TRUE(first) << err;
    EXPECT_THAT(open_in_another_process(real), HasSubstr("locked: the database " + real + " is in use by another syncplc instance"));
    // A symlink to the directory is another name of the same file too.
    fs::create_directory_symlink(dir + "/real", dir + "/dirlink");
    EXPECT_THAT(open_in_another_process(dir + "/dirlink/plc.db"), HasSubstr("locked: "));
  }
  EXPECT_FALSE(fs::exists(link + ".lock")) << "one lock file, beside the real one";
  EXPECT_EQ(open_in_another_process(link), "opened");
}

}  // namespace
}  // namespace syncplc::store
