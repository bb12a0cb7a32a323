#include "fblocks/library.hpp"
#include "fblocks/motion/motion.hpp"

namespace syncplc {

void register_motion_blocks(BlockRegistry& r) {
  motion::register_taylor_estimator(r);
  motion::register_reference_generators(r);
  motion::register_nonlinear_filter(r);
  motion::register_sync_controller(r);
  motion::register_pid_controllers(r);
  motion::register_transient_sync(r);
  motion::register_optimal_compensator(r);
}

}  // namespace syncplc
