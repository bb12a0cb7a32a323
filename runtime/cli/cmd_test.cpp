#include <fstream>
#include <iostream>

#include "runtime/cli/commands.hpp"
#include "runtime/project/scan_test.hpp"

namespace syncplc::cli {

int cmd_test(const std::string& project, const std::string& tests, const std::string& junit) {
  auto rep = run_scan_tests(project, tests);
  if (!rep.diagnostics.empty()) {
    for (const auto& d : rep.diagnostics.sorted()) std::cerr << d.text() << "\n";
    std::cerr << "syncplc: " << rep.diagnostics.size() << " error(s); no test ran\n";
    return kExitInvalid;
  }
  for (const auto& c : rep.cases) {
    std::cout << (c.passed ? "[  PASS  ] " : "[  FAIL  ] ") << c.name << "  (" << c.steps_checked << " checks, "
              << c.virtual_seconds << " s virtual)\n";
    for (const auto& f : c.failures) std::cout << "    " << f << "\n";
  }
  std::size_t failed = rep.failed();
  std::cout << (rep.cases.size() - failed) << " passed, " << failed << " failed\n";
  if (!junit.empty()) {
    std::ofstream out(junit, std::ios::trunc);
    if (!out) {
      std::cerr << "syncplc: cannot write " << junit << "\n";
      return kExitInvalid;
    }
    write_junit(out, project, rep);
  }
  return failed == 0 ? kExitOk : kExitTestFailed;
}

}  // namespace syncplc::cli
