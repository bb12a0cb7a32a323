// The ST test corpus (tests/st/corpus) as the parser's and the checker's
// corpus tests read it: a directory's .st files in name order, a file's
// text, and the comparison with a sibling expected file (.expected, .errors)
// that SYNCPLC_ST_UPDATE=1 rewrites instead (review the diff).
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

namespace syncplc::st::corpus {

namespace fs = std::filesystem;

inline const fs::path& root() {
  static const fs::path p = fs::path(SYNCPLC_SOURCE_DIR) / "tests/st/corpus";
  return p;
}

inline std::string read(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

inline std::vector<fs::path> sources(const std::string& dir) {
  std::vector<fs::path> out;
  for (const auto& e : fs::directory_iterator(root() / dir))
    if (e.path().extension() == ".st") out.push_back(e.path());
  std::sort(out.begin(), out.end());
  return out;
}

inline bool updating() { return std::getenv("SYNCPLC_ST_UPDATE") != nullptr; }

// Compares `actual` with the sibling file `ext` of `source`, or writes it when updating.
inline void check_against(const fs::path& source, const std::string& ext, const std::string& actual) {
  fs::path expected = source;
  expected.replace_extension(ext);
  if (updating()) {
    std::ofstream(expected, std::ios::binary) << actual;
    return;
  }
  ASSERT_TRUE(fs::exists(expected)) << expected << " missing (SYNCPLC_ST_UPDATE=1 writes it)";
  EXPECT_EQ(actual, read(expected)) << source;
}

}  // namespace syncplc::st::corpus
