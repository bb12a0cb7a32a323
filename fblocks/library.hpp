// The block library shipped with syncplc.
#pragma once

#include "runtime/core/block.hpp"

namespace syncplc {

// IEC 61131-3 standard blocks (fblocks/iec): timers, edges, counters,
// bistables, arithmetic, comparison, selection, logic, and the one-scan delay.
void register_iec_blocks(BlockRegistry& registry);

// The motion blocks from the papers (fblocks/motion): nonlinear filter,
// transient-time synchronizer, Taylor estimator, synchronous and PD/PID
// controllers, reference generators.
void register_motion_blocks(BlockRegistry& registry);

// The drive profiles (fblocks/drives): CIA402_DRIVE, the master side of a
// CiA 402 drive's state machine.
void register_drive_blocks(BlockRegistry& registry);

// PLCopen Motion Control Part 1 (fblocks/plcopen): the axis MC_AXIS, the
// MC_* blocks that work on it, and SIM_SERVO, a simulated drive.
void register_plcopen_blocks(BlockRegistry& registry);

// Every block type that ships with syncplc, registered once.
const BlockRegistry& builtin_blocks();

}  // namespace syncplc
