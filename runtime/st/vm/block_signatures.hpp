// The built-in blocks Structured Text may instance as function blocks, as the
// checker sees them (BlockSignature, types.hpp): every registered block type,
// a generic one at its default type (CTU at INT), with its parameters (their
// defaults and ranges) and its array pins (sized by a parameter), except the
// type conversions (ST writes those as functions) and the generic types
// without a default. A block's links (an MC block's `Axis`) follow its pins
// as VAR_IN_OUT references (`ref_target` set: AXIS_REF, a list link
// ARRAY[1..n] OF AXIS_REF). The pins and parameters keep the registry's
// order, so an index into one is an index into the other; where a pin's cells are in
// an instance's frame: builtin_layout (var_path.hpp).
#pragma once

#include <vector>

#include "runtime/core/block.hpp"
#include "runtime/st/types.hpp"

namespace syncplc::st::vm {

std::vector<BlockSignature> block_signatures(const BlockRegistry& registry);

// IEC 61131-3's typed counters (3rd edition, table 45): CTU_INT, CTU_DINT,
// CTU_LINT, CTU_UDINT, CTU_ULINT, and the same of CTD and CTUD, are the
// generic counter at that type; block_signatures lists them beside CTU.
// The registered block of an ST FB type's name and the type its generic
// pins have (the default type for the plain name); null when none.
const BlockTypeInfo* builtin_block(const BlockRegistry& registry, std::string_view name, IecType* datatype);

// The ST type of a reference to an instance of block type `target_type`
// (a link's target): AXIS_REF for MC_AXIS (PLCopen's name), else
// `<target_type>_REF`.
std::string ref_type_name(std::string_view target_type);

// A parameter's value between the checker's form (durations in
// nanoseconds, BOOL 0/1) and a Cell of the parameter's type.
Cell param_cell(IecType type, const ConstValue& v);
ConstValue param_value(IecType type, Cell c);

}  // namespace syncplc::st::vm
