// A variable of a POU instance by its path, as users write it everywhere a
// tag or a pin is named: `speed`, `fb.q`, `axes[2].pos`, `grid[1, 3]`,
// `s.field`, `w.3` (a bit). Resolved once (at load, or when a client names
// it) to a cell of the instance's frame and the type there.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

#include "runtime/st/vm/code.hpp"

namespace syncplc::st::vm {

struct VarRef {
  std::uint32_t at = 0;        // first cell in the frame
  const Type* type = nullptr;  // BOOL for a bit
  int bit = -1;                // a bit of the cell at `at`
  // A VAR_IN_OUT or VAR_EXTERNAL: `at` holds the reference, not the value.
  bool reference = false;
};

// Resolves `path` in POU `pou` of `m`; on failure nullopt and *error says
// which part is unknown (with a suggestion when one is close).
std::optional<VarRef> resolve_path(const Module& m, std::uint32_t pou, std::string_view path, std::string* error);

// Cells a value of type t takes in a frame (as the code generator lays it out).
std::uint32_t frame_cells_of(const Module& m, const Type* t);

}  // namespace syncplc::st::vm
