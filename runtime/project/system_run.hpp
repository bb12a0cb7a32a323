// Every node of an opened system (system.hpp) on one virtual time line
// (runtime/core/system_clock.hpp), each node's motion metrics (its
// `metrics:` section) sampled after its scans: what `syncplc sim` and
// `syncplc test` run, a project alone as a system of one node.
#pragma once

#include <memory>
#include <vector>

#include "runtime/core/system_clock.hpp"
#include "runtime/project/metrics.hpp"
#include "runtime/project/system.hpp"

namespace syncplc {

class SystemRun {
 public:
  // `s` outlives the run; its nodes' programs are opened (open_system).
  explicit SystemRun(LoadedSystem& s);
  SystemRun(const SystemRun&) = delete;
  SystemRun& operator=(const SystemRun&) = delete;

  SystemClock& clock() { return *clock_; }
  const VirtualClock& node_clock(std::size_t node) const { return *clocks_[node]; }
  const MotionMetrics& metrics(std::size_t node) const { return *metrics_[node]; }

 private:
  std::vector<std::unique_ptr<VirtualClock>> clocks_;
  std::vector<std::unique_ptr<MotionMetrics>> metrics_;
  std::unique_ptr<SystemClock> clock_;
};

}  // namespace syncplc
