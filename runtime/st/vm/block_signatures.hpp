// The built-in blocks Structured Text may instance as function blocks, as the
// checker sees them (BlockSignature, types.hpp): every registered block type
// whose pins have no array length, a generic one at its default type (CTU at
// INT), except the type conversions (ST writes those as functions) and the
// generic types without a default. The pins keep the
// registry's order, which is how the code generator and var_path.cpp find a
// pin's cell (1 + its index after the Block* cell).
#pragma once

#include <vector>

#include "runtime/core/block.hpp"
#include "runtime/st/types.hpp"

namespace syncplc::st::vm {

std::vector<BlockSignature> block_signatures(const BlockRegistry& registry);

}  // namespace syncplc::st::vm
