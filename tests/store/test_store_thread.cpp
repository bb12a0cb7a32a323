// The store thread: jobs on their own schedules, a final run at stop, a
// failing job retried with the fault visible until it succeeds.
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <limits>
#include <stdexcept>
#include <thread>

#include "runtime/core/monotonic_clock.hpp"
#include "runtime/store/store_thread.hpp"

namespace syncplc::store {
namespace {

struct CountingJob : StoreJob {
  std::atomic<int> runs{0}, finals{0};
  std::atomic<bool> fail{false};
  std::atomic<std::int64_t> period_ns{5'000'000};
  std::int64_t next_ = 0;
  const char* name() const override { return "counting"; }
  bool prepare(Database& db, std::string*) override {
    db.sql().exec("CREATE TABLE IF NOT EXISTS runs (n INTEGER)");
    return true;
  }
  std::int64_t due_ns() const override { return next_; }
  void run(Database& db, std::int64_t now, bool final) override {
    if (fail) throw std::runtime_error("database or disk is full");
    db.sql().exec("INSERT INTO runs VALUES (1)");
    ++runs;
    if (final) ++finals;
    next_ = now + period_ns;
  }
};

struct RefusingJob : StoreJob {
  const char* name() const override { return "refusing"; }
  bool prepare(Database&, std::string* error) override {
    *error = "tables too new";
    return false;
  }
  std::int64_t due_ns() const override { return 0; }
  void run(Database&, std::int64_t, bool) override { FAIL() << "never added"; }
};

std::unique_ptr<Database> memory() {
  std::string err;
  return Database::open(kMemoryDatabase, nullptr, &err);
}

template <class F>
bool eventually(F&& f, int ms = 60000) {  // a guard against a hang only
  for (int i = 0; i < ms; ++i) {
    if (f()) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  return f();
}

TEST(StoreThread, RunsJobsWhenDueAndOnceMoreAtStop) {
  StoreThread st(memory());
  auto job = std::make_unique<CountingJob>();
  CountingJob& j = *job;
  std::string err;
  ASSERT_TRUE(st.add(std::move(job), &err)) << err;
  st.start();
  EXPECT_TRUE(eventually([&] { return j.runs >= 5; }));
  st.stop();
  EXPECT_EQ(j.finals, 1);
  EXPECT_EQ(st.database().sql().execAndGet("SELECT count(*) FROM runs").getInt(), j.runs.load());
  EXPECT_FALSE(st.health().fault);
  st.stop();  // idempotent
  EXPECT_EQ(j.finals, 1);
}

TEST(StoreThread, AJobThatCannotPrepareIsNotAdded) {
  StoreThread st(memory());
  std::string err;
  EXPECT_FALSE(st.add(std::make_unique<RefusingJob>(), &err));
  EXPECT_EQ(err, "refusing: tables too new");
}

TEST(StoreThread, AFailingJobShowsTheFaultAndIsRetriedUntilItSucceeds) {
  StoreThread st(memory());
  auto job = std::make_unique<CountingJob>();
  CountingJob& j = *job;
  j.fail = true;
  std::string err;
  ASSERT_TRUE(st.add(std::move(job), &err));
  st.start();
  ASSERT_TRUE(eventually([&] { return st.health().fault; }));
  const StoreHealth h = st.health();
  EXPECT_EQ(h.last_error, "counting: database or disk is full");
  EXPECT_GE(h.failures, 1u);
  // Retried a second later, not in a tight loop.
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  EXPECT_LE(st.health().failures, 2u);
  j.fail = false;
  EXPECT_TRUE(eventually([&] { return !st.health().fault; }));
  EXPECT_GT(j.runs, 0);
  st.stop();
}

TEST(StoreThread, ExclusiveRunsWhileNoJobRuns) {
  StoreThread st(memory());
  auto job = std::make_unique<CountingJob>();
  CountingJob& j = *job;
  j.period_ns = 0;  // as often as it can
  std::string err;
  ASSERT_TRUE(st.add(std::move(job), &err));
  st.start();
  ASSERT_TRUE(eventually([&] { return j.runs > 10; }));
  st.exclusive([&] {
    const int before = j.runs;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
    EXPECT_EQ(j.runs, before) << "no job ran meanwhile";
  });
  st.stop();
}

}  // namespace
}  // namespace syncplc::store
