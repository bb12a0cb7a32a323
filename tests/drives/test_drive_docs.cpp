// The YAML examples of docs/drives.md: each "# file: NAME" project loads and
// each "# tests: NAME" scan-cycle test passes, so the page's example of
// CIA402_DRIVE cannot drift from what the block does.
#include <gtest/gtest.h>

#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <map>
#include <string>
#include <vector>

#include "runtime/project/loader.hpp"
#include "runtime/project/scan_test.hpp"

namespace syncplc {
namespace {

struct Example {
  std::string kind, name, text;
  int line = 0;
};

std::vector<Example> yaml_examples(const std::string& path) {
  std::ifstream in(path);
  std::vector<Example> out;
  std::string line;
  bool inside = false;
  for (int n = 1; std::getline(in, line); ++n) {
    if (!inside && line == "```yaml") {
      out.push_back(Example{});
      out.back().line = n;
      inside = true;
    } else if (inside && line == "```") {
      inside = false;
    } else if (inside) {
      Example& e = out.back();
      for (const char* k : {"file", "tests"})
        if (e.text.empty() && line.rfind(std::string("# ") + k + ": ", 0) == 0) {
          e.kind = k;
          e.name = line.substr(std::string(k).size() + 4);
        }
      e.text += line + "\n";
    }
  }
  return out;
}

TEST(DriveDocs, TheExamplesLoadAndTheirScanTestsPass) {
  const std::string doc = SYNCPLC_SOURCE_DIR "/docs/drives.md";
  const auto examples = yaml_examples(doc);
  ASSERT_GE(examples.size(), 2u) << doc;
  const auto dir = std::filesystem::temp_directory_path() / ("syncplc-drive-docs-" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  std::map<std::string, std::string> projects;
  int tests = 0;
  for (const auto& e : examples) {
    SCOPED_TRACE(doc + ":" + std::to_string(e.line));
    ASSERT_FALSE(e.kind.empty()) << "a yaml example starts with # file: or # tests:";
    const std::string path = (dir / (e.kind == "file" ? e.name : "tests-" + std::to_string(++tests) + ".yaml")).string();
    std::ofstream(path) << e.text;
    if (e.kind == "file") {
      const LoadResult r = load_project(path);
      for (const auto& d : r.diagnostics.sorted()) ADD_FAILURE() << d.text();
      EXPECT_TRUE(r.ok());
      projects[e.name] = path;
    } else {
      ASSERT_TRUE(projects.count(e.name)) << "no project example named " << e.name;
      const ScanTestReport rep = run_scan_tests(projects[e.name], path);
      for (const auto& d : rep.diagnostics.sorted()) ADD_FAILURE() << d.text();
      for (const auto& c : rep.cases)
        for (const auto& f : c.failures) ADD_FAILURE() << c.name << ": " << f;
      EXPECT_TRUE(rep.ok());
      EXPECT_GE(rep.cases.size(), 2u);
    }
  }
  EXPECT_GE(tests, 1);
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace syncplc
