// The historian end to end: `syncplc run` with trended tags for a moment,
// then its database read by the sqlite3 shell (nobody here wrote it) and by
// `syncplc trend --csv`. Only properties a loaded machine cannot break are
// checked (no exact point counts: real-time scans may be skipped).
#include <gtest/gtest.h>

#include <cstdio>
#include <limits>
#include <regex>
#include <sstream>

#include "runtime/cli/wall_time.hpp"
#include "tests/support/cli_runner.hpp"
#include "tests/support/test_blocks.hpp"

namespace {

using syncplc::testing::run_cli;
using syncplc::testing::write_temp_file;

// A shell command's standard output.
std::string shell(const std::string& cmd) {
  std::string out;
  FILE* f = popen(cmd.c_str(), "r");
  if (!f) return out;
  char buf[4096];
  for (std::size_t n; (n = fread(buf, 1, sizeof buf, f)) > 0;) out.append(buf, n);
  pclose(f);
  return out;
}

std::vector<std::string> lines(const std::string& text) {
  std::vector<std::string> out;
  std::istringstream in(text);
  for (std::string l; std::getline(in, l);) out.push_back(l);
  return out;
}

std::vector<std::string> split(const std::string& line, char sep) {
  std::vector<std::string> out;
  std::istringstream in(line);
  for (std::string f; std::getline(in, f, sep);) out.push_back(f);
  return out;
}

const char* const kProject = R"(
tasks: [{name: main, period: 1ms}]
tags:
  - {name: pos, type: LREAL, unit: mm, trend: {rate: 100ms}}
  - {name: idle, type: LREAL, task: main, trend: {rate: 50ms, deadband: 1}}
blocks:
  - {name: ref, type: COSINE_TRAJECTORY, task: main, params: {amplitude: 10, omega: 3, cycles: 0}, inputs: {enable: TRUE}}
connections:
  - ref.x -> pos
)";

TEST(CliTrend, RunStoresBucketsTheSqliteShellAndTrendCsvRead) {
  const std::string project = write_temp_file("trend.yaml", kProject);
  const std::string here = write_temp_file("trend.keep", "");
  const std::string path = here.substr(0, here.rfind('/')) + "/trend.db";
  std::remove(path.c_str());
  auto r = run_cli("run " + project + " --duration 1500ms --no-status --db " + path);
  ASSERT_EQ(r.rc, 0) << r.err;

  EXPECT_EQ(shell("sqlite3 " + path + " 'PRAGMA integrity_check'"), "ok\n");
  // Every stored bucket of pos: start on the 100 ms grid, at most 100 scans
  // of the 1 ms task, min <= mean <= max within the cosine's 0..20 mm.
  const auto rows = lines(shell("sqlite3 -separator , " + path +
                                " \"SELECT p.t, p.span, p.min, p.max, p.mean, p.count, s.unit FROM trend_point p "
                                "JOIN trend_series s ON s.id = p.series WHERE s.label = 'pos' ORDER BY p.t\""));
  ASSERT_GE(rows.size(), 5u) << r.err;
  long long prev = 0;
  for (const auto& row : rows) {
    auto f = split(row, ',');
    ASSERT_EQ(f.size(), 7u) << row;
    const long long t = std::stoll(f[0]);
    EXPECT_EQ(f[1], "100000000");
    if (prev) {
      EXPECT_EQ((t - prev) % 100'000'000, 0) << row;
    }
    EXPECT_GT(t, prev);
    prev = t;
    const double mn = std::stod(f[2]), mx = std::stod(f[3]), mean = std::stod(f[4]);
    EXPECT_LE(mn, mean);
    EXPECT_LE(mean, mx);
    EXPECT_GE(mn, -1e-9);
    EXPECT_LE(mx, 20 + 1e-9);
    const int count = std::stoi(f[5]);
    EXPECT_GE(count, 1);
    EXPECT_LE(count, 100);
    EXPECT_EQ(f[6], "mm");
  }
  // idle never moves: its deadband keeps only its first bucket.
  EXPECT_EQ(shell("sqlite3 " + path + " \"SELECT count(*), max(p.max) FROM trend_point p JOIN trend_series s "
                                      "ON s.id = p.series WHERE s.label = 'idle'\""),
            "1|0.0\n");

  // syncplc trend --csv: the same points, one line each after the header.
  auto csv = run_cli("trend pos --db " + path + " --csv");
  ASSERT_EQ(csv.rc, 0) << csv.err;
  const auto out = lines(csv.out);
  ASSERT_EQ(out.size(), rows.size() + 1) << csv.out;
  EXPECT_EQ(out[0], "time,tag,min,max,mean,count");
  const std::regex iso(R"(\d{4}-\d\d-\d\dT\d\d:\d\d:\d\d\.\d{3}Z)");
  for (std::size_t i = 1; i < out.size(); ++i) {
    auto f = split(out[i], ',');
    auto g = split(rows[i - 1], ',');
    ASSERT_EQ(f.size(), 6u) << out[i];
    EXPECT_TRUE(std::regex_match(f[0], iso)) << out[i];
    EXPECT_EQ(f[1], "pos");
    EXPECT_NEAR(std::stod(f[3]), std::stod(g[3]), 1e-12 * 20);  // the shell prints 15 digits, trend --csv all 17
    EXPECT_EQ(f[5], g[5]);
  }
  // --since in the future: the header alone.
  auto none = run_cli("trend pos --db " + path + " --csv --since 2999-01-01");
  EXPECT_EQ(none.rc, 0) << none.err;
  EXPECT_EQ(none.out, "time,tag,min,max,mean,count\n");
  // A tag that is not trended: exit 2 with the trended ones named.
  auto bad = run_cli("trend speed --db " + path);
  EXPECT_EQ(bad.rc, 2);
  EXPECT_NE(bad.err.find("no trend of 'speed'"), std::string::npos) << bad.err;
  EXPECT_NE(bad.err.find("trended: idle, pos"), std::string::npos) << bad.err;
}

TEST(CliTrend, WhenIsAUtcTimeOrADurationAgo) {
  using syncplc::cli::format_wall;
  using syncplc::cli::parse_when;
  std::string err;
  const std::int64_t t = 1'764'043'200'000'000'000;  // 2025-11-25T04:00:00Z
  EXPECT_EQ(parse_when("2025-11-25T04:00:00Z", 0, &err), t);
  EXPECT_EQ(parse_when("2025-11-25 04:00:00.25", 0, &err), t + 250'000'000);
  EXPECT_EQ(parse_when("2025-11-25", 0, &err), t - 4 * 3'600'000'000'000);
  EXPECT_EQ(parse_when("10m", t, &err), t - 600'000'000'000);
  EXPECT_EQ(parse_when("now", t, &err), t);
  EXPECT_EQ(parse_when("2999-01-01", 0, &err), std::numeric_limits<std::int64_t>::max());  // past int64 ns: after everything
  EXPECT_FALSE(parse_when("yesterday", t, &err));
  EXPECT_NE(err.find("'yesterday' is not a time"), std::string::npos) << err;
  EXPECT_FALSE(parse_when("2025-13-01", t, &err));
  EXPECT_EQ(format_wall(t + 100'000'000), "2025-11-25T04:00:00.100Z");
}

}  // namespace
