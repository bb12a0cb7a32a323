// Internal: the registration functions of the drive blocks in
// fblocks/drives, called by register_drive_blocks().
#pragma once

#include "runtime/core/block.hpp"

namespace syncplc::drives {

inline constexpr const char* kCategory = "Drives";

void register_cia402_drive(BlockRegistry& r);  // cia402_drive.cpp: CIA402_DRIVE

}  // namespace syncplc::drives
