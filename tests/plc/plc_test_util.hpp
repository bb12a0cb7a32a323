// What the PLC-instance tests share: a project file written for a test, the
// options of a quiet in-memory PLC, and a wait for a condition.
#pragma once

#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <string>
#include <thread>

#include "runtime/plc/plc.hpp"
#include "tests/realtime/quiet_options.hpp"
#include "tests/support/test_blocks.hpp"

namespace syncplc::plc::testing {

// `text` as the file `name` in this process's own temporary directory.
inline std::string write_project(const std::string& name, const std::string& text) {
  const auto dir = std::filesystem::temp_directory_path() / ("syncplc-plc-" + std::to_string(getpid()));
  std::filesystem::create_directories(dir);
  const auto path = dir / name;
  std::ofstream(path, std::ios::trunc) << text;
  return path.string();
}

// A PLC of `project` with the test blocks, no database file, no HTTP, quiet tasks.
inline PlcOptions options(const std::string& project) {
  PlcOptions o;
  o.project = project;
  o.db = ":memory:";
  o.load.blocks = &syncplc::testing::test_blocks();
  o.runner = quiet_options();
  o.http.enabled = false;
  return o;
}

// Polls f until it holds; false once `limit` passed (a hang guard, not a bound).
template <class F>
bool eventually(F f, std::chrono::milliseconds limit = std::chrono::milliseconds(20000)) {
  const auto until = std::chrono::steady_clock::now() + limit;
  while (!f()) {
    if (std::chrono::steady_clock::now() > until) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  return true;
}

}  // namespace syncplc::plc::testing
