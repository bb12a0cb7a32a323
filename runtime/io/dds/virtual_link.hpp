// The `dds` driver's link in virtual time (docs/dds.md, "In virtual time"):
// samples go over the system's VirtualBus instead of Cyclone DDS, in the
// scan itself (the bus is memory the clock's one thread owns). The node's
// injection applies here too: a sample is lost with probability
// inject.loss (a seeded SimRandom per subscription: bit for bit the same
// run for the same project and seed) and seen inject.delay later.
#pragma once

#include <memory>
#include <vector>

#include "runtime/core/sim_random.hpp"
#include "runtime/io/dds/link.hpp"
#include "runtime/io/dds/subscription_intake.hpp"
#include "runtime/io/dds/virtual_bus.hpp"

namespace syncplc::dds {

class VirtualLink final : public Link {
 public:
  // period_ns: the driver's task's; seed: the driver's (DriverSetup::seed).
  VirtualLink(const DdsSettings& s, std::shared_ptr<VirtualBus> bus, std::int64_t period_ns, std::uint64_t seed)
      : Link(s), bus_(std::move(bus)), period_ns_(period_ns), seed_(seed) {}
  ~VirtualLink() override { close(); }

  bool open(std::string* error) override;
  void close() noexcept override;
  void poll(std::int64_t now_ns) noexcept override;
  void hand_over() noexcept override;

 private:
  struct Sub {
    int id = -1;
    SubscriptionIntake intake;
    SimRandom rng{1};
  };
  std::shared_ptr<VirtualBus> bus_;
  std::int64_t period_ns_;
  std::uint64_t seed_;
  std::vector<int> pub_ids_;
  std::vector<Sub> sub_state_;
  std::vector<std::uint64_t> last_sent_;
  std::vector<bool> sent_any_;
};

}  // namespace syncplc::dds
