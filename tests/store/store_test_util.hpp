// Helpers of the store tests: a fresh directory per test.
#pragma once

#include <unistd.h>

#include <cstdio>
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

// What the sqlite3 shell (Debian's, read-only) prints for `sql` on `db`,
// stderr included, without the trailing newlines.
inline std::string sqlite_shell(const std::string& db, const std::string& sql) {
  const std::string cmd = "sqlite3 -readonly '" + db + "' \"" + sql + "\" 2>&1";
  std::string out;
  if (FILE* p = popen(cmd.c_str(), "r")) {
    char buf[4096];
    while (std::size_t n = fread(buf, 1, sizeof buf, p)) out.append(buf, n);
    pclose(p);
  }
  while (!out.empty() && out.back() == '\n') out.pop_back();
  return out;
}

}  // namespace syncplc::store::testing
