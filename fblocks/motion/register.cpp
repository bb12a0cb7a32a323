#include "fblocks/library.hpp"
#include "fblocks/motion/motion.hpp"

namespace syncplc {

void register_motion_blocks(BlockRegistry& r) {
  (void)r;
}

}  // namespace syncplc
