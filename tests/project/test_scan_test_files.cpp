// Errors in a scan-cycle tests file (`syncplc test PROJECT TESTS.yaml`) and
// how a test's `set:` reaches the program. Each test writes a project and a
// tests file and runs them as `syncplc test` does.
#include "runtime/project/scan_test.hpp"
#include "tests/project/loader_test_util.hpp"

namespace syncplc::loadertest {
namespace {

using ::testing::ElementsAre;

// A project with one 10 ms task: `lamp` is written by a NOT of `go`, `sp`
// is written by nobody (an HMI setpoint).
const char* const kProject = R"(
tasks: [{name: main, period: 10ms}]
tags:
  - {name: go, type: BOOL}
  - {name: lamp, type: BOOL}
  - {name: sp, type: LREAL, unit: m}
blocks:
  - {name: n, type: NOT}
connections:
  - go -> n.IN
  - n.OUT -> lamp
)";

struct Run {
  ScanTestReport report;
  std::string tests_path;
  // The tests file's diagnostics, with the file name replaced by "t.yaml".
  std::vector<std::string> errors() const {
    std::vector<std::string> v;
    for (const auto& d : report.diagnostics.sorted()) {
      std::string t = d.text();
      if (t.rfind(tests_path, 0) == 0) t = "t.yaml" + t.substr(tests_path.size());
      v.push_back(t);
    }
    return v;
  }
};

Run run_tests(const std::string& name, const char* tests, const char* project = kProject) {
  Run r;
  std::string p = temp_file("scan/" + name + ".yaml", yaml(project));
  r.tests_path = temp_file("scan/" + name + "-tests.yaml", yaml(tests));
  r.report = run_scan_tests(p, r.tests_path);
  return r;
}

TEST(ScanTestFiles, ACycleLaterThanTimeCanCountIsAnError) {
  // phase + n * period overflowed 64 bits of nanoseconds.
  auto r = run_tests("cycle", R"(
cases:
  - name: far
    steps:
      - {cycle: 18446744073709551615, expect: {lamp: TRUE}}
      - {cycle: 922337203685477580, expect: {lamp: TRUE}}
      - {cycle: 9, expect: {lamp: TRUE}}
)");
  EXPECT_THAT(r.errors(), ElementsAre("t.yaml:4:17: cycle 18446744073709551615 of task main is later than TIME can count",
                                      "t.yaml:5:17: cycle 922337203685477580 of task main is later than TIME can count"));
}

TEST(ScanTestFiles, SetOnATagWrittenEveryScanIsAnError) {
  // lamp is written by block n every scan: the set would never be seen.
  auto r = run_tests("written", R"(
cases:
  - name: lamp
    steps:
      - {at: 0ms, set: {lamp: FALSE, sp: 2}}
      - {at: 10ms, expect: {lamp: TRUE}}
)");
  EXPECT_THAT(r.errors(), ElementsAre("t.yaml:4:31: lamp is written every scan by block n.OUT, which wins: this set would "
                                      "be overwritten before anything reads it; set what block n reads instead"));
}

TEST(ScanTestFiles, AnErrorInAStepsTimeHidesNoErrorOfItsSet) {
  auto r = run_tests("at", R"(
cases:
  - name: both
    steps:
      - {at: 10 ms, set: {nothing: TRUE, sp: fast}}
      - {set: {lamp2: TRUE}}
)");
  EXPECT_THAT(r.errors(),
              ElementsAre("t.yaml:4:14: at: '10 ms' is not a duration (no space may separate 10 from its unit: 10ms; "
                          "write e.g. 1ms, 250us, 0.5s, T#1m30s)",
                          "t.yaml:4:36: unknown tag or instance.pin 'nothing'", "t.yaml:4:46: sp: 'fast' is not a number",
                          "t.yaml:5:9: a step needs 'at: <time>' or 'cycle: <n>'",
                          "t.yaml:5:23: unknown tag or instance.pin 'lamp2'"));
}

TEST(ScanTestFiles, SetGoesThroughTheOwnersWriteQueue) {
  // Like an HMI write: queued, applied at the owner's next scan start. A
  // queue too small for the set shows that it took that path.
  const char* project = R"(
tasks: [{name: main, period: 10ms, write_queue: 16}]
tags:
  - {name: few, type: "ARRAY[1..4] OF INT"}
  - {name: many, type: "ARRAY[1..20] OF INT"}
  - {name: out, type: INT}
blocks:
  - {name: m, type: MOVE}
connections:
  - few[2] -> m.IN
  - m.OUT -> out
)";
  auto ok = run_tests("queue-ok", R"(
cases:
  - name: queued
    steps:
      - {at: 20ms, set: {few: 7, "few[2]": 3}}
      - {at: 20ms, expect: {few: [7, 3, 7, 7], out: 3}}
)",
                      project);
  EXPECT_TRUE(ok.report.ok()) << ::testing::PrintToString(ok.errors())
                              << ::testing::PrintToString(ok.report.cases.empty() ? std::vector<std::string>{}
                                                                                   : ok.report.cases[0].failures);
  auto full = run_tests("queue-full", R"(
cases:
  - name: too many
    steps:
      - {at: 20ms, set: {many: 1}}
)",
                        project);
  ASSERT_EQ(full.report.cases.size(), 1u);
  EXPECT_THAT(full.report.cases[0].failures,
              ElementsAre(full.tests_path + ":4:32: case 'too many' at 20ms: set many: the write queue of task main is full"));
}

}  // namespace
}  // namespace syncplc::loadertest
