// Registers the IEC 61131-3 standard blocks (and the execution-control and
// diagnostic helpers that ship with them).
#include "fblocks/iec/common.hpp"
#include "fblocks/library.hpp"

namespace syncplc {

void register_iec_blocks(BlockRegistry& registry) {
  iec::register_timers(registry);
  iec::register_edges(registry);
  iec::register_counters(registry);
  iec::register_bistables(registry);
  iec::register_arithmetic(registry);
  iec::register_comparison(registry);
  iec::register_selection(registry);
  iec::register_logic(registry);
  iec::register_unit_delay(registry);
  iec::register_burn(registry);
  iec::register_conversions(registry);
}

}  // namespace syncplc
