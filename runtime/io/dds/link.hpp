// What the `dds` driver exchanges samples through (docs/dds.md): the real
// link on Cyclone DDS (dds_link.hpp, its own threads) in real time, or the
// simulated one on an in-process bus (virtual_link.hpp) in virtual time. The
// driver sees only the hand-over buffers: a publication's newest values
// (PublicationCells) and a subscription's newest sample (SubscriptionCells).
#pragma once

#include <atomic>
#include <cstdint>
#include <string>
#include <vector>

#include "runtime/core/triple_buffer.hpp"
#include "runtime/io/dds/dds_settings.hpp"
#include "runtime/io/dds/subscription_intake.hpp"
#include "runtime/io/dds/subscription_latch.hpp"

namespace syncplc::dds {

// The hand-over cells of one publication (write_outputs -> the link):
// [scan, time, started, values...].
struct PublicationCells {
  static constexpr std::size_t kScan = 0, kTime = 1, kStarted = 2, kValues = 3;
};

struct LinkCounters {
  std::atomic<std::uint64_t> sent{0}, write_errors{0}, received{0}, lost{0}, late{0}, mismatched{0}, writers_changed{0},
      injected_lost{0};  // dropped by the injection (docs/dds.md)
};

class Link {
 public:
  explicit Link(const DdsSettings& s) : s_(s), pubs_(s.publish.size()), subs_(s.subscribe.size()) {
    for (std::size_t i = 0; i < s.publish.size(); ++i) pubs_[i].resize(PublicationCells::kValues + s.publish[i].values);
    for (std::size_t i = 0; i < s.subscribe.size(); ++i)
      subs_[i].resize(SubscriptionCells::kValues + s.subscribe[i].values);
  }
  virtual ~Link() = default;
  Link(const Link&) = delete;
  Link& operator=(const Link&) = delete;

  // Before the first scan: the exchange is set up and the subscriptions'
  // buffers hold "nothing received". False with *error.
  virtual bool open(std::string* error) = 0;
  virtual void close() noexcept = 0;

  TripleBuffer& publication(std::size_t i) { return pubs_[i]; }
  TripleBuffer& subscription(std::size_t i) { return subs_[i]; }
  // The scan, before the subscriptions are latched: the simulated link
  // takes what its bus shows at `now_ns` (the real one receives on its own
  // thread: nothing to do).
  virtual void poll(std::int64_t /*now_ns*/) noexcept {}
  // The scan: the publications' newest values are in their buffers.
  virtual void hand_over() noexcept = 0;
  const LinkCounters& counters() const { return counters_; }

 protected:
  // Values before the first sample: zero, not yet received (received = 0).
  void clear_subscriptions() {
    std::vector<Cell> zero;
    for (auto& b : subs_) {
      zero.assign(b.size(), Cell{});
      b.fill(zero.data());
    }
  }
  // What SubscriptionIntake::accept added, into the counters.
  void count(const IntakeCounters& added) noexcept {
    auto add = [](std::atomic<std::uint64_t>& c, std::uint64_t n) {
      if (n) c.fetch_add(n, std::memory_order_relaxed);
    };
    add(counters_.writers_changed, added.writers_changed);
    add(counters_.late, added.late);
    add(counters_.lost, added.lost);
    add(counters_.received, added.late ? 0 : 1);
  }
  const DdsSettings& s_;
  std::vector<TripleBuffer> pubs_, subs_;
  LinkCounters counters_;
};

}  // namespace syncplc::dds
