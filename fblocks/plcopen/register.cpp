#include "fblocks/library.hpp"
#include "fblocks/plcopen/plcopen.hpp"

namespace syncplc {

void register_plcopen_blocks(BlockRegistry& r) {
  plcopen::register_axis(r);
  plcopen::register_admin_blocks(r);
  plcopen::register_move_blocks(r);
  plcopen::register_sim_servo(r);
  plcopen::register_group_move(r);
  plcopen::register_gear_blocks(r);
  plcopen::register_cam_blocks(r);
}

}  // namespace syncplc
