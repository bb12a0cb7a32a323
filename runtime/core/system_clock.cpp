#include "runtime/core/system_clock.hpp"

#include <algorithm>

namespace syncplc {

void SystemClock::run_until(std::int64_t t, bool inclusive) {
  for (;;) {
    std::int64_t next = VirtualClock::kNever;
    for (const VirtualClock* c : nodes_) next = std::min(next, c->next_event());
    if (next == VirtualClock::kNever || (inclusive ? next > t : next >= t)) break;
    for (VirtualClock* c : nodes_) c->run_until(next, true);
    now_ = next;
    if (observer_) observer_(next);
  }
}

}  // namespace syncplc
