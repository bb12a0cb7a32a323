// Every YAML example of docs/project-format.md is checked here, so the
// reference cannot drift from what the loader accepts. Each ```yaml block
// starts with one of (a ```st block: (* part: NAME *), an ST source a project names)
//   # file: NAME    a project: it must load, or fail with exactly the
//                   "# error: NAME:line:col: message" lines it contains
//   # part: NAME    a file included by another example (not loaded alone)
//   # tests: NAME   a scan-cycle tests file for project NAME: every case passes
#include <fstream>
#include <map>
#include <sstream>

#include "runtime/project/scan_test.hpp"
#include "tests/project/loader_test_util.hpp"

namespace syncplc::loadertest {
namespace {

struct Example {
  std::string kind, name, text;
  int doc_line = 0;
  std::vector<std::string> expected;  // "# error:" lines
};

std::vector<Example> read_examples(const std::string& path) {
  std::ifstream in(path);
  std::vector<Example> out;
  std::string line;
  int n = 0;
  Example* cur = nullptr;
  while (std::getline(in, line)) {
    ++n;
    if (!cur && (line == "```yaml" || line == "```st")) {
      out.push_back(Example{});
      cur = &out.back();
      cur->doc_line = n;
      continue;
    }
    if (cur && line == "```") {
      cur = nullptr;
      continue;
    }
    if (!cur) continue;
    if (cur->text.empty()) {
      for (const char* k : {"file", "part", "tests"}) {
        std::string prefix = std::string("# ") + k + ": ";
        if (line.rfind(prefix, 0) == 0) {
          cur->kind = k;
          cur->name = line.substr(prefix.size());
        }
      }
      // A Structured Text source a project example names: (* part: NAME *).
      if (line.rfind("(* part: ", 0) == 0 && line.size() > 12 && line.substr(line.size() - 3) == " *)") {
        cur->kind = "part";
        cur->name = line.substr(9, line.size() - 12);
      }
    }
    if (line.rfind("# error: ", 0) == 0) cur->expected.push_back(line.substr(9));
    cur->text += line + "\n";
  }
  return out;
}

TEST(DocExamples, EveryYamlExampleOfTheProjectFormatReferenceIsChecked) {
  const std::string doc = SYNCPLC_SOURCE_DIR "/docs/project-format.md";
  auto examples = read_examples(doc);
  ASSERT_GT(examples.size(), 10u) << doc;
  std::map<std::string, std::string> path_of;
  int tests_files = 0;
  for (const auto& e : examples) {
    ASSERT_FALSE(e.kind.empty()) << doc << ":" << e.doc_line << ": a yaml example must start with # file:, # part: or # tests:";
    if (e.kind == "tests") continue;
    ASSERT_FALSE(path_of.count(e.name)) << doc << ":" << e.doc_line << ": two examples named " << e.name;
    path_of[e.name] = temp_file("doc/" + e.name, e.text);
  }
  const std::string dir = temp_root() + "doc/";
  int loaded = 0, failing = 0;
  for (const auto& e : examples) {
    SCOPED_TRACE(doc + ":" + std::to_string(e.doc_line) + ": " + e.kind + " " + e.name);
    if (e.kind == "file") {
      auto r = load_project(path_of[e.name]);
      std::vector<std::string> got;
      for (const auto& d : r.diagnostics.sorted()) {
        std::string t = d.text();
        for (std::size_t at; (at = t.find(dir)) != std::string::npos;) t.erase(at, dir.size());
        got.push_back(t);
      }
      EXPECT_EQ(got, e.expected);
      EXPECT_EQ(r.ok(), e.expected.empty());
      (e.expected.empty() ? loaded : failing)++;
    } else if (e.kind == "tests") {
      ASSERT_TRUE(path_of.count(e.name)) << "no project example named " << e.name;
      std::string tests = temp_file("doc/tests-" + std::to_string(++tests_files) + ".yaml", e.text);
      auto rep = run_scan_tests(path_of[e.name], tests);
      for (const auto& d : rep.diagnostics.sorted()) ADD_FAILURE() << d.text();
      for (const auto& c : rep.cases)
        for (const auto& f : c.failures) ADD_FAILURE() << f;
      EXPECT_TRUE(rep.ok());
    }
  }
  EXPECT_GT(loaded, 5);
  EXPECT_GT(failing, 5);
  EXPECT_GE(tests_files, 1);
}

}  // namespace
}  // namespace syncplc::loadertest
