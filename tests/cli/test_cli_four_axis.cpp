// The shipped four-axis projects end to end: reproducible simulation with and
// without frame loss, the demo's scan-cycle tests, metrics, the bus report.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "tests/support/cli_runner.hpp"

namespace {

using syncplc::testing::run_cli;
using syncplc::testing::slurp;
using syncplc::testing::write_temp_file;

const std::string kDir = std::string(SYNCPLC_SOURCE_DIR) + "/projects/four_axis_table/";

TEST(FourAxisTable, SimIsBitForBitReproducibleWithLoss) {
  for (const char* p : {"sync.yaml", "pd.yaml"}) {
    std::string t1 = write_temp_file(std::string("fa1_") + p + ".csv", ""), t2 = write_temp_file(std::string("fa2_") + p + ".csv", "");
    std::string m1 = t1 + ".json", m2 = t2 + ".json";
    const std::string args = "sim " + kDir + p + " -q -d 3s --seed 5 --set ring.loss.p=0.2 --set ring.loss.scope=link";
    auto a = run_cli(args + " --trace " + t1 + " --metrics " + m1);
    auto b = run_cli(args + " --trace " + t2 + " --metrics " + m2);
    ASSERT_EQ(a.rc, 0) << a.err;
    ASSERT_EQ(b.rc, 0) << b.err;
    EXPECT_EQ(slurp(t1), slurp(t2)) << p;
    auto j1 = nlohmann::json::parse(slurp(m1)), j2 = nlohmann::json::parse(slurp(m2));
    j1.erase("wall_s");
    j2.erase("wall_s");
    EXPECT_EQ(j1, j2) << p;
    EXPECT_EQ(j1["metrics"]["samples"], 3000);
    EXPECT_GT(j1["drivers"][1]["counters"]["frames_lost"].get<double>(), 3000 * 0.4);  // node 4 at 20 % per link
    // Another seed, another loss pattern.
    auto c = run_cli("sim " + kDir + p + " -q -d 3s --seed 6 --set ring.loss.p=0.2 --set ring.loss.scope=link --trace " + t2);
    ASSERT_EQ(c.rc, 0) << c.err;
    EXPECT_NE(slurp(t1), slurp(t2)) << p;
  }
}

TEST(FourAxisTable, DemoPassesItsScanCycleTestsAndThePdBaselineDoesNot) {
  auto sync = run_cli("test " + kDir + "sync.yaml " + kDir + "tests.yaml");
  EXPECT_EQ(sync.rc, 0) << sync.out << sync.err;
  EXPECT_NE(sync.out.find("3 passed, 0 failed"), std::string::npos) << sync.out;
  auto pd = run_cli("test " + kDir + "pd.yaml " + kDir + "tests.yaml");
  EXPECT_EQ(pd.rc, 1) << pd.out << pd.err;
  EXPECT_NE(pd.out.find("metrics.sync_rsme is 0.137"), std::string::npos) << pd.out;
}

TEST(FourAxisTable, SynchronousControlBeatsPdByThePapersMargins) {
  std::string ms = write_temp_file("fa_sync.json", ""), mp = write_temp_file("fa_pd.json", "");
  ASSERT_EQ(run_cli("sim " + kDir + "sync.yaml -q -d 6.283185s --metrics " + ms).rc, 0);
  ASSERT_EQ(run_cli("sim " + kDir + "pd.yaml -q -d 6.283185s --metrics " + mp).rc, 0);
  auto s = nlohmann::json::parse(slurp(ms))["metrics"], p = nlohmann::json::parse(slurp(mp))["metrics"];
  const double sync_cut = 1 - s["sync_rsme"].get<double>() / p["sync_rsme"].get<double>();
  const double track_cut = 1 - s["track_rsme"].get<double>() / p["track_rsme"].get<double>();
  // Paper 000 Table 1: -45.7 % Sync-RSME, -20.6 % Track-RSME (experiment).
  EXPECT_GT(sync_cut, 0.457);
  EXPECT_GT(track_cut, 0.206);
}

TEST(FourAxisTable, CheckReportsTheBusTime) {
  auto r = run_cli("check " + kDir + "sync.yaml");
  ASSERT_EQ(r.rc, 0) << r.err;
  EXPECT_NE(r.out.find("ring (sim_ring): 4 nodes, ethercat 100 Mbit/s, 128 B payload + 12 B overhead: bus time 11.20 us "
                       "per 1ms cycle"),
            std::string::npos)
      << r.out;
}

}  // namespace

namespace {

// The other papers' projects are reproducible too: same seed, same bytes.
TEST(PaperProjects, SimIsBitForBitReproducible) {
  const std::string src = SYNCPLC_SOURCE_DIR;
  const std::pair<std::string, std::string> runs[] = {
      {src + "/projects/paper003_estimator/estimator.yaml", "-d 5s --set ring.loss.p=0.3"},
      {src + "/projects/paper004_sync/three_signals.yaml", "-d 60s"},
      {src + "/projects/paper004_sync/six_axes.yaml", "-d 60s --set sync.rule=1"},
  };
  for (const auto& [project, args] : runs) {
    std::string t1 = write_temp_file("pp1.csv", ""), t2 = write_temp_file("pp2.csv", "");
    auto a = run_cli("sim " + project + " -q --seed 3 " + args + " --trace " + t1);
    auto b = run_cli("sim " + project + " -q --seed 3 " + args + " --trace " + t2);
    ASSERT_EQ(a.rc, 0) << project << a.err;
    ASSERT_EQ(b.rc, 0) << project << b.err;
    const std::string x = slurp(t1);
    EXPECT_GT(x.size(), 10000u) << project;
    EXPECT_EQ(x, slurp(t2)) << project;
  }
}

}  // namespace
