// Internal: the registration functions of the motion block families in
// fblocks/motion, one per file, called by register_motion_blocks().
#pragma once

#include "runtime/core/block.hpp"

namespace syncplc::motion {

inline constexpr const char* kCategory = "Motion";

// Most samples (or segments) one scan catches up after skipped releases (10 s
// at 1 ms): a scan's execution time stays bounded, and beyond it the block's
// output falls behind the time grid (NONLINEAR_FILTER, TRANSIENT_SYNC,
// STEP_RAMP_SEQUENCE).
inline constexpr int kMaxCatchUp = 10000;

void register_taylor_estimator(BlockRegistry& r);      // taylor_estimator.cpp
void register_reference_generators(BlockRegistry& r);  // reference_generators.cpp
// NONLINEAR_FILTER (nonlinear_filter.cpp): paper 004, Section II.
void register_nonlinear_filter(BlockRegistry& r);
void register_sync_controller(BlockRegistry& r);   // sync_controller.cpp: SYNC_CONTROLLER
void register_pid_controllers(BlockRegistry& r);   // pid.cpp: PD_CONTROLLER, PID
// TRANSIENT_SYNC (transient_sync_info.cpp, transient_sync.cpp): paper 004, Section III.
void register_transient_sync(BlockRegistry& r);
// OPTIMAL_COMPENSATOR (optimal_compensator.cpp): the dropout compensator paper 003 compares against.
void register_optimal_compensator(BlockRegistry& r);

}  // namespace syncplc::motion
