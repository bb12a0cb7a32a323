// A compiled POU as text, one instruction a line: what the code generator
// made of a source, for tests and for counting what a loop costs per
// iteration (docs/benchmarks.md section 17). Load path only (allocates).
#pragma once

#include <cstdint>
#include <string>

#include "runtime/st/vm/code.hpp"

namespace syncplc::st::vm {

// "  12  ADD_F64  a=3 b=4 c=5 d=0  (line 7)" for every instruction of POU `pou`.
std::string listing(const Module& m, std::uint32_t pou);

}  // namespace syncplc::st::vm
