// NURBS_PATH (fblocks/contour/nurbs_path.cpp): the NURBS interpolator of
// paper 003 section 4.3, eqs. (7)-(8), with the speed-controlled parameter
// update of Yeh & Hsu (1999). See docs/motion/nurbs.md.
#pragma once

#include "runtime/core/block.hpp"

namespace syncplc {

void register_nurbs_blocks(BlockRegistry& registry);

}  // namespace syncplc
