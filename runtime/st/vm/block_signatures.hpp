// The built-in blocks Structured Text may instance as function blocks, as the
// checker sees them (BlockSignature, types.hpp): every registered block type,
// a generic one at its default type (CTU at INT), with its parameters (their
// defaults and ranges) and its array pins (sized by a parameter), except the
// type conversions (ST writes those as functions) and the generic types
// without a default. The pins and parameters keep the registry's order, so
// an index into one is an index into the other; where a pin's cells are in
// an instance's frame: builtin_layout (var_path.hpp).
#pragma once

#include <vector>

#include "runtime/core/block.hpp"
#include "runtime/st/types.hpp"

namespace syncplc::st::vm {

std::vector<BlockSignature> block_signatures(const BlockRegistry& registry);

// A parameter's value between the checker's form (durations in
// nanoseconds, BOOL 0/1) and a Cell of the parameter's type.
Cell param_cell(IecType type, const ConstValue& v);
ConstValue param_value(IecType type, Cell c);

}  // namespace syncplc::st::vm
