// Loading helpers for tests that run projects with the test block types.
#pragma once

#include <gtest/gtest.h>

#include <memory>
#include <string>

#include "runtime/project/loader.hpp"
#include "tests/support/image_key.hpp"
#include "tests/support/test_blocks.hpp"

namespace syncplc {

// Loads a project text with the test block types; a load error fails the test.
// The whole result (the program, its Modbus settings and metrics).
inline LoadResult load_test_result(const std::string& yaml) {
  LoadOptions o;
  o.blocks = &testing::test_blocks();
  auto r = load_project_text(yaml, "test.yaml", o);
  for (const auto& d : r.diagnostics.list()) ADD_FAILURE() << d.text();
  return r;
}

inline std::unique_ptr<Program> load_test_project(const std::string& yaml) { return std::move(load_test_result(yaml).program); }

inline Cell& tag_cell(Program& p, const std::string& name) {
  auto r = p.resolve(name);
  EXPECT_TRUE(r) << name;
  return *p.live_cell(*r, testing::image_key());
}

}  // namespace syncplc
