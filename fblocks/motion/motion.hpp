// Internal: the registration functions of the motion block families in
// fblocks/motion, one per file, called by register_motion_blocks().
#pragma once

#include "runtime/core/block.hpp"

namespace syncplc::motion {

inline constexpr const char* kCategory = "Motion";

// NONLINEAR_FILTER (nonlinear_filter.cpp): paper 004, Section II.
void register_nonlinear_filter(BlockRegistry& r);
// TRANSIENT_SYNC (transient_sync.cpp): paper 004, Section III.
void register_transient_sync(BlockRegistry& r);

}  // namespace syncplc::motion
