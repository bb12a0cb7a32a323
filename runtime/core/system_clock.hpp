// Several programs on one virtual time line: the nodes of a distributed
// system simulated in one process (`syncplc sim SYSTEM.yaml`, docs/dds.md,
// "In virtual time"). Each node keeps its own VirtualClock (its tasks, its
// grid, its online change); this one steps them together, instant by
// instant: at each instant every node runs its scans of that instant, the
// nodes in their fixed order. What one node sends another is seen no
// earlier than the publisher's next grid point (runtime/io/dds/virtual_bus),
// so the order within an instant changes nothing, and a run is bit for bit
// the same for the same projects and seed.
#pragma once

#include <cstdint>
#include <functional>
#include <vector>

#include "runtime/core/virtual_clock.hpp"

namespace syncplc {

class SystemClock {
 public:
  explicit SystemClock(std::vector<VirtualClock*> nodes) : nodes_(std::move(nodes)) {}
  // Runs every scan of every node that starts before t (inclusive: at or before t).
  void run_until(std::int64_t t, bool inclusive = false);
  std::int64_t now() const { return now_; }
  // Called after every node has run its scans of instant t.
  void on_time_point(std::function<void(std::int64_t t)> f) { observer_ = std::move(f); }

 private:
  std::vector<VirtualClock*> nodes_;
  std::function<void(std::int64_t)> observer_;
  std::int64_t now_ = 0;
};

}  // namespace syncplc
