// Age limits against a wall clock that steps (docs/store.md, "Age limits
// and the wall clock"): the event log's events_max_age and the historian's
// trend_raw_age and trend_max_age. The wall clock the jobs read is stepped
// by the test (set_wall_clock); the monotonic clock is the `now` each run is
// given. A run started with the clock 200 days ahead, or a clock set back
// and forward again, deletes nothing before its time; time that really
// passes still ages rows out.
#include <SQLiteCpp/Statement.h>
#include <gtest/gtest.h>

#include "runtime/store/event_log.hpp"
#include "runtime/store/historian.hpp"
#include "runtime/store/trend_retention.hpp"
#include "tests/store/store_test_util.hpp"
#include "tests/support/project_fixture.hpp"

namespace syncplc::store {
// Named, not anonymous: unity builds put several test files in one
// translation unit (SYNCPLC_UNITY), where their helpers must not meet.
namespace retention_clock_test {

constexpr std::int64_t kSecond = 1'000'000'000;
constexpr std::int64_t kMinute = 60 * kSecond;
constexpr std::int64_t kHour = 60 * kMinute;
constexpr std::int64_t kDay = 24 * kHour;
constexpr std::int64_t kT0 = 1'764'000'000'000'000'000;  // 2025-11-24: "now" when the story starts

EventRecord record(std::int64_t wall_ns, std::string message) {
  return EventRecord{wall_ns, "info", "", std::nullopt, "run", std::move(message), ""};
}

std::unique_ptr<Database> open_db(const std::string& name) {
  std::string err;
  auto db = Database::open(testing::fresh_dir(name) + "/plc.db", nullptr, &err);
  EXPECT_TRUE(db) << err;
  return db;
}

std::string messages(Database& db) {
  SQLite::Statement q(db.sql(), "SELECT message FROM events ORDER BY id");
  std::string out;
  while (q.executeStep()) out += (out.empty() ? "" : ", ") + q.getColumn(0).getString();
  return out;
}

// One `syncplc run`'s event log job on `db`, reading the wall clock `wall`.
struct EventRun {
  EventRun(Database& db, const std::int64_t& wall) : log(queue, EventRetention{1000, 90 * kDay}) {
    log.set_wall_clock([&wall] { return wall; });
    std::string err;
    EXPECT_TRUE(log.prepare(db, &err)) << err;
  }
  EventQueue queue;
  EventLog log;
};

TEST(RetentionClock, ARunWithTheWallClock200DaysAheadDeletesNoEventAndTimeThatPassesStillAgesThemOut) {
  auto db = open_db("events_ahead");
  std::int64_t wall = kT0;
  {
    EventRun run(*db, wall);
    run.queue.push(record(kT0 - 80 * kDay, "80 days old"));
    run.queue.push(record(kT0 - 10 * kDay, "10 days old"));
    run.queue.push(record(kT0, "new"));
    run.log.run(*db, 1000 * kSecond, false);
  }
  ASSERT_EQ(messages(*db), "80 days old, 10 days old, new");

  // The next start: an hour later, with the clock 200 days ahead (an RTC
  // set wrong, a mistyped date). Its first write and retention pass...
  wall = kT0 + kHour + 200 * kDay;
  EventRun wrong(*db, wall);
  std::int64_t mono = 7 * kSecond;  // another process: its monotonic clock starts anew
  wrong.queue.push(record(wall, "start"));
  wrong.log.run(*db, mono, false);
  EXPECT_EQ(messages(*db), "80 days old, 10 days old, new, start") << "the audit trail is kept";
  // ...and a day of running like that.
  wall += kDay;
  mono += kDay;
  wrong.log.run(*db, mono, false);
  EXPECT_EQ(messages(*db), "80 days old, 10 days old, new, start");

  // Eleven more days pass: the 80-day-old event is now 92 days old by the
  // time that passed while the PLC ran, and goes.
  wall += 11 * kDay;
  mono += 11 * kDay;
  wrong.log.run(*db, mono, false);
  EXPECT_EQ(messages(*db), "10 days old, new, start");
}

TEST(RetentionClock, AWallClockSetBackAndForwardAgainDeletesNothingBeforeItsTime) {
  auto db = open_db("events_back");
  std::int64_t wall = kT0, mono = kSecond;
  EventRun run(*db, wall);
  run.queue.push(record(kT0 - 10 * kDay, "10 days old"));
  run.log.run(*db, mono, false);
  // The clock is set 200 days back: what is written meanwhile is stamped so.
  wall = kT0 - 200 * kDay + kMinute;
  mono += kMinute;
  run.queue.push(record(wall, "written while the clock was behind"));
  run.log.run(*db, mono, false);
  // Set right again a minute later: the event written a minute ago reads as
  // 200 days old, and stays.
  wall = kT0 + 2 * kMinute;
  mono += kMinute;
  run.log.run(*db, mono, false);
  EXPECT_EQ(messages(*db), "10 days old, written while the clock was behind");
  // 90 days of running later it is 90 days old, and goes. (The older event is
  // kept longer than its limit: the store's clock stays behind by the step;
  // kept longer, never deleted sooner.)
  wall += 90 * kDay;
  mono += 90 * kDay;
  run.log.run(*db, mono, false);
  EXPECT_EQ(messages(*db), "10 days old");
}

TEST(RetentionClock, TheTimeThePlcIsStoppedDoesNotCountAndTheClockGoesOnAcrossRuns) {
  auto db = open_db("events_downtime");
  std::int64_t wall = kT0;
  {
    EventRun run(*db, wall);
    run.queue.push(record(kT0 - 85 * kDay, "85 days old"));
    run.log.run(*db, kSecond, false);
    wall += 2 * kDay;  // two days of running
    run.log.run(*db, kSecond + 2 * kDay, false);
  }
  EXPECT_EQ(messages(*db), "85 days old") << "87 days";
  // Stopped for ten days: nothing can tell that from a clock set ahead.
  wall += 10 * kDay;
  EventRun next(*db, wall);
  next.log.run(*db, kSecond, false);
  EXPECT_EQ(messages(*db), "85 days old");
  // Three more days of running: 90 days of the PLC's time.
  wall += 3 * kDay + kMinute;
  next.log.run(*db, kSecond + 3 * kDay + kMinute, false);
  EXPECT_EQ(messages(*db), "");
}

constexpr const char* kTrended = R"(
tasks:
  - {name: fast, period: 1ms}
tags:
  - {name: s, type: LREAL, task: fast, trend: {rate: 1s}}
)";

// Raw points of the series of tag s, one a second from `from` for `n` seconds.
void insert_raw(Database& db, std::int64_t from, int n) {
  SQLite::Statement ins(db.sql(), "INSERT INTO trend_point SELECT id, 0, ?, 1000000000, 1, 2, 1.5, 1000 "
                                  "FROM trend_series WHERE label = 's'");
  db.sql().exec("BEGIN");
  for (int i = 0; i < n; ++i) {
    ins.reset();
    ins.bind(1, from + i * kSecond);
    ins.exec();
  }
  db.sql().exec("COMMIT");
}

std::int64_t points(Database& db, int level) {
  SQLite::Statement q(db.sql(), "SELECT count(*) FROM trend_point WHERE level = ?");
  q.bind(1, level);
  q.executeStep();
  return q.getColumn(0).getInt64();
}

TEST(RetentionClock, ARunWithTheWallClock200DaysAheadNeitherDownsamplesNorExpiresTrends) {
  auto r = load_test_result(kTrended);
  ASSERT_TRUE(r.ok());
  StoreSettings s = r.store;
  s.trend_raw_age_ns = kDay;
  s.trend_downsample_ns = kMinute;
  s.trend_max_age_ns = 90 * kDay;
  auto db = open_db("trends_ahead");
  std::int64_t wall = kT0;
  std::string err;
  {
    Historian h(*r.program, s);
    h.set_time_base(kT0);
    h.set_wall_clock([&wall] { return wall; });
    ASSERT_TRUE(h.prepare(*db, &err)) << err;
    insert_raw(*db, kT0 - 2 * kHour, 3600);  // an hour of points, two hours ago
    h.run(*db, kSecond, false);
  }
  ASSERT_EQ(points(*db, 0), 3600);

  // The next start, with the clock 200 days ahead.
  wall = kT0 + kHour + 200 * kDay;
  Historian h(*r.program, s);
  h.set_time_base(wall);
  h.set_wall_clock([&wall] { return wall; });
  ASSERT_TRUE(h.prepare(*db, &err)) << err;
  std::int64_t mono = kSecond;
  h.run(*db, mono, false);
  EXPECT_EQ(points(*db, 0), 3600) << "kept raw: not downsampled, not expired";
  EXPECT_EQ(points(*db, 1), 0);

  // A day of running: the points are a day old and are downsampled (60
  // one-minute buckets); 90 more days, and they expire.
  wall += kDay;
  mono += kDay;
  h.run(*db, mono, false);
  EXPECT_EQ(points(*db, 0), 0);
  EXPECT_EQ(points(*db, 1), 60);
  wall += 90 * kDay;
  mono += 90 * kDay;
  h.run(*db, mono, false);
  EXPECT_EQ(points(*db, 1), 0);
}

}  // namespace
}  // namespace syncplc::store
