// The statistics `run` and `sim` print (runtime/project/report.hpp): the task
// table, then a line for each task across whose edges anything went.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <sstream>

#include "runtime/core/virtual_clock.hpp"
#include "runtime/project/report.hpp"
#include "tests/support/project_fixture.hpp"

namespace syncplc {
namespace {

using ::testing::HasSubstr;
using ::testing::Not;

TEST(Statistics, CountWritesAppliedOnlyForTasksThatHadAny) {
  auto p = load_test_project(R"(
tasks: [{name: fast, period: 1ms}, {name: slow, period: 10ms}]
tags:
  - {name: sp, type: INT, hmi: readwrite, task: fast}
  - {name: other, type: INT, task: slow}
)");
  ASSERT_TRUE(p);
  VirtualClock clock(*p);
  clock.run_until(3'000'000, true);
  Cell one;
  one.set<std::int16_t>(7);
  ASSERT_TRUE(p->write_tag(*p->find_tag("sp"), 0, &one, 1));
  ASSERT_TRUE(p->write_tag(*p->find_tag("sp"), 0, &one, 1));
  clock.run_until(20'000'000, true);
  std::ostringstream os;
  print_statistics(os, *p, true);
  EXPECT_THAT(os.str(), HasSubstr("\n  fast: 2 queued writes applied, 0 late reads, 0 events dropped\n"));
  EXPECT_THAT(os.str(), Not(HasSubstr("  slow:"))) << "nothing crossed its edges";
}

}  // namespace
}  // namespace syncplc
