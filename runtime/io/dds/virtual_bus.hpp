// The network of a simulated system (docs/dds.md, "In virtual time"): the
// `dds` drivers of all nodes run in one process on one virtual clock
// (`syncplc sim SYSTEM.yaml`, `syncplc test`) and exchange their samples
// here instead of over Cyclone DDS.
//
// Timing, as logical execution time: a sample of a publisher's scan
// released at r is visible from r + T_pub (the publisher's next grid point,
// when its scan has surely ended) plus the subscribing node's injected delay.
// Nodes on one grid thus see each other's samples one scan late, as they do
// in real time when a sample takes less than a period, and the order in
// which the nodes' scans of one instant run changes nothing.
//
// Each topic keeps its newest samples in a ring sized at registration for
// the slowest of its subscribers; registration (open) allocates, publish and
// take (the scans) never do.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "runtime/core/iec_type.hpp"

namespace syncplc {

class VirtualBus {
 public:
  // A publisher of `topic` (open): its id, or -1 with *error when another
  // node publishes the topic or a subscriber takes another count of values.
  int advertise(const std::string& topic, std::uint32_t values, const std::string& node, std::int64_t period_ns,
                std::string* error);
  // A subscriber of `topic` that sees each sample `delay_ns` after it is
  // visible; its id, or -1 with *error when the publisher sends another count.
  int subscribe(const std::string& topic, std::uint32_t values, const std::string& node, std::int64_t delay_ns,
                std::int64_t period_ns, std::string* error);
  // close: the publisher's topic has no writer until it is advertised again
  // (a new writer: the subscribers count its scans afresh). A publisher
  // that another advertisement of the topic replaced (an online change's new
  // driver opens before the old one closes) leaves the topic to it.
  void withdraw_publisher(int id) noexcept;
  void withdraw_subscriber(int id) noexcept;

  // The scan of publisher `id`: one sample.
  void publish(int id, std::uint64_t scan, std::int64_t release_ns, const Cell* values) noexcept;

  // One sample as a subscriber takes it.
  struct Sample {
    std::uint64_t writer = 0;  // which advertisement sent it (a node that advertised again is a new writer)
    std::uint64_t scan = 0;
    const double* values = nullptr;
  };
  // The scan of subscriber `id` at `now_ns`: calls f(sample) for every
  // sample of its topic visible at now_ns that it has not taken, oldest
  // first. Samples overwritten before the subscriber came to them (its task
  // stopped) are skipped: the gap in the scan count shows them lost.
  template <class F>
  void take(int id, std::int64_t now_ns, F&& f) noexcept {
    Subscriber& s = subs_[static_cast<std::size_t>(id)];
    Topic& t = topics_[s.topic];
    if (t.head == 0) return;
    const std::uint64_t cap = t.capacity;
    if (t.head > cap && s.next + cap <= t.head) s.next = t.head - cap + 1;
    for (; s.next <= t.head; ++s.next) {
      const Slot& slot = t.slots[static_cast<std::size_t>(s.next % cap)];
      if (slot.release_ns + t.period_ns + s.delay_ns > now_ns) break;
      f(Sample{slot.writer, slot.scan, &t.values[static_cast<std::size_t>(s.next % cap) * t.count]});
    }
  }

  // Subscriptions of topics no node publishes (a misspelt topic, a node
  // missing from the system): one line each.
  std::vector<std::string> unmatched() const;

 private:
  struct Slot {
    std::uint64_t writer = 0, scan = 0;
    std::int64_t release_ns = 0;
  };
  struct Topic {
    std::string name;
    std::uint32_t count = 0;
    std::string publisher;         // node, "" while none
    std::int64_t period_ns = 0;    // the publisher's
    std::uint64_t writer = 0;      // the current advertisement
    std::uint64_t head = 0;        // samples published (sequence of the newest, from 1)
    std::uint64_t capacity = 0;
    std::vector<Slot> slots;
    std::vector<double> values;    // capacity x count
  };
  struct Subscriber {
    std::size_t topic = 0;
    std::string node;
    std::int64_t delay_ns = 0, period_ns = 0;
    std::uint64_t next = 1;        // sequence of the next sample to look at
    bool open = false;
  };
  std::size_t topic_index(const std::string& name, std::uint32_t values);
  // A topic nobody holds takes another count of values: its ring goes.
  static void relayout(Topic& t, std::uint32_t values);
  // Grows the ring so that every subscriber finds every sample it has not
  // taken yet: samples published in one subscriber period plus its delay.
  void size_ring(Topic& t);

  std::vector<Topic> topics_;
  std::vector<Subscriber> subs_;
  struct Publisher {
    std::size_t topic = 0;
    std::uint64_t writer = 0;  // its advertisement
  };
  std::vector<Publisher> pubs_;
  std::uint64_t writers_ = 0;
};

}  // namespace syncplc
