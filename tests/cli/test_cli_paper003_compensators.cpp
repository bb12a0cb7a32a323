// The shipped paper-003 compensator projects (docs/results.md §3, Figs. 7-8)
// end to end through `syncplc sim`: the orderings the results page reports
// hold at 20 % loss, on a shorter run than the page's.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include <string>
#include <vector>

#include "tests/support/cli_runner.hpp"

namespace {

using syncplc::testing::run_cli;
using syncplc::testing::slurp;
using syncplc::testing::write_temp_file;

const std::string kCompensatorsDir = std::string(SYNCPLC_SOURCE_DIR) + "/projects/paper003_compensators/";

// metrics.axes[i].rms_error, i = zero, hold, recursive Taylor, robust Taylor,
// Wiener predictor, Ling & Lemmon's optimum (its shipped taps are those for 20 % loss).
std::vector<double> compensator_rms(const std::string& project, const std::string& duration, const std::string& loss) {
  const std::string m = write_temp_file("p003_" + project + ".json", "");
  auto r = run_cli("sim " + kCompensatorsDir + project + " -q -d " + duration + " --set ring.loss.p=" + loss +
                   " --set wiener.dropout_rate=" + loss + " --metrics " + m);
  EXPECT_EQ(r.rc, 0) << r.err;
  std::vector<double> out;
  const auto j = nlohmann::json::parse(slurp(m));  // named: a range-for over a member of a temporary dangles
  for (const auto& a : j["metrics"]["axes"])
    out.push_back(a["rms_error"].is_number() ? a["rms_error"].get<double>() : 1e300);
  return out;
}

TEST(Paper003Compensators, WhiteNoiseOptimalLowestAndTaylorWorst) {
  const auto v = compensator_rms("noise.yaml", "20s", "0.2");
  ASSERT_EQ(v.size(), 6u);
  const double zero = v[0] * v[0], hold = v[1] * v[1], recursive = v[2] * v[2], robust = v[3] * v[3],
               wiener = v[4] * v[4], optimal = v[5] * v[5];
  EXPECT_LT(optimal, zero);         // Ling & Lemmon's output-power optimum: the lowest of all
  EXPECT_LT(optimal, wiener);
  EXPECT_LT(wiener, 0.97 * hold);   // the Wiener predictor: -5.9 % at 20 % (100 s)
  EXPECT_LT(zero, wiener);          // ... and not the output-power optimum
  EXPECT_LT(hold, robust);
  EXPECT_LT(robust, recursive);     // the paper's recursive Taylor: worst for noise
  EXPECT_GT(optimal, 0.18);
  EXPECT_LT(optimal, 0.22);         // R_yy(0) = 0.197 without loss
}

TEST(Paper003Compensators, SinusoidOptimalWorstOfThePapersThree) {
  const auto v = compensator_rms("sinusoid.yaml", "10s", "0.2");
  ASSERT_EQ(v.size(), 6u);
  const double zero = v[0], hold = v[1], recursive = v[2], robust = v[3], wiener = v[4], optimal = v[5];
  EXPECT_GT(optimal, 30 * hold);  // mm of deviation against hundredths
  EXPECT_GT(optimal, 30 * recursive);
  EXPECT_LT(robust, hold);
  EXPECT_GT(optimal, zero);       // shaped for noise, its negative taps do worse than no estimate at all
  EXPECT_LT(wiener, zero);
}

// `syncplc design-compensator` on the shipped loop: the optimum's power is
// below zero fill's and hold's, the recursive Taylor taps are reported
// unbounded, and the --set line gives the taps the project runs with.
TEST(Paper003Compensators, DesignCompensatorPrintsTheOptimumAndItsSetLine) {
  auto r = run_cli("design-compensator " + kCompensatorsDir + "loop_model.yaml --loss 0.2 --taps 4,-6,4,-1 --json");
  ASSERT_EQ(r.rc, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  const double optimal = j["optimal"]["output_power"].get<double>();
  ASSERT_EQ(j["compare"].size(), 3u);
  EXPECT_LT(optimal, j["compare"][0]["output_power"].get<double>());  // zero fill
  EXPECT_LT(optimal, j["compare"][1]["output_power"].get<double>());  // hold
  EXPECT_FALSE(j["compare"][2]["ms_stable"].get<bool>());             // 4, -6, 4, -1 at 20 %
  EXPECT_TRUE(j["compare"][2]["output_power"].is_null());
  EXPECT_LT(j["optimal"]["gradient_norm"].get<double>(), 1e-7);
  // The shipped project's taps are the ones designed at 20 %.
  const auto taps = j["optimal"]["taps"];
  ASSERT_EQ(taps.size(), 4u);
  for (const char* project : {"noise.yaml", "sinusoid.yaml"}) {
    const std::string text = slurp(kCompensatorsDir + project);
    const auto block = text.find("name: optimal\n");
    ASSERT_NE(block, std::string::npos) << project;
    for (int i = 0; i < 4; ++i) {
      const std::string key = "a" + std::to_string(i + 1) + ": ";
      const auto at = text.find(key, block);
      ASSERT_NE(at, std::string::npos) << project << " " << key;
      EXPECT_NEAR(std::stod(text.substr(at + key.size(), 30)), taps[static_cast<std::size_t>(i)].get<double>(), 1e-9)
          << project << " " << key;
    }
  }
  auto text = run_cli("design-compensator " + kCompensatorsDir + "loop_model.yaml --loss 0.2 --order 2");
  ASSERT_EQ(text.rc, 0) << text.err;
  EXPECT_NE(text.out.find("--set NAME.design=1 --set NAME.order=2 --set NAME.a1="), std::string::npos) << text.out;
}

TEST(Paper003Compensators, DesignCompensatorRefusesABadLoopWithItsPlace) {
  const std::string f = write_temp_file("bad_loop.yaml", "plant: {num: [0, 1], den: [0, 1]}\ndelay: 0\nfoo: 1\n");
  auto r = run_cli("design-compensator " + f + " --loss 0.1");
  EXPECT_EQ(r.rc, 2);
  EXPECT_NE(r.err.find("bad_loop.yaml:2:8: delay is a whole number of frames"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("bad_loop.yaml:3:6: unknown key 'foo'"), std::string::npos) << r.err;
  const std::string g = write_temp_file("bad_loop2.yaml", "plant: {num: [0, 1], den: [0, 1]}\n");
  r = run_cli("design-compensator " + g + " --loss 0.1");
  EXPECT_EQ(r.rc, 2);
  EXPECT_NE(r.err.find("denominator's first coefficient (z^0) is 0"), std::string::npos) << r.err;
  r = run_cli("design-compensator " + g + " --loss 1.5");
  EXPECT_NE(r.rc, 0);
  r = run_cli("design-compensator " + kCompensatorsDir + "loop_model.yaml --loss 0.2 --taps 1,x");
  EXPECT_EQ(r.rc, 2);
  EXPECT_NE(r.err.find("'x' is not a finite number"), std::string::npos) << r.err;
}

}  // namespace
