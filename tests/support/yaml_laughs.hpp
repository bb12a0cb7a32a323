// The "billion laughs" project the YAML limits are tested with
// (tests/project/test_yaml_limits.cpp, tests/cli/test_cli_yaml_limits.cpp).
#pragma once

#include <string>

namespace syncplc::testing {

// Eight levels of ten aliases each: about 600 bytes, 10^8 nodes expanded.
// Line 1 a task; lines 2..9 the anchors l0 .. l7.
inline std::string laughs() {
  std::string s = "tasks: [{name: main, period: 1ms}]\n";
  s += "l0: &l0 [lol, lol, lol, lol, lol, lol, lol, lol, lol, lol]\n";
  for (int i = 1; i < 8; ++i) {
    const std::string a = "*l" + std::to_string(i - 1);
    s += "l" + std::to_string(i) + ": &l" + std::to_string(i) + " [" + a;
    for (int k = 1; k < 10; ++k) s += ", " + a;
    s += "]\n";
  }
  return s;
}

}  // namespace syncplc::testing
