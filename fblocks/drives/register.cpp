#include "fblocks/drives/drives.hpp"
#include "fblocks/library.hpp"

namespace syncplc {

void register_drive_blocks(BlockRegistry& r) { drives::register_cia402_drive(r); }

}  // namespace syncplc
