#include "runtime/project/system_run.hpp"

namespace syncplc {

SystemRun::SystemRun(LoadedSystem& s) {
  std::vector<VirtualClock*> order;
  for (auto& n : s.nodes) {
    Program& p = *n.loaded.program;
    clocks_.push_back(std::make_unique<VirtualClock>(p));
    metrics_.push_back(std::make_unique<MotionMetrics>(n.loaded.metrics));
    VirtualClock& c = *clocks_.back();
    MotionMetrics& m = *metrics_.back();
    if (m.enabled()) c.on_time_point([&p, &c, &m](std::int64_t t) { m.sample(p, c.image_access(), t, c.scans(m.task())); });
    order.push_back(&c);
  }
  clock_ = std::make_unique<SystemClock>(std::move(order));
}

}  // namespace syncplc
