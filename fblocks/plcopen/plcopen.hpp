// Internal: the registration functions of the PLCopen Motion Control blocks
// in fblocks/plcopen, one per file, called by register_plcopen_blocks()
// (fblocks/library.hpp).
#pragma once

#include "runtime/core/block.hpp"

namespace syncplc::plcopen {

inline constexpr const char* kCategory = "PLCopen motion";

void register_axis(BlockRegistry& r);         // axis_block.cpp: MC_AXIS
void register_admin_blocks(BlockRegistry& r); // mc_admin.cpp: MC_Power, MC_Reset, MC_Read*, MC_SetPosition, MC_*Parameter
void register_move_blocks(BlockRegistry& r);  // mc_move.cpp: MC_Move*, MC_Halt, MC_Stop, MC_Home
void register_sim_servo(BlockRegistry& r);    // sim_servo.cpp: SIM_SERVO
void register_group_move(BlockRegistry& r);   // mc_group.cpp: MC_GroupMoveAbsolute
void register_gear_blocks(BlockRegistry& r);  // mc_gear.cpp: MC_GearIn, MC_GearOut, MC_CamOut
void register_cam_blocks(BlockRegistry& r);   // mc_cam.cpp: MC_CamIn

}  // namespace syncplc::plcopen
