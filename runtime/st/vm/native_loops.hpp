// Which loops of a POU keep cells in machine registers when compiled to
// native code (native_x64.cpp), and which cells: the analysis, apart from
// the emitter, over the instructions alone (plain data out).
//
// A loop qualifies when it is innermost (no other backward jump in it),
// every instruction in it has a native template (nothing leaves it for the
// interpreter but the rare paths, around which the emitter writes the
// registers back and reads them again), and no jump from outside lands
// inside it but at its head. Its cells are classed by how the loop's
// instructions use them: as LREAL values only (a vector register), as
// integers or raw bits only (a general register), or both or as part of an
// array the loop indexes (left in the frame). The most used win the
// registers there are.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "runtime/st/vm/code.hpp"

namespace syncplc::st::vm {

struct RegisterLoop {
  std::uint32_t head = 0, end = 0;  // the body is [head, end]; end holds the backward jump
  std::vector<std::uint32_t> reals;  // cells kept in vector registers (LREAL)
  std::vector<std::uint32_t> words;  // cells kept in general registers (their 64 bits)
};

// `templated` says whether native code has a template for an instruction.
std::vector<RegisterLoop> register_loops(const Module& m, const CompiledPou& p,
                                         bool (*templated)(const Module&, const Insn&), std::size_t max_reals,
                                         std::size_t max_words);

}  // namespace syncplc::st::vm
