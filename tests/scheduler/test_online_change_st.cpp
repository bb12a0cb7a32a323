// Online change of Structured Text instances (issue 23): an unchanged POU's
// instance is kept as it runs; a changed body takes effect at the task's
// switch, keeping every variable whose path and type are unchanged, and new
// variables start at their initial values; the report lists the instance.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "runtime/core/program_change.hpp"
#include "runtime/core/virtual_clock.hpp"
#include "tests/support/project_fixture.hpp"

namespace syncplc {
namespace online_change_st {

std::string write_source(const std::string& name, const std::string& text) {
  const auto dir = std::filesystem::temp_directory_path() / ("syncplc-st-change-" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  const auto path = dir / name;
  std::ofstream(path) << text;
  return path.string();
}

std::string project(const std::string& source) {
  return "tasks: [{name: main, period: 1ms}]\nsources: [" + source +
         "]\ntags:\n  - {name: out, type: DINT}\nprograms:\n  - {name: main, type: Main}\n";
}

const char* kV1 = R"(
FUNCTION_BLOCK Counter
VAR_OUTPUT y : DINT; END_VAR
VAR n : DINT; END_VAR
n := n + 1;
y := n;
END_FUNCTION_BLOCK
PROGRAM Main
VAR_EXTERNAL out : DINT; END_VAR
VAR c : Counter; total : DINT; gone : BOOL; END_VAR
c();
total := c.y;
out := total;
END_PROGRAM
)";

// The body changed (total doubles), a variable added, one removed, one's type changed.
const char* kV2 = R"(
FUNCTION_BLOCK Counter
VAR_OUTPUT y : DINT; END_VAR
VAR n : DINT; END_VAR
n := n + 1;
y := n;
END_FUNCTION_BLOCK
PROGRAM Main
VAR_EXTERNAL out : DINT; END_VAR
VAR c : Counter; total : DINT; fresh : INT := 7; END_VAR
c();
total := c.y * 2;
out := total;
END_PROGRAM
)";

struct StRun {
  std::unique_ptr<Program> a, b;
  std::unique_ptr<ProgramChange> change;
  std::unique_ptr<VirtualClock> clock;
};

void change_at(StRun& r, const std::string& first, const std::string& second) {
  r.a = load_test_project(project(write_source("a.st", first)));
  ASSERT_TRUE(r.a);
  r.clock = std::make_unique<VirtualClock>(*r.a);
  r.clock->run_until(99'500'000);  // 100 scans: 0 .. 99 ms
  r.b = load_test_project(project(write_source("b.st", second)));
  ASSERT_TRUE(r.b);
  r.change = plan_change(*r.a, *r.b);
  r.change->switch_ns = 100'000'000;
  r.clock->begin_change(*r.change);
  r.clock->run_until(149'500'000);  // 50 more scans on the new program
  ASSERT_TRUE(r.clock->change_complete());
}

TEST(OnlineChangeSt, AnUnchangedPouKeepsItsInstanceRunning) {
  StRun r;
  change_at(r, kV1, kV1);
  EXPECT_EQ(r.change->count(InstanceFate::Kept), 1u);
  EXPECT_EQ(tag_cell(*r.b, "main.c.n").get<std::int32_t>(), 150);
  EXPECT_EQ(tag_cell(*r.b, "out").get<std::int32_t>(), 150);
}

TEST(OnlineChangeSt, AChangedBodyTakesEffectAtTheSwitchAndKeepsTheVariables) {
  StRun r;
  change_at(r, kV1, kV2);
  ASSERT_EQ(r.change->instances.size(), 1u);
  const InstanceChange& ic = r.change->instances[0];
  EXPECT_EQ(ic.name, "main");
  EXPECT_EQ(ic.fate, InstanceFate::New);
  EXPECT_EQ(ic.detail.rfind("its code changed; its variables kept: c.y, c.n, total", 0), 0u) << ic.detail;
  EXPECT_NE(ic.detail.find("new, at their initial values: fresh"), std::string::npos) << ic.detail;
  // The counter inside went on counting (150 scans in all), the new body doubles it.
  EXPECT_EQ(tag_cell(*r.b, "main.c.n").get<std::int32_t>(), 150);
  EXPECT_EQ(tag_cell(*r.b, "out").get<std::int32_t>(), 300);
  EXPECT_EQ(tag_cell(*r.b, "main.fresh").get<std::int16_t>(), 7);
}

}  // namespace online_change_st
}  // namespace syncplc
