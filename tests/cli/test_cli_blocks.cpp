// `syncplc blocks`: the list shows each type's first sentence (not cut at an
// abbreviation, no second paragraph); an unknown name suggests the closest.
#include <gtest/gtest.h>

#include <sstream>
#include <string>

#include "tests/support/cli_runner.hpp"

namespace syncplc {
namespace {

std::string line_of(const std::string& out, const std::string& name) {
  std::istringstream is(out);
  for (std::string l; std::getline(is, l);)
    if (l.rfind("  " + name + " ", 0) == 0) return l;
  return "";
}

TEST(CliBlocks, SummariesAreWholeFirstSentences) {
  auto list = testing::run_cli("blocks");
  ASSERT_EQ(list.rc, 0);
  const std::string cos = line_of(list.out, "COSINE_TRAJECTORY");
  EXPECT_NE(cos.find("(Fig. 4): with tau"), std::string::npos) << cos;
  const std::string steps = line_of(list.out, "STEP_RAMP_SEQUENCE");
  EXPECT_NE(steps.find("Figs. 5 and 10), the input the nonlinear filter expects"), std::string::npos) << steps;
  const std::string sync = line_of(list.out, "TRANSIENT_SYNC");
  EXPECT_NE(sync.find("energy index"), std::string::npos) << sync;
  EXPECT_EQ(sync.find("Every scan k"), std::string::npos) << sync;  // the second paragraph
  for (const char* b : {"COSINE_TRAJECTORY", "STEP_RAMP_SEQUENCE", "TRANSIENT_SYNC", "TON", "INT_TO_DINT"})
    EXPECT_EQ(line_of(list.out, b).back(), '.') << b;
}

TEST(CliBlocks, UnknownNameSuggestsTheClosest) {
  auto ton = testing::run_cli("blocks ton");
  EXPECT_EQ(ton.rc, 2);
  EXPECT_NE(ton.err.find("unknown block type 'ton'; did you mean 'TON'?"), std::string::npos) << ton.err;
  auto conv = testing::run_cli("blocks int_to_dnt");
  EXPECT_NE(conv.err.find("did you mean 'INT_TO_DINT'?"), std::string::npos) << conv.err;
  auto none = testing::run_cli("blocks QQQQQQQQ");
  EXPECT_EQ(none.err.find("did you mean"), std::string::npos) << none.err;
}

}  // namespace
}  // namespace syncplc
