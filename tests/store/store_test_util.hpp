// Helpers of the store tests: a fresh directory per test.
#pragma once

#include <unistd.h>

#include <filesystem>
#include <string>

namespace syncplc::store::testing {

// An empty directory of this process: /tmp/syncplc-store-<pid>/<name>.
inline std::string fresh_dir(const std::string& name) {
  namespace fs = std::filesystem;
  const fs::path dir = fs::temp_directory_path() / ("syncplc-store-" + std::to_string(getpid())) / name;
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir.string();
}

}  // namespace syncplc::store::testing
