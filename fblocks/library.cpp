#include "fblocks/library.hpp"

#include "fblocks/contour/ccc.hpp"
#include "fblocks/contour/nurbs.hpp"

namespace syncplc {

const BlockRegistry& builtin_blocks() {
  static const BlockRegistry registry = [] {
    BlockRegistry r;
    register_iec_blocks(r);
    register_motion_blocks(r);
    register_drive_blocks(r);
    register_plcopen_blocks(r);
    register_ccc_blocks(r);
    register_nurbs_blocks(r);
    return r;
  }();
  return registry;
}

}  // namespace syncplc
