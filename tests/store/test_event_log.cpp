// The event log job: records written with every field, the count and age
// limits, the queue's bound, and a database that refuses writes (disk full,
// read-only): nothing stored is damaged, records wait and are written once
// it takes writes again. Checked with the sqlite3 shell where it matters.
#include <SQLiteCpp/Statement.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <sqlite3.h>

#include <chrono>
#include <cstdio>
#include <string>
#include <thread>

#include "runtime/store/event_log.hpp"
#include "tests/store/store_test_util.hpp"

namespace syncplc::store {
namespace {

using ::testing::HasSubstr;
using syncplc::store::testing::sqlite_shell;

constexpr std::int64_t kSecond = 1'000'000'000;

EventRecord record(std::int64_t wall_ns, std::string message) {
  return EventRecord{wall_ns, "info", "main", 7, "run", std::move(message), ""};
}

std::unique_ptr<Database> open_db(const std::string& name) {
  std::string err;
  auto db = Database::open(testing::fresh_dir(name) + "/plc.db", nullptr, &err);
  EXPECT_TRUE(db) << err;
  return db;
}

std::int64_t count(Database& db) { return db.sql().execAndGet("SELECT count(*) FROM events").getInt64(); }


TEST(EventLog, WritesEveryFieldOfAQueuedRecordAndNullForWhatIsNotKnown) {
  auto db = open_db("fields");
  EventQueue q;
  EventLog log(q, EventRetention{});
  std::string err;
  ASSERT_TRUE(log.prepare(*db, &err)) << err;
  const std::int64_t now = wall_now_ns();
  q.push(EventRecord{now, "hmi-write", "main", std::nullopt, "modbus", "speed := 12.5", "127.0.0.1:40512"});
  q.push(EventRecord{now + 1, "overrun", "fast", 1234, "fast", "scan overran its period", ""});
  EXPECT_EQ(log.due_ns(), 0) << "queued records are due now";
  log.run(*db, 0, false);
  EXPECT_EQ(q.pending(), 0u);
  EXPECT_EQ(sqlite_shell(db->path(), "SELECT kind, task, ifnull(scan, 'NULL'), source, message, ifnull(client, 'NULL') "
                              "FROM events ORDER BY id"),
            "hmi-write|main|NULL|modbus|speed := 12.5|127.0.0.1:40512\n"
            "overrun|fast|1234|fast|scan overran its period|NULL");
  EXPECT_EQ(sqlite_shell(db->path(), "SELECT time_ns FROM events ORDER BY id LIMIT 1"), std::to_string(now));
}

TEST(EventLog, KeepsTheNewestMaxCountEvents) {
  auto db = open_db("count");
  EventQueue q;
  EventLog log(q, EventRetention{5, 3600 * kSecond});
  std::string err;
  ASSERT_TRUE(log.prepare(*db, &err)) << err;
  const std::int64_t now = wall_now_ns();
  for (int i = 0; i < 12; ++i) q.push(record(now + i, "e" + std::to_string(i)));
  log.run(*db, 0, false);
  EXPECT_EQ(count(*db), 5);
  EXPECT_EQ(sqlite_shell(db->path(), "SELECT group_concat(message, ',') FROM (SELECT message FROM events ORDER BY id)"),
            "e7,e8,e9,e10,e11");
}

TEST(EventLog, DropsEventsOlderThanMaxAgeAndChecksTheAgeAgainLater) {
  auto db = open_db("age");
  EventQueue q;
  EventLog log(q, EventRetention{1000, 3600 * kSecond});
  std::string err;
  ASSERT_TRUE(log.prepare(*db, &err)) << err;
  const std::int64_t now = wall_now_ns();
  q.push(record(now - 2 * 3600 * kSecond, "two hours ago"));
  q.push(record(now - 60 * kSecond, "a minute ago"));
  log.run(*db, 0, false);
  EXPECT_EQ(sqlite_shell(db->path(), "SELECT message FROM events"), "a minute ago");
  // Nothing queued: the job is due again only for the age limit, not before a minute.
  EXPECT_GE(log.due_ns(), 60 * kSecond);
}

TEST(EventQueue, IsBoundedAndCountsWhatItDrops) {
  EventQueue q(3);
  int woken = 0;
  q.on_push([&] { ++woken; });
  for (int i = 0; i < 5; ++i) q.push(record(i, "e"));
  EXPECT_EQ(q.pending(), 3u);
  EXPECT_EQ(q.dropped(), 2u);
  EXPECT_EQ(woken, 3) << "the store thread is woken for each accepted record only";
  // Records taken by the job still count until they are committed.
  std::vector<EventRecord> taken;
  q.take(taken);
  EXPECT_EQ(taken.size(), 3u);
  EXPECT_FALSE(q.push(record(9, "still full")));
  q.settle(3);
  EXPECT_TRUE(q.push(record(10, "room again")));
}

// Fills the database to its page limit: the next transaction fails with SQLITE_FULL.
void fill_to_the_limit(Database& db) {
  const std::int64_t pages = db.sql().execAndGet("PRAGMA page_count").getInt64();
  db.sql().exec("PRAGMA max_page_count = " + std::to_string(pages));
}

TEST(EventLog, DiskFullKeepsRecordsQueuedDamagesNothingAndWritesThemOnceThereIsRoom) {
  auto db = open_db("full");
  EventQueue q(100);
  EventLog log(q, EventRetention{});
  std::string err;
  ASSERT_TRUE(log.prepare(*db, &err)) << err;
  const std::int64_t now = wall_now_ns();
  q.push(record(now, "before the disk filled"));
  log.run(*db, 0, false);
  fill_to_the_limit(*db);
  const std::string big(8000, 'x');  // more than the free room of a page
  for (int i = 0; i < 10; ++i) q.push(record(now + 1 + i, big));
  try {
    log.run(*db, 0, false);
    FAIL() << "the insert should not fit";
  } catch (const SQLite::Exception& e) {
    EXPECT_EQ(e.getErrorCode(), SQLITE_FULL) << e.what();
  }
  EXPECT_EQ(q.pending(), 10u) << "kept for the next try";
  EXPECT_EQ(log.due_ns(), 0);
  EXPECT_EQ(sqlite_shell(db->path(), "PRAGMA integrity_check"), "ok");
  EXPECT_EQ(sqlite_shell(db->path(), "SELECT count(*) || ' ' || max(message) FROM events"), "1 before the disk filled");
  // Space returns: the waiting records are written once, in order.
  db->sql().exec("PRAGMA max_page_count = 1073741823");
  log.run(*db, 0, false);
  EXPECT_EQ(q.pending(), 0u);
  EXPECT_EQ(sqlite_shell(db->path(), "SELECT count(*), count(DISTINCT time_ns) FROM events"), "11|11");
  EXPECT_EQ(sqlite_shell(db->path(), "PRAGMA integrity_check"), "ok");
}

TEST(EventLog, AReadOnlyDatabaseRefusesWithSqliteReadonlyAndTheRecordsWait) {
  auto db = open_db("readonly");
  EventQueue q(100);
  EventLog log(q, EventRetention{});
  std::string err;
  ASSERT_TRUE(log.prepare(*db, &err)) << err;
  q.push(record(wall_now_ns(), "first"));
  log.run(*db, 0, false);
  // The connection refuses every write, as on a file system remounted
  // read-only: SQLite answers SQLITE_READONLY and writes nothing.
  db->sql().exec("PRAGMA query_only = 1");
  q.push(record(wall_now_ns(), "second"));
  try {
    log.run(*db, 0, false);
    FAIL() << "a read-only database took a write";
  } catch (const SQLite::Exception& e) {
    EXPECT_EQ(e.getErrorCode(), SQLITE_READONLY) << e.what();
  }
  EXPECT_EQ(q.pending(), 1u);
  EXPECT_EQ(sqlite_shell(db->path(), "SELECT group_concat(message) FROM events"), "first");
  db->sql().exec("PRAGMA query_only = 0");
  log.run(*db, 0, false);
  EXPECT_EQ(sqlite_shell(db->path(), "SELECT group_concat(message) FROM (SELECT message FROM events ORDER BY id)"),
            "first,second");
}

template <class F>
bool eventually(F&& f, int ms = 60000) {  // a guard against a hang only
  for (int i = 0; i < ms / 5; ++i) {
    if (f()) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  return f();
}

TEST(EventLog, OnTheStoreThreadAFullDiskIsAVisibleFaultThatClearsWhenRoomReturns) {
  std::string err;
  const std::string path = testing::fresh_dir("thread") + "/plc.db";
  auto opened = Database::open(path, nullptr, &err);
  ASSERT_TRUE(opened) << err;
  StoreThread st(std::move(opened));
  EventQueue q(100);
  q.on_push([&st] { st.wake(); });
  ASSERT_TRUE(st.add(std::make_unique<EventLog>(q, EventRetention{}), &err)) << err;
  st.exclusive([&] { fill_to_the_limit(st.database()); });
  st.start();
  q.push(record(wall_now_ns(), std::string(8000, 'y')));
  ASSERT_TRUE(eventually([&] { return st.health().fault; }));
  EXPECT_THAT(st.health().last_error, HasSubstr("events: database or disk is full"));
  EXPECT_EQ(q.pending(), 1u);
  st.exclusive([&] { st.database().sql().exec("PRAGMA max_page_count = 1073741823"); });
  // Retried by the thread (a second after the failure): written, the fault cleared.
  EXPECT_TRUE(eventually([&] { return !st.health().fault && q.pending() == 0; }));
  st.stop();
  EXPECT_EQ(sqlite_shell(path, "SELECT count(*) FROM events"), "1");
  EXPECT_EQ(sqlite_shell(path, "PRAGMA integrity_check"), "ok");
}

}  // namespace
}  // namespace syncplc::store
