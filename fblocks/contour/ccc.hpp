// Cross-coupled contour control (fblocks/contour/ccc_*.cpp): CCC_2AXIS, the
// contour-error estimate and CCC law of paper 003 section 4.3 on Yeh & Hsu's
// contour-error vector. See docs/motion/contouring.md.
#pragma once

#include "runtime/core/block.hpp"

namespace syncplc {

void register_ccc_blocks(BlockRegistry& registry);  // ccc_block.cpp

}  // namespace syncplc
