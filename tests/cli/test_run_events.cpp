// What `syncplc run` leaves in the event log, read with the sqlite3 shell and
// with `syncplc events`: start and stop with the reason, a task's events with
// its scan number, a corrupt database moved aside, a missing one refused.
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <fstream>

#include "tests/store/store_test_util.hpp"
#include "tests/support/cli_runner.hpp"

namespace syncplc::testing {
namespace {

using syncplc::store::testing::sqlite_shell;


std::string fresh_db(const std::string& name) {
  const auto dir = std::filesystem::temp_directory_path() / ("syncplc-run-events-" + std::to_string(getpid())) / name;
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return (dir / "plc.db").string();
}

// A task whose watchdog (log only) trips on its first scans: events with scan numbers.
const char* kProject = R"(tasks:
  - {name: slow, period: 10ms, watchdog: {time: 1ms, action: log}}
tags:
  - {name: x, type: LREAL}
blocks:
  - {name: b, type: BURN, task: slow, inputs: {EXEC: 2ms}}
)";

TEST(RunEvents, StartStopAndATasksEventsWithItsScanNumber) {
  const std::string project = write_temp_file("run_events.yaml", kProject);
  const std::string db = fresh_db("start_stop");
  const CliResult r = run_cli("run " + project + " --no-status -d 300ms --db " + db);
  ASSERT_EQ(r.rc, 0) << r.err;
  EXPECT_EQ(sqlite_shell(db, "SELECT kind FROM events ORDER BY id LIMIT 1"), "start");
  EXPECT_EQ(sqlite_shell(db, "SELECT message FROM events ORDER BY id DESC LIMIT 1"),
            "the run ended (--duration) (exit status 0)");
  // Each watchdog trip is one event of task slow with the scan it came from.
  EXPECT_EQ(sqlite_shell(db, "SELECT count(*) > 0, count(*) = count(scan), count(DISTINCT scan) = count(*) FROM events "
                      "WHERE kind = 'watchdog' AND task = 'slow'"),
            "1|1|1");
  const CliResult listed = run_cli("events --db " + db + " --kind watchdog");
  ASSERT_EQ(listed.rc, 0) << listed.err;
  EXPECT_NE(listed.out.find("watchdog          slow       "), std::string::npos) << listed.out;
  EXPECT_NE(listed.out.find("watchdog tripped"), std::string::npos) << listed.out;
  EXPECT_EQ(sqlite_shell(db, "PRAGMA integrity_check"), "ok");
}

TEST(RunEvents, ACorruptDatabaseMovedAsideIsAnEventOfTheNewOne) {
  const std::string project = write_temp_file("run_events_corrupt.yaml", kProject);
  const std::string db = fresh_db("corrupt");
  std::ofstream(db) << "this is not an SQLite database, and it is long enough to be read as one......";
  const CliResult r = run_cli("run " + project + " --no-status -d 100ms --db " + db);
  ASSERT_EQ(r.rc, 0) << r.err;
  const std::string moved = sqlite_shell(db, "SELECT message FROM events WHERE kind = 'store-moved-aside'");
  EXPECT_NE(moved.find("the database was unreadable ("), std::string::npos) << moved;
  EXPECT_NE(moved.find("moved to " + db + ".corrupt-"), std::string::npos) << moved;
}

TEST(RunEvents, EventsWithoutADatabaseSaysSo) {
  const std::string db = fresh_db("missing");
  const CliResult r = run_cli("events --db " + db);
  EXPECT_EQ(r.rc, 2);
  EXPECT_EQ(r.err, "syncplc: no database at " + db + "\n");
}

}  // namespace
}  // namespace syncplc::testing
