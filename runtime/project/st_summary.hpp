// How a project's Structured Text runs (syncplc check prints it): how much
// there is, and how much of it runs as native code (docs/st.md, "How
// compiled ST runs").
#pragma once

#include <cstddef>

namespace syncplc {

struct StSummary {
  std::size_t files = 0;           // sources:
  std::size_t pous = 0;            // FUNCTIONs, FUNCTION_BLOCKs and PROGRAMs compiled
  std::size_t native_pous = 0;     // of them, run as native code
  std::size_t register_loops = 0;  // loops of native code that keep cells in registers
  bool native_asked = true;        // project: st_engine is native (the default)
};

}  // namespace syncplc
