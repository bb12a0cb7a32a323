// Bad input of any kind gets an error, never a crash: the example project is
// mutated at random (lines deleted, duplicated, swapped, truncated, characters
// replaced) and every variant is loaded. Under ASan/UBSan this also checks for
// memory errors on every error path the mutations reach.
#include <gtest/gtest.h>

#include <fstream>
#include <random>
#include <sstream>

#include "runtime/project/loader.hpp"

namespace syncplc {
namespace {

std::vector<std::string> lines_of(const std::string& path) {
  std::ifstream in(path);
  std::vector<std::string> v;
  for (std::string l; std::getline(in, l);) v.push_back(l);
  return v;
}

std::string join(const std::vector<std::string>& v) {
  std::string s;
  for (const auto& l : v) s += l + "\n";
  return s;
}

TEST(LoaderMutations, EveryVariantLoadsOrReportsErrorsWithPlaces) {
  const auto base = lines_of(std::string(SYNCPLC_SOURCE_DIR) + "/projects/bottle_line/bottle_line.yaml");
  ASSERT_GT(base.size(), 50u);
  ASSERT_TRUE(load_project_text(join(base), "base.yaml").ok());
  std::mt19937_64 rng(20261121);
  const char* junk[] = {"", "-", ":", "{", "]", "%", "\"", "->", "ARRAY[0..", "1e999", "T#", "\t", "&a", "*a", "!!int x"};
  int loaded = 0, rejected = 0;
  for (int iter = 0; iter < 1500; ++iter) {
    auto v = base;
    int edits = 1 + static_cast<int>(rng() % 3);
    for (int e = 0; e < edits; ++e) {
      std::size_t i = rng() % v.size();
      switch (rng() % 6) {
        case 0: v.erase(v.begin() + static_cast<long>(i)); break;
        case 1: v.insert(v.begin() + static_cast<long>(i), v[i]); break;
        case 2: std::swap(v[i], v[rng() % v.size()]); break;
        case 3: v[i] = v[i].substr(0, rng() % (v[i].size() + 1)); break;
        case 4:
          if (!v[i].empty()) v[i][rng() % v[i].size()] = "x:{}[],-#%0.9 "[rng() % 14];
          break;
        case 5: v[i] += junk[rng() % std::size(junk)]; break;
      }
    }
    auto r = load_project_text(join(v), "mutant.yaml");
    if (r.ok()) {
      ++loaded;
      continue;
    }
    ++rejected;
    ASSERT_FALSE(r.diagnostics.empty());
    for (const auto& d : r.diagnostics.list()) {
      ASSERT_EQ(d.loc.file, "mutant.yaml") << d.text();
      ASSERT_GE(d.loc.line, 1) << d.text() << "\n" << join(v);
      ASSERT_FALSE(d.message.empty());
    }
  }
  EXPECT_GT(rejected, 500);  // most mutations break something ...
  EXPECT_GT(loaded, 10);     // ... and some (comments, blank lines) do not
}

}  // namespace
}  // namespace syncplc
