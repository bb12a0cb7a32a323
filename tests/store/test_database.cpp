// The database file: creation, the instance lock, bad files moved aside, the
// parts' schema versions (runtime/store/database.hpp, schema.hpp).
#include <SQLiteCpp/Statement.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <iterator>

#include "runtime/store/database.hpp"
#include "runtime/store/schema.hpp"
#include "tests/store/store_test_util.hpp"

namespace syncplc::store {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;

using testing::read_all;

TEST(Database, CreatesTheFileAndItsDirectoryInWalModeWithFullSync) {
  const std::string path = testing::fresh_dir("create") + "/state/syncplc/plc.db";
  OpenReport report;
  std::string err;
  auto db = Database::open(path, &report, &err);
  ASSERT_TRUE(db) << err;
  EXPECT_TRUE(report.created);
  EXPECT_TRUE(report.moved_aside.empty());
  EXPECT_TRUE(fs::exists(path));
  EXPECT_EQ((fs::status(fs::path(path).parent_path()).permissions() & fs::perms::all), fs::perms::owner_all);
  EXPECT_EQ(db->sql().execAndGet("PRAGMA journal_mode").getString(), "wal");
  EXPECT_EQ(db->sql().execAndGet("PRAGMA synchronous").getInt(), 2) << "FULL";
}

TEST(Database, ASecondWriterIsRefusedWithTheHoldersPid) {
  const std::string path = testing::fresh_dir("lock") + "/plc.db";
  std::string err;
  auto first = Database::open(path, nullptr, &err);
  ASSERT_TRUE(first) << err;
  // Another process (flock is per open file description: a fork that opens
  // the file again is a second instance).
  const std::string got = testing::open_in_another_process(path);
  EXPECT_THAT(got, HasSubstr("locked: the database " + path + " is in use by another syncplc instance (pid " +
                             std::to_string(getpid()) + ")"));
  // Once the first is gone, the database opens again.
  first.reset();
  auto again = Database::open(path, nullptr, &err);
  EXPECT_TRUE(again) << err;
}

TEST(Database, AFileThatIsNotADatabaseIsMovedAsideUntouched) {
  const std::string dir = testing::fresh_dir("garbage");
  const std::string path = dir + "/plc.db";
  const std::string junk(10000, 'x');
  std::ofstream(path, std::ios::binary) << junk;
  OpenReport report;
  std::string err;
  auto db = Database::open(path, &report, &err);
  ASSERT_TRUE(db) << err;
  EXPECT_TRUE(report.created);
  ASSERT_FALSE(report.moved_aside.empty());
  EXPECT_THAT(report.moved_aside, HasSubstr(path + ".corrupt-"));
  EXPECT_THAT(report.problem, HasSubstr("not a database"));
  EXPECT_EQ(read_all(report.moved_aside), junk) << "the bad file is kept whole";
  EXPECT_EQ(db->sql().execAndGet("PRAGMA quick_check").getString(), "ok");
}

TEST(Database, ADamagedDatabaseIsMovedAsideWithItsWal) {
  const std::string dir = testing::fresh_dir("damaged");
  const std::string path = dir + "/plc.db";
  {
    std::string err;
    auto db = Database::open(path, nullptr, &err);
    ASSERT_TRUE(db) << err;
    db->sql().exec("CREATE TABLE t (k INTEGER PRIMARY KEY, v TEXT); CREATE INDEX t_v ON t (v)");
    SQLite::Statement ins(db->sql(), "INSERT INTO t (v) VALUES (?)");
    db->sql().exec("BEGIN");  // one sync, not 2000
    for (int i = 0; i < 2000; ++i) {
      ins.bind(1, "value " + std::to_string(i * 7919));
      ins.exec();
      ins.reset();
    }
    db->sql().exec("COMMIT");
    db->sql().exec("PRAGMA wal_checkpoint(TRUNCATE)");
  }
  // Scribble over the middle pages (the header stays a database's).
  {
    std::fstream f(path, std::ios::in | std::ios::out | std::ios::binary);
    f.seekp(4096 * 3 + 100);
    const std::string noise(4096 * 4, '\x5a');
    f.write(noise.data(), static_cast<std::streamsize>(noise.size()));
  }
  const std::string damaged = read_all(path);
  OpenReport report;
  std::string err;
  auto db = Database::open(path, &report, &err);
  ASSERT_TRUE(db) << err;
  ASSERT_FALSE(report.moved_aside.empty()) << "quick_check finds the damage";
  EXPECT_FALSE(report.problem.empty());
  EXPECT_EQ(read_all(report.moved_aside), damaged);
  EXPECT_FALSE(db->sql().tableExists("t")) << "a new, empty database";
}

TEST(Database, ReadersOpenWithoutTheLockBesideTheWriter) {
  const std::string path = testing::fresh_dir("reader") + "/plc.db";
  std::string err;
  auto writer = Database::open(path, nullptr, &err);
  ASSERT_TRUE(writer) << err;
  writer->sql().exec("CREATE TABLE t (v INTEGER); INSERT INTO t VALUES (42)");
  auto reader = Database::open_read_only(path, &err);
  ASSERT_TRUE(reader) << err;
  EXPECT_EQ(reader->sql().execAndGet("SELECT v FROM t").getInt(), 42);
  EXPECT_FALSE(Database::open_read_only(path + ".nothing", &err));
  EXPECT_THAT(err, HasSubstr("no database at"));
}

TEST(Database, MemoryDatabasesTakeNoLock) {
  std::string err;
  auto a = Database::open(kMemoryDatabase, nullptr, &err);
  auto b = Database::open(kMemoryDatabase, nullptr, &err);
  EXPECT_TRUE(a && b) << err;
}

TEST(Schema, MigrationsRunOnceInOrderAndANewerVersionIsRefused) {
  std::string err;
  auto db = Database::open(kMemoryDatabase, nullptr, &err);
  ASSERT_TRUE(db);
  SchemaPart part{"things", {"CREATE TABLE things (a INTEGER)", "ALTER TABLE things ADD COLUMN b TEXT"}};
  ASSERT_TRUE(ensure_schema(db->sql(), part, &err)) << err;
  EXPECT_EQ(schema_version(db->sql(), "things"), 2);
  ASSERT_TRUE(ensure_schema(db->sql(), part, &err)) << "again: nothing to do";
  db->sql().exec("INSERT INTO things (a, b) VALUES (1, 'x')");
  part.migrations.push_back("ALTER TABLE things ADD COLUMN c REAL");
  ASSERT_TRUE(ensure_schema(db->sql(), part, &err));
  EXPECT_EQ(schema_version(db->sql(), "things"), 3);
  EXPECT_EQ(db->sql().execAndGet("SELECT b FROM things").getString(), "x") << "data kept across a migration";
  SchemaPart older{"things", {"CREATE TABLE things (a INTEGER)"}};
  EXPECT_FALSE(ensure_schema(db->sql(), older, &err));
  EXPECT_EQ(err, "the database's things tables are version 3, newer than this syncplc knows (1)");
  EXPECT_EQ(schema_version(db->sql(), "other"), 0);
}

TEST(Schema, AFailedMigrationLeavesTheVersionAndTheDataAlone) {
  std::string err;
  auto db = Database::open(kMemoryDatabase, nullptr, &err);
  ASSERT_TRUE(db);
  SchemaPart part{"p", {"CREATE TABLE p (a INTEGER); INSERT INTO p VALUES (7)"}};
  ASSERT_TRUE(ensure_schema(db->sql(), part, &err));
  part.migrations.push_back("ALTER TABLE p ADD COLUMN b; INSERT INTO nosuch VALUES (1)");
  EXPECT_THROW(ensure_schema(db->sql(), part, &err), SQLite::Exception);
  EXPECT_EQ(schema_version(db->sql(), "p"), 1);
  EXPECT_EQ(db->sql().execAndGet("SELECT count(*) FROM pragma_table_info('p')").getInt(), 1) << "rolled back whole";
}

}  // namespace
}  // namespace syncplc::store
