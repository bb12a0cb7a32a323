// Helpers for the project-loader tests: load a project written as a raw
// string, list its diagnostics as "file:line:col: message" lines, and a test
// block library with parameters (the builtin IEC blocks take none).
#pragma once

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "fblocks/library.hpp"
#include "runtime/project/loader.hpp"

namespace syncplc::loadertest {

// Drops the newline that follows R"( so that line 1 of the project is the
// first line written after it.
inline std::string yaml(const char* text) {
  std::string s(text);
  if (!s.empty() && s.front() == '\n') s.erase(s.begin());
  return s;
}

inline LoadResult load(const char* text, const LoadOptions& o = {}) {
  return load_project_text(yaml(text), "p.yaml", o);
}

// Every diagnostic as "file:line:col: message", sorted by place.
inline std::vector<std::string> errors(const LoadResult& r) {
  std::vector<std::string> v;
  for (const auto& d : r.diagnostics.sorted()) v.push_back(d.text());
  return v;
}
inline std::vector<std::string> errors(const char* text, const LoadOptions& o = {}) { return errors(load(text, o)); }

inline std::string joined(const LoadResult& r) {
  std::string s;
  for (const auto& e : errors(r)) s += e + "\n";
  return s;
}

#define ASSERT_LOADS(r) ASSERT_TRUE((r).ok()) << ::syncplc::loadertest::joined(r)

// An error at exactly this place whose message contains `gist`.
inline ::testing::Matcher<const std::vector<std::string>&> has_error(const std::string& place, const std::string& gist) {
  using namespace ::testing;
  return Contains(AllOf(StartsWith(place + ": "), HasSubstr(gist)));
}

// The builtin IEC blocks plus two blocks with parameters:
//   GAIN (IN LREAL -> OUT LREAL), params K (LREAL m/s, default 1, 0..100) and
//        N (DINT, default 0); OUT := IN * K.
//   NEED (IN LREAL -> OUT LREAL), mandatory parameter P (INT).
const BlockRegistry& param_blocks();

// The GAIN instance's K as the block received it.
double gain_k(const Program& p, const std::string& instance);

// Writes `text` to `name` in a fresh temporary directory per test program;
// returns the path.
std::string temp_file(const std::string& name, const std::string& text);
// That directory, with a trailing '/'.
std::string temp_root();

}  // namespace syncplc::loadertest
