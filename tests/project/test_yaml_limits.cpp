// YAML aliases are limited: a project's files may hold one YAML node per byte
// (at least 10,000), aliases counted as what they expand to, and nest at most
// 64 levels deep. A file of nested aliases ("billion laughs": 600 bytes that
// expand to 10^8 nodes) is refused at the alias that passes the limit,
// before it is expanded, in bounded memory.
#include <algorithm>
#include <fstream>
#include <sstream>

#include "tests/project/loader_test_util.hpp"
#include "tests/support/yaml_laughs.hpp"
#include "tests/support/bounded_child.hpp"

namespace syncplc::loadertest {
namespace {

using ::testing::ElementsAre;
using ::testing::HasSubstr;
using ::testing::SizeIs;

using testing::laughs;  // tests/support/yaml_laughs.hpp

// Where the budget of a file of laughs() runs out: on line 5 (l3, a list of
// l2's of 1,111 nodes each), at the alias that takes the count past 10,000.
// Every node counts, keys too: line 1 holds 8 (the root map among them),
// line 2 12, line 3 112, line 4 1,112, line 5 2 before its aliases: 1,246,
// and 1,246 + 8 x 1,111 = 10,134. The 8th alias of line 5 is at column 45.
const char* kLaughsPlace = "p.yaml:5:45";

TEST(YamlLimits, NestedAliasesAreRefusedAtTheAliasThatPassesTheBudget) {
  ASSERT_LT(laughs().size(), 700u);
  auto r = load_project_text(laughs(), "p.yaml");
  EXPECT_FALSE(r.ok());
  EXPECT_THAT(errors(r), ElementsAre(std::string(kLaughsPlace) +
                                     ": alias *l2 expands the file past its limit of 10000 YAML nodes (one per "
                                     "byte of the project's files, at least 10000): aliases are not expanded "
                                     "that far"));
}

// The refusal costs memory in proportion to the file, not to its expansion:
// measured in a child whose address space is capped (a loader that expands
// the aliases runs out of it there, not out of the machine's memory).
TEST(YamlLimits, TheRefusalTakesBoundedMemory) {
  const std::string out = temp_file("laughs_bounded.txt", "");
  syncplc::testing::ChildEnd end = syncplc::testing::run_bounded([&] {
    auto r = load_project_text(laughs(), "p.yaml");
    std::ofstream f(out);
    for (const auto& e : errors(r)) f << e << "\n";
    return r.ok() ? 1 : 0;
  });
  std::stringstream got;
  got << std::ifstream(out).rdbuf();
  ASSERT_TRUE(end.exited) << "the child ended by signal " << end.status;
  EXPECT_EQ(end.status, 0) << got.str();
  EXPECT_THAT(got.str(), HasSubstr(std::string(kLaughsPlace) + ": alias *l2 expands the file past its limit"));
  EXPECT_LT(end.grown_kb(), 200 * 1024) << "peak RSS of the check beyond what it inherited";
}

TEST(YamlLimits, AProjectFileIsRefusedAtItsPlaceWithTheSameMessage) {
  const std::string path = temp_file("laughs/project.yaml", laughs());
  auto r = load_project(path);
  EXPECT_FALSE(r.ok());
  ASSERT_THAT(errors(r), SizeIs(1));
  EXPECT_THAT(errors(r)[0], ::testing::StartsWith(path + ":5:45: alias *l2 expands the file past its limit"));
}

TEST(YamlLimits, AliasesWithinTheBudgetAreExpanded) {
  // One anchored map used by three blocks: the ordinary use of aliases.
  auto r = load(R"(
tasks: [{name: main, period: 1ms}]
tags: [{name: a, type: INT}, {name: b, type: INT}, {name: c, type: INT}]
blocks:
  - {name: add_a, type: ADD, inputs: &two {IN2: 2}}
  - {name: add_b, type: ADD, inputs: *two}
  - {name: add_c, type: ADD, inputs: *two}
connections: [a -> add_a.IN1, b -> add_b.IN1, c -> add_c.IN1]
)");
  ASSERT_LOADS(r);
}

TEST(YamlLimits, AnIncludedFileIsRefusedAtItsOwnPlace) {
  const std::string main = temp_file("laughs_inc/main.yaml", "include: [more.yaml]\ntasks: [{name: main, period: 1ms}]\n");
  std::string more = laughs();
  more.erase(0, more.find('\n') + 1);  // no task line: the anchors start on line 1
  const std::string inc = temp_file("laughs_inc/more.yaml", more);
  auto r = load_project(main);
  EXPECT_FALSE(r.ok());
  ASSERT_THAT(errors(r), SizeIs(1)) << joined(r);
  EXPECT_THAT(errors(r)[0], ::testing::StartsWith(inc + ":4:45: alias *l2 expands the file past its limit"));
}

// The whole load shares one budget: a file included again and again counts
// each time it is read, and its bytes once.
TEST(YamlLimits, OneFileIncludedManyTimesSharesTheLoadsBudget) {
  // f0 includes f1 ten times, f1 includes f2 ten times ... f4 holds 200
  // nodes: 10^4 reads of it, 2 million nodes, from about 1 kB of files.
  for (int i = 0; i < 4; ++i) {
    std::string list = "include: [";
    for (int k = 0; k < 10; ++k) list += std::string(k ? ", " : "") + "f" + std::to_string(i + 1) + ".yaml";
    temp_file("laughs_many/f" + std::to_string(i) + ".yaml",
              list + "]\n" + (i == 0 ? "tasks: [{name: main, period: 1ms}]\n" : ""));
  }
  std::string leaf = "watch: [";
  for (int k = 0; k < 200; ++k) leaf += std::string(k ? "," : "") + "x";
  temp_file("laughs_many/f4.yaml", leaf + "]\n");
  auto r = load_project(temp_root() + "laughs_many/f0.yaml");
  EXPECT_FALSE(r.ok());
  std::string budget_errors;
  for (const auto& e : errors(r))
    if (e.find("YAML nodes") != std::string::npos) budget_errors += e + "\n";
  EXPECT_THAT(budget_errors, HasSubstr("f4.yaml:1:"));
  EXPECT_THAT(budget_errors, HasSubstr(": the project's files pass their limit of 10000 YAML nodes"));
  // Refused once: the files not yet read are not read.
  EXPECT_EQ(std::count(budget_errors.begin(), budget_errors.end(), '\n'), 1) << budget_errors;
  EXPECT_LT(r.sources.size(), 100u);
}

TEST(YamlLimits, NestingIsLimitedTo64Levels) {
  std::string deep = "tasks: [{name: main, period: 1ms}]\nx: ";
  for (int i = 0; i < 100; ++i) deep += "[";
  for (int i = 0; i < 100; ++i) deep += "]";
  auto r = load_project_text(deep + "\n", "p.yaml");
  // The 65th list from the top: the root map is level 1, x's value level 2.
  EXPECT_THAT(errors(r), ElementsAre("p.yaml:2:67: YAML nested deeper than 64 levels"));
}

TEST(YamlLimits, NestingByAliasesIsLimitedToo) {
  // Each anchor one level deeper than the one before, by alias: 70 levels
  // from 70 short lines.
  std::string s = "tasks: [{name: main, period: 1ms}]\nd0: &d0 [x]\n";
  for (int i = 1; i < 70; ++i)
    s += "d" + std::to_string(i) + ": &d" + std::to_string(i) + " [*d" + std::to_string(i - 1) + "]\n";
  auto r = load_project_text(s, "p.yaml");
  ASSERT_THAT(errors(r), SizeIs(1)) << joined(r);
  // d62 is 63 levels deep; under d63's list (level 2 of the file) it nests to 65.
  EXPECT_EQ(errors(r)[0], "p.yaml:65:12: alias *d62 nests the file deeper than 64 levels");
}

TEST(YamlLimits, AnAliasOfAnUnknownAnchorIsNamed) {
  EXPECT_THAT(errors("tasks: [{name: main, period: 1ms}]\nx: *nowhere\n"),
              ElementsAre(::testing::StartsWith("p.yaml:2:4: ")));
}

}  // namespace
}  // namespace syncplc::loadertest
