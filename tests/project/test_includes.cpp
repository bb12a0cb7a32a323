// include: merges the lists of other files into the project; errors inside
// an included file name that file.
#include <filesystem>

#include "tests/project/loader_test_util.hpp"

namespace syncplc::loadertest {
namespace {

using ::testing::ElementsAre;

std::string dir_of(const std::string& path) { return std::filesystem::path(path).parent_path().string(); }

TEST(Includes, ListsAreMergedFromEveryFile) {
  std::string main = temp_file("merge/main.yaml", yaml(R"(
include: [io.yaml, logic/blocks.yaml]
tasks: [{name: main, period: 1ms}]
tags:
  - {name: go, type: BOOL}
traces: [go]
)"));
  temp_file("merge/io.yaml", yaml(R"(
tags:
  - {name: lamp, type: BOOL}
drivers:
  - {name: io, type: memory, channels: [{name: l, dir: out, type: BOOL}], bind: {l: lamp}}
)"));
  temp_file("merge/logic/blocks.yaml", yaml(R"(
include: wiring.yaml          # relative to logic/
blocks:
  - {name: t, type: TON, inputs: {PT: 10ms}}
traces: [lamp]
)"));
  temp_file("merge/logic/wiring.yaml", yaml(R"(
connections:
  - go -> t.IN
  - t.Q -> lamp
)"));
  auto r = load_project(main);
  ASSERT_LOADS(r);
  const Program& p = *r.program;
  // The file's own items first, then the included ones in include order.
  ASSERT_EQ(p.tags.size(), 2u);
  EXPECT_EQ(p.tags[0].name, "go");
  EXPECT_EQ(p.tags[1].name, "lamp");
  EXPECT_EQ(p.tags[1].loc.file, dir_of(main) + "/io.yaml");
  EXPECT_EQ(p.find_tag("lamp")->writer, "block t.Q");
  EXPECT_EQ(p.drivers.size(), 1u);
  ASSERT_EQ(p.traces.size(), 2u);
  EXPECT_EQ(p.traces[0].label, "go");
  EXPECT_EQ(p.traces[1].label, "lamp");
  EXPECT_EQ(p.file, main);
}

TEST(Includes, ErrorInsideAnIncludedFileNamesThatFile) {
  std::string main = temp_file("err/main.yaml", yaml(R"(
include: parts/tags.yaml
tasks: [{name: main, period: 1ms}]
tags:
  - {name: x, type: INT}
)"));
  std::string inc = temp_file("err/parts/tags.yaml", yaml(R"(
tags:
  - {name: y, type: INT, init: 40000}
  - {name: x, type: BOOL}
blocks: [{name: n, type: NOT, inputs: {IN: maybe}}]
)"));
  auto r = load_project(main);
  EXPECT_FALSE(r.ok());
  EXPECT_THAT(errors(r), ElementsAre(inc + ":2:32: init of y: value 40000 is out of range for INT (-32768 .. 32767)",
                                     inc + ":3:12: duplicate name 'x' (first defined at " + main + ":4:12)",
                                     inc + ":4:44: n.IN: 'maybe' is not a BOOL (TRUE or FALSE)"));
}

TEST(Includes, ErrorsFoundWhileBuildingNameTheIncludedFileToo) {
  std::string main = temp_file("build/main.yaml", yaml(R"(
include: blocks.yaml
tasks: [{name: main, period: 1ms}]
)"));
  std::string inc = temp_file("build/blocks.yaml", yaml(R"(
blocks:
  - {name: n, type: NOT, inputs: {IN: maybe}}
)"));
  EXPECT_THAT(errors(load_project(main)), ElementsAre(inc + ":2:39: n.IN: 'maybe' is not a BOOL (TRUE or FALSE)"));
}

TEST(Includes, YamlErrorInAnIncludedFile) {
  std::string main = temp_file("syntax/main.yaml", "include: broken.yaml\ntasks: [{name: main, period: 1ms}]\n");
  std::string inc = temp_file("syntax/broken.yaml", "tags:\n  - {name: x, type: BOOL\n");
  auto e = errors(load_project(main));
  ASSERT_EQ(e.size(), 1u);
  EXPECT_THAT(e[0], ::testing::StartsWith(inc + ":3:1: YAML syntax error"));
}

TEST(Includes, MissingIncludedFile) {
  std::string main = temp_file("missing/main.yaml", yaml(R"(
include:
  - nothere.yaml
tasks: [{name: main, period: 1ms}]
)"));
  EXPECT_THAT(errors(load_project(main)), ElementsAre(main + ":2:5: include 'nothere.yaml': cannot open file"));
}

TEST(Includes, WhatAnIncludedFileCannotDo) {
  std::string main = temp_file("rules/main.yaml", yaml(R"(
include: [sub.yaml]
tasks: [{name: main, period: 1ms}]
tags: [{name: a, type: BOOL}]
)"));
  std::string sub = temp_file("rules/sub.yaml", yaml(R"(
project: {name: other}
tags: {name: b, type: BOOL}
colour: red
)"));
  EXPECT_THAT(errors(load_project(main)),
              ElementsAre(sub + ":1:10: an included file cannot set 'project'",
                          sub + ":2:7: 'tags' must be a list to be included", sub + ":3:9: unknown top-level key 'colour'"));
}

TEST(Includes, MetricsComeFromOneFile) {
  std::string main = temp_file("metrics/main.yaml", yaml(R"(
include: [sub.yaml]
tasks: [{name: main, period: 1ms}]
)"));
  temp_file("metrics/sub.yaml", yaml(R"(
tags: [{name: e, type: "ARRAY[1..2] OF LREAL"}]
metrics: {axis_errors: e}
)"));
  auto r = load_project(main);
  ASSERT_TRUE(r.ok()) << joined(r);
  EXPECT_EQ(r.metrics.axis_errors.size(), 2u);
  std::string twice = temp_file("metrics/twice.yaml", yaml(R"(
include: [sub.yaml]
tasks: [{name: main, period: 1ms}]
metrics: {axis_errors: e}
)"));
  EXPECT_THAT(errors(load_project(twice)),
              ElementsAre(::testing::HasSubstr("sub.yaml:2:10: 'metrics' is also set at ")));
}

TEST(Includes, IncludeMustNameFiles) {
  EXPECT_THAT(errors(R"(
include: {file: a.yaml}
tasks: [{name: main, period: 1ms}]
)"),
              ElementsAre("p.yaml:1:10: include: a file name or a list of file names"));
  EXPECT_THAT(errors(R"(
include: [[a.yaml]]
tasks: [{name: main, period: 1ms}]
)"),
              ElementsAre("p.yaml:1:11: include: expected a file name"));
}

TEST(Includes, ACycleIsReportedWhereItCloses) {
  std::string main = temp_file("cycle/main.yaml", "include: b.yaml\ntasks: [{name: main, period: 1ms}]\n");
  std::string b = temp_file("cycle/b.yaml", "include: c.yaml\n");
  std::string c = temp_file("cycle/c.yaml", "tags: [{name: x, type: INT}]\ninclude: b.yaml\n");
  EXPECT_THAT(errors(load_project(main)), ElementsAre(c + ":2:10: include cycle: b.yaml -> c.yaml -> b.yaml"));
  // Including oneself is the shortest cycle.
  std::string self = temp_file("cycle/self.yaml", "include: self.yaml\ntasks: [{name: main, period: 1ms}]\n");
  EXPECT_THAT(errors(load_project(self)), ElementsAre(self + ":1:10: include cycle: self.yaml -> self.yaml"));
}

TEST(Includes, DeepButAcyclicNestingStopsAtTheDepthLimit) {
  std::string main = temp_file("deep/main.yaml", "include: d1.yaml\ntasks: [{name: main, period: 1ms}]\n");
  for (int i = 1; i <= 12; ++i)
    temp_file("deep/d" + std::to_string(i) + ".yaml", "include: d" + std::to_string(i + 1) + ".yaml\n");
  temp_file("deep/d13.yaml", "tags: []\n");
  auto e = errors(load_project(main));
  EXPECT_THAT(e, ::testing::Contains(::testing::HasSubstr("includes nested deeper than 8 levels")));
}

}  // namespace
}  // namespace syncplc::loadertest
