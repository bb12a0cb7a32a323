// The historian in virtual time: the task folds every scan into its bucket
// (a one-scan spike is in the stored max), the deadband, downsampling and
// retention by age and size, checked on the tables the HMI will read.
#include <gtest/gtest.h>

#include <SQLiteCpp/Statement.h>

#include "runtime/core/program_change.hpp"
#include "runtime/core/virtual_clock.hpp"
#include "runtime/store/historian.hpp"
#include "runtime/store/trend_retention.hpp"
#include "tests/support/project_fixture.hpp"

namespace syncplc::store {
namespace {

constexpr std::int64_t kMs = 1'000'000;
constexpr std::int64_t kT0 = 1'764'000'000'000'000'000;  // the wall time of logical 0 in these tests

const char* const kProject = R"(
tasks:
  - {name: fast, period: 1ms}
tags:
  - {name: x, type: LREAL, task: fast, trend: {rate: 100ms}}
  - {name: y, type: LREAL, task: fast, trend: {rate: 10ms, deadband: 0.5}}
  - {name: a, type: "ARRAY[1..2] OF INT", task: fast, trend: true}
)";

std::unique_ptr<Database> memory() {
  std::string err;
  auto db = Database::open(kMemoryDatabase, nullptr, &err);
  EXPECT_TRUE(db) << err;
  return db;
}

struct Point {
  std::int64_t t;
  double min, max, mean;
  std::int64_t count;
};

std::vector<Point> points(Database& db, const std::string& label, int level = 0) {
  SQLite::Statement q(db.sql(), "SELECT p.t, p.min, p.max, p.mean, p.count FROM trend_point p JOIN trend_series s "
                                "ON s.id = p.series WHERE s.label = ? AND p.level = ? ORDER BY p.t");
  q.bind(1, label);
  q.bind(2, level);
  std::vector<Point> out;
  while (q.executeStep())
    out.push_back({q.getColumn(0).getInt64(), q.getColumn(1).getDouble(), q.getColumn(2).getDouble(),
                   q.getColumn(3).getDouble(), q.getColumn(4).getInt64()});
  return out;
}

// Runs the project in virtual time until `end`, setting the tags from `set`
// before each scan (called with the scan's release time).
template <class F>
void run(Program& p, std::int64_t end, F&& set) {
  VirtualClock vc(p);
  set(std::int64_t{0});
  vc.on_time_point([&](std::int64_t t) { set(t + kMs); });
  vc.run_until(end);
}

TEST(Historian, AOneScanSpikeOfA1msTaskSampledAt100msIsInTheStoredMax) {
  auto r = load_test_result(kProject);
  ASSERT_TRUE(r.ok());
  Program& p = *r.program;
  Cell& x = tag_cell(p, "x");
  run(p, 350 * kMs, [&](std::int64_t t) { x.set<double>(t == 150 * kMs ? 100.0 : 1.0); });

  auto db = memory();
  Historian h(p, r.store);
  h.set_time_base(kT0);
  std::string err;
  ASSERT_TRUE(h.prepare(*db, &err)) << err;
  h.run(*db, 0, true);
  auto pts = points(*db, "x");
  ASSERT_EQ(pts.size(), 3u);  // the bucket from 300 ms on is still running
  for (int i = 0; i < 3; ++i) {
    EXPECT_EQ(pts[i].t, kT0 + i * 100 * kMs);
    EXPECT_EQ(pts[i].count, 100);
    EXPECT_EQ(pts[i].min, 1.0);
  }
  EXPECT_EQ(pts[0].max, 1.0);
  EXPECT_EQ(pts[1].max, 100.0);  // the one scan at 150 ms
  EXPECT_DOUBLE_EQ(pts[1].mean, (99 * 1.0 + 100.0) / 100);
  EXPECT_EQ(pts[2].max, 1.0);
  EXPECT_EQ(h.lost(), 0u);

  // An array's elements are series of their own, at the task's period (trend: true).
  auto a1 = points(*db, "a[1]"), a2 = points(*db, "a[2]");
  EXPECT_EQ(a1.size(), 349u);
  EXPECT_EQ(a2.size(), 349u);
  EXPECT_EQ(a1.front().count, 1);
}

TEST(Historian, TheDeadbandStoresABucketOnlyWhenSomeScanMovedMoreThanItFromTheLastStoredMean) {
  auto r = load_test_result(kProject);
  ASSERT_TRUE(r.ok());
  Program& p = *r.program;
  Cell& y = tag_cell(p, "y");
  // y (10 ms buckets, deadband 0.5): 0 until 30 ms, drifts to 0.4 (inside the
  // band), one scan at 0.6 at 55 ms (outside), 0.2 from 70 ms, 2 from 90 ms.
  run(p, 120 * kMs, [&](std::int64_t t) {
    double v = t < 30 * kMs ? 0.0 : 0.4;
    if (t == 55 * kMs) v = 0.6;
    if (t >= 70 * kMs) v = 0.2;
    if (t >= 90 * kMs) v = 2.0;
    y.set<double>(v);
  });
  auto db = memory();
  Historian h(p, r.store);
  h.set_time_base(kT0);
  std::string err;
  ASSERT_TRUE(h.prepare(*db, &err)) << err;
  h.run(*db, 0, true);
  auto pts = points(*db, "y");
  // Stored: the first bucket; 50 ms (its max 0.6 is 0.6 from the stored 0);
  // 90 ms (2 is 1.6 from the stored mean 0.42). Not stored: 10-40 ms and
  // 60-80 ms (every scan within 0.5 of the last stored mean), 100 ms (2 = 2).
  ASSERT_EQ(pts.size(), 3u);
  EXPECT_EQ(pts[0].t, kT0);
  EXPECT_EQ(pts[1].t, kT0 + 50 * kMs);
  EXPECT_EQ(pts[1].max, 0.6);
  EXPECT_EQ(pts[1].min, 0.4);
  EXPECT_DOUBLE_EQ(pts[1].mean, (9 * 0.4 + 0.6) / 10);
  EXPECT_EQ(pts[2].t, kT0 + 90 * kMs);
  EXPECT_EQ(pts[2].mean, 2.0);
}

std::vector<std::int64_t> starts(Database& db, const std::string& label) {
  std::vector<std::int64_t> out;
  for (const auto& pt : points(db, label)) out.push_back((pt.t - kT0) / kMs);
  return out;
}

// An online change loses no scan: the historian drains the old program until
// its tasks ended, then takes their buckets in progress; the bucket the
// switch cuts holds the old task's scans and the new task's, merged. A clean
// stop stores the buckets in progress too.
TEST(Historian, AnOnlineChangeAndACleanStopLoseNoScan) {
  const std::string a = "tasks: [{name: fast, period: 1ms}]\n"
                        "tags: [{name: x, type: LREAL, task: fast, trend: {rate: 10ms}}]\n"
                        "blocks: [{name: m, type: MOVE, datatype: LREAL, inputs: {IN: 1.0}}]\n"
                        "connections: [m.OUT -> x]\n"
                        "store: {trend_raw_age: 36500d, trend_max_age: 36500d}\n";  // kT0 is in 2025: keep it raw
  const std::string b = "tasks: [{name: fast, period: 1ms}]\n"
                        "tags: [{name: x, type: LREAL, task: fast, trend: {rate: 10ms}},\n"
                        "       {name: z, type: INT, task: fast, trend: {rate: 20ms}}]\n"
                        "blocks: [{name: m, type: MOVE, datatype: LREAL, inputs: {IN: 3.0}}]\n"
                        "connections: [m.OUT -> x]\n"
                        "store: {trend_raw_age: 36500d, trend_max_age: 36500d}\n";
  auto ra = load_test_result(a);
  ASSERT_TRUE(ra.ok());
  auto db = memory();
  Historian h(*ra.program, ra.store);
  h.set_time_base(kT0);
  std::string err;
  ASSERT_TRUE(h.prepare(*db, &err)) << err;
  VirtualClock clock(*ra.program);
  clock.run_until(42 * kMs);
  auto rb = load_test_result(b);
  ASSERT_TRUE(rb.ok());
  auto change = plan_change(*ra.program, *rb.program);
  change->switch_ns = 45 * kMs;
  clock.begin_change(*change);
  h.switch_program(*rb.program, rb.store);  // as the reloader does: when the change is accepted
  h.run(*db, 0, false);                     // a commit while the old task still runs (42..44 ms)
  clock.run_until(100 * kMs);
  ASSERT_TRUE(clock.change_complete());
  h.tasks_ended(*ra.program);  // as the reloader does once every task switched
  h.run(*db, 2'000'000'000, false);
  EXPECT_EQ(starts(*db, "x"), (std::vector<std::int64_t>{0, 10, 20, 30, 40, 50, 60, 70, 80}));
  const auto x = points(*db, "x");
  EXPECT_EQ(x[3].count, 10);
  EXPECT_EQ(x[3].max, 1.0);
  EXPECT_EQ(x[4].count, 10) << "40..44 ms from the old task, 45..49 ms from the new";
  EXPECT_EQ(x[4].min, 1.0);
  EXPECT_EQ(x[4].max, 3.0);
  EXPECT_DOUBLE_EQ(x[4].mean, 2.0);
  EXPECT_EQ(x[5].min, 3.0);
  // A clean stop: the buckets in progress (x at 90 ms, z at 80 ms) are stored as they are.
  h.tasks_ended(*rb.program);
  h.run(*db, 3'000'000'000, true);
  EXPECT_EQ(starts(*db, "x").back(), 90);
  EXPECT_EQ(points(*db, "x").back().count, 10);
  // z is new from the switch on: 45..59 ms, 60..79 ms, 80..99 ms.
  EXPECT_EQ(starts(*db, "z"), (std::vector<std::int64_t>{40, 60, 80}));
  EXPECT_EQ(points(*db, "z").front().count, 15);
  std::int64_t scans = 0;
  for (const auto& pt : points(*db, "x")) scans += pt.count;
  EXPECT_EQ(scans, 100) << "every scan of 0..99 ms, old and new";
  EXPECT_EQ(h.lost(), 0u);
  EXPECT_EQ(db->sql().execAndGet("SELECT count(*) FROM trend_series").getInt(), 2);
}

// A series whose rate an online change changes: every bucket keeps the rate
// it was folded with. The old program's buckets (100 ms) are stamped on the
// 100 ms grid, the new one's on the 10 ms grid from the switch on; none is
// stamped in the future or on the other's grid (issue 21).
TEST(Historian, ARateChangedByAnOnlineChangeStampsEachBucketWithItsOwnRate) {
  const auto project = [](const char* rate, double in) {
    return std::string("tasks: [{name: fast, period: 1ms}]\n") + "tags: [{name: x, type: LREAL, task: fast, trend: {rate: " +
           rate + "}}]\n" + "blocks: [{name: m, type: MOVE, datatype: LREAL, inputs: {IN: " + std::to_string(in) +
           "}}]\n" + "connections: [m.OUT -> x]\n" + "store: {trend_raw_age: 36500d, trend_max_age: 36500d}\n";
  };
  auto ra = load_test_result(project("100ms", 1.0));
  ASSERT_TRUE(ra.ok());
  auto db = memory();
  Historian h(*ra.program, ra.store);
  h.set_time_base(kT0);
  std::string err;
  ASSERT_TRUE(h.prepare(*db, &err)) << err;
  VirtualClock clock(*ra.program);
  clock.run_until(242 * kMs);
  h.run(*db, 0, false);  // the old buckets 0 and 100 ms are queued (and stored) before the change
  auto rb = load_test_result(project("10ms", 3.0));
  ASSERT_TRUE(rb.ok());
  auto change = plan_change(*ra.program, *rb.program);
  change->switch_ns = 250 * kMs;
  clock.begin_change(*change);
  h.switch_program(*rb.program, rb.store);
  clock.run_until(400 * kMs);
  ASSERT_TRUE(clock.change_complete());
  h.tasks_ended(*ra.program);
  h.run(*db, 2'000'000'000, false);
  const auto pts = points(*db, "x");
  ASSERT_FALSE(pts.empty());
  std::int64_t scans = 0;
  for (const auto& pt : pts) {
    const std::int64_t at = (pt.t - kT0) / kMs;
    EXPECT_LT(at, 400) << "a bucket stamped after the last scan";
    if (pt.max == 1.0) {
      EXPECT_EQ(at % 100, 0) << "an old bucket off the 100 ms grid, at " << at << " ms";
    }
    if (pt.min == 3.0) {
      EXPECT_GE(at, 250) << "a new bucket before the switch, at " << at << " ms";
    }
    scans += pt.count;
  }
  // 0..249 ms in three old buckets (the last cut by the switch), 250..389 ms in new ones.
  EXPECT_EQ(starts(*db, "x").front(), 0);
  EXPECT_EQ(scans, 390);
  EXPECT_EQ(db->sql().execAndGet("SELECT count(*) FROM trend_point WHERE span = 100000000").getInt(), 3);
}

// The series of a label whose variable an online change replaced (another
// type: another tag identity, as online change and retain see it) starts its
// deadband afresh: its first bucket is stored even within the old band.
TEST(Historian, AnotherVariableUnderTheSameLabelStartsItsDeadbandAfresh) {
  const auto project = [](const char* type, const char* in) {
    return std::string("tasks: [{name: fast, period: 1ms}]\n") + "tags: [{name: x, type: " + type +
           ", task: fast, trend: {rate: 10ms, deadband: 5}}]\n" + "blocks: [{name: m, type: MOVE, datatype: " + type +
           ", inputs: {IN: " + in + "}}]\n" + "connections: [m.OUT -> x]\n" +
           "store: {trend_raw_age: 36500d, trend_max_age: 36500d}\n";
  };
  auto ra = load_test_result(project("LREAL", "1.0"));
  ASSERT_TRUE(ra.ok());
  auto db = memory();
  Historian h(*ra.program, ra.store);
  h.set_time_base(kT0);
  std::string err;
  ASSERT_TRUE(h.prepare(*db, &err)) << err;
  VirtualClock clock(*ra.program);
  clock.run_until(45 * kMs);
  auto rb = load_test_result(project("INT", "2"));
  ASSERT_TRUE(rb.ok());
  auto change = plan_change(*ra.program, *rb.program);
  change->switch_ns = 50 * kMs;
  clock.begin_change(*change);
  h.switch_program(*rb.program, rb.store);
  clock.run_until(100 * kMs);
  ASSERT_TRUE(clock.change_complete());
  h.tasks_ended(*ra.program);
  h.run(*db, 2'000'000'000, false);
  // LREAL 1.0: the first bucket only (the rest within the band of 5); INT 2
  // from 50 ms: its first bucket stored though |2 - 1| < 5.
  EXPECT_EQ(starts(*db, "x"), (std::vector<std::int64_t>{0, 50}));
}

// Raw points of one series "s", every second from `from` for `n` seconds, value i.
void insert_raw(Database& db, std::int64_t from, int n) {
  db.sql().exec("INSERT OR IGNORE INTO trend_series (id, label, tag, element, type, unit, rate_ns, deadband) "
                "VALUES (1, 's', 's', 0, 'LREAL', '', 1000000000, 0)");
  SQLite::Statement ins(db.sql(), "INSERT INTO trend_point VALUES (1, 0, ?, 1000000000, ?, ?, ?, ?)");
  db.sql().exec("BEGIN");
  for (int i = 0; i < n; ++i) {
    ins.reset();
    ins.bind(1, from + i * 1000 * kMs);
    ins.bind(2, i - 0.5);
    ins.bind(3, i + 0.5);
    ins.bind(4, static_cast<double>(i));
    ins.bind(5, 1 + i % 2);  // counts 1, 2, 1, 2 ...: the mean is weighted by them
    ins.exec();
  }
  db.sql().exec("COMMIT");
}

StoreSettings retention(std::int64_t raw_age, std::int64_t downsample, std::int64_t max_age, std::uint64_t max_bytes) {
  StoreSettings s;
  s.trend_raw_age_ns = raw_age;
  s.trend_downsample_ns = downsample;
  s.trend_max_age_ns = max_age;
  s.trend_max_bytes = max_bytes;
  return s;
}

TEST(TrendRetention, OldRawPointsAreDownsampledIntoMinOfMinsMaxOfMaxesAndTheCountWeightedMean) {
  auto db = memory();
  std::string err;
  ASSERT_TRUE(ensure_trend_schema(db->sql(), &err)) << err;
  const std::int64_t hour = 3'600'000 * kMs, minute = 60'000 * kMs;
  const std::int64_t start = kT0 - kT0 % minute;  // a whole minute
  insert_raw(*db, start, 180);                     // three minutes
  // Raw age 1 h: at start + 1 h + 150 s the first two minutes are older than it.
  auto rep = apply_trend_retention(db->sql(), retention(hour, minute, 24 * hour, 1ULL << 30), start + hour + 150'000 * kMs);
  EXPECT_EQ(rep.downsampled, 120u);
  auto coarse = points(*db, "s", 1);
  ASSERT_EQ(coarse.size(), 2u);
  for (int m = 0; m < 2; ++m) {
    EXPECT_EQ(coarse[m].t, start + m * minute);
    EXPECT_EQ(coarse[m].min, 60 * m - 0.5);
    EXPECT_EQ(coarse[m].max, 60 * m + 59.5);
    EXPECT_EQ(coarse[m].count, 90);  // 30 × 1 + 30 × 2
    double sum = 0;
    for (int i = 60 * m; i < 60 * m + 60; ++i) sum += i * (1 + i % 2);
    EXPECT_DOUBLE_EQ(coarse[m].mean, sum / 90);
  }
  auto raw = points(*db, "s", 0);
  ASSERT_EQ(raw.size(), 60u);  // the third minute is kept raw: its bucket is not wholly past the raw age
  EXPECT_EQ(raw.front().t, start + 2 * minute);
}

TEST(TrendRetention, PointsOlderThanTheMaxAgeGo) {
  auto db = memory();
  std::string err;
  ASSERT_TRUE(ensure_trend_schema(db->sql(), &err)) << err;
  insert_raw(*db, kT0, 100);
  const std::int64_t s = 1000 * kMs;
  auto rep = apply_trend_retention(db->sql(), retention(200 * s, 60 * s, 200 * s, 1ULL << 30), kT0 + 230 * s);
  EXPECT_EQ(rep.expired, 30u);
  auto raw = points(*db, "s");
  ASSERT_EQ(raw.size(), 70u);
  EXPECT_EQ(raw.front().t, kT0 + 30 * s);
}

TEST(TrendRetention, TheOldestPointsGoUntilTheDatabaseFitsTheSize) {
  auto db = memory();
  std::string err;
  ASSERT_TRUE(ensure_trend_schema(db->sql(), &err)) << err;
  insert_raw(*db, kT0, 20000);
  const std::uint64_t before = database_used_bytes(db->sql());
  const std::uint64_t limit = 256 * 1024;
  ASSERT_GT(before, 2 * limit);
  const std::int64_t s = 1000 * kMs;
  auto rep = apply_trend_retention(db->sql(), retention(1000000 * s, 60 * s, 2000000 * s, limit), kT0 + 20000 * s);
  EXPECT_LE(database_used_bytes(db->sql()), limit);
  EXPECT_GT(rep.trimmed, 0u);
  auto raw = points(*db, "s");
  ASSERT_FALSE(raw.empty());
  EXPECT_EQ(raw.back().t, kT0 + 19999 * s);  // the newest stay
  EXPECT_EQ(raw.size(), 20000u - rep.trimmed);
  EXPECT_EQ(raw.front().t, kT0 + static_cast<std::int64_t>(rep.trimmed) * s);  // the oldest went first
  EXPECT_LT(rep.trimmed, 20000u * 19 / 20);  // a twentieth of the span at a time: not much more than needed
}

TEST(TrendFold, AFullRingDropsAndCountsInsteadOfWaiting) {
  TrendFold f;
  f.add(0, 0, IecType::LREAL, 100 * kMs);
  f.finalize();  // room for 4 s of 100 ms buckets and a little more
  Cell c;
  c.set<double>(1.0);
  for (int i = 0; i <= 100; ++i) f.fold(&c, i * 100 * kMs);  // 100 buckets finished, none taken
  std::uint64_t taken = 0;
  TrendBucket b;
  while (f.pop(b)) ++taken;
  EXPECT_GE(taken, 42u);
  EXPECT_EQ(taken + f.dropped(), 100u);
  EXPECT_GT(f.dropped(), 0u);
}

}  // namespace
}  // namespace syncplc::store
