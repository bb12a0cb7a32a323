// A variable of a POU instance by its path, as users write it everywhere a
// tag or a pin is named: `speed`, `fb.q`, `axes[2].pos`, `grid[1, 3]`,
// `s.field`, `w.3` (a bit). Resolved once (at load, or when a client names
// it) to a cell of the instance's frame and the type there.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "runtime/st/vm/code.hpp"

namespace syncplc::st::vm {

struct VarRef {
  std::uint32_t at = 0;        // first cell in the frame
  const Type* type = nullptr;  // BOOL for a bit
  int bit = -1;                // a bit of the cell at `at`
  // A VAR_IN_OUT or VAR_EXTERNAL: `at` holds the reference, not the value.
  bool reference = false;
  // The path runs through a VAR_TEMP (set again at every call) or a VAR
  // CONSTANT (its declared value is compiled into the code).
  bool temp = false;
  bool constant = false;
};

// Resolves `path` in POU `pou` of `m`; on failure nullopt and *error says
// which part is unknown (with a suggestion when one is close).
std::optional<VarRef> resolve_path(const Module& m, std::uint32_t pou, std::string_view path, std::string* error);

// Cells a value of type t takes in a frame (as the code generator lays it out).
std::uint32_t frame_cells_of(const Module& m, const Type* t);

// Where a built-in block instance's pins are in a frame, from its cell (the
// Block*, at 0): the one layout the code generator, var_path and the
// instance's binding share. Each pin takes its cells in declaration order,
// an array pin one per element (pin_at[k] its first, the cell
// Block::bind_pins points pin k at). A link pin (a VAR_IN_OUT AXIS_REF, or
// ARRAY OF AXIS_REF) takes one reference cell, then per element a cell
// holding the Block* it was last linked to (LINK_BLOCK compares it).
struct BuiltinLayout {
  std::vector<std::uint32_t> pin_at;
  std::uint32_t cells = 1;  // the Block* cell and every pin's
};
BuiltinLayout builtin_layout(const FbType& fb);

}  // namespace syncplc::st::vm
