// Scan-cycle tests written by users (`syncplc test PROJECT TESTS.yaml`).
//
//   cases:
//     - name: lamp lights 500 ms after start
//       seed: 7                       # optional
//       steps:
//         - at: 0ms                   # or  cycle: 12  (task: fast; default the first task)
//           set: {start: true}        # tags, instance.pin, driver.channel
//         - at: 501ms
//           expect: {lamp: true, t1.ET: {value: 500ms, tolerance: 1ms}}
//
// An expectation may be a bound instead of a value: {max: 0.06}, {min: 2},
// or both. `metrics.track_rsme`, `metrics.sync_rsme`,
// `metrics.max_abs_error[i]` and `metrics.max_abs_sync_error[i]` are the
// motion metrics (paper 000 eqs. 26-27) of the project's `metrics:
// axis_errors`, accumulated from the start of the case.
//
// A system file (system.hpp) in place of the project runs every node of a
// distributed project together on its simulated bus: targets then start
// with their node (axis1.ref_ok, master.metrics.track_rsme) and `task:` is
// node.task.
//
// Each case starts from a fresh load of the project and runs in virtual time.
// `set` at time t is applied before any scan released at t; `expect` at t is
// checked after every scan released at or before t has run. `cycle: n` of a
// task means the planned release of its n-th scan (from 0).
#pragma once

#include <ostream>
#include <string>
#include <vector>

#include "runtime/project/loader.hpp"

namespace syncplc {

struct ScanTestCaseResult {
  std::string name;
  bool passed = false;
  std::vector<std::string> failures;  // each with its place in the tests file
  double virtual_seconds = 0;
  std::uint64_t steps_checked = 0;
};

struct ScanTestReport {
  std::vector<ScanTestCaseResult> cases;
  Diagnostics diagnostics;  // errors in the tests file or the project: nothing ran
  bool ok() const;          // loaded and every case passed
  std::size_t failed() const;
};

ScanTestReport run_scan_tests(const std::string& project_path, const std::string& tests_path,
                              const LoadOptions& options = {});
void write_junit(std::ostream& os, const std::string& suite, const ScanTestReport& r);

}  // namespace syncplc
