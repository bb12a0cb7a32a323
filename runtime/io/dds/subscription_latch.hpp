// What a `dds` subscription shows the program at each scan (docs/dds.md,
// "Quality: age, loss, reactions"), from the newest sample the receive
// thread handed over:
//
//   TOPIC_age       scans since the newest sample arrived: 0 when one came in
//                   since the last scan; before the first sample, scans since
//                   the driver opened
//   TOPIC_ok        a sample has arrived and age <= stale_after
//   TOPIC_reaction  age > stale_after: the subscription's reaction applies,
//                   hold (the values stay, flagged by ok FALSE), safe (the
//                   values take the subscription's safe values) or stop (the
//                   task stops with its safe outputs, ScanContext::request_stop)
//   TOPIC_scan      the publisher's scan count of the values shown
//   TOPIC_lost      samples the publisher sent that never arrived (gaps in its
//                   scan count), since open
//   TOPIC_late      samples that arrived after a newer one (dropped), since open
//
// Values are copied to the channel only from a new sample; a stale
// subscription never shows old values as fresh.
#pragma once

#include <cstdint>

#include "runtime/core/block.hpp"
#include "runtime/io/dds/dds_settings.hpp"

namespace syncplc::dds {

// The hand-over cells of one subscription (receive thread -> latch), in a
// TripleBuffer: [received, publisher scan, lost, late, publisher's scan
// start, values...].
struct SubscriptionCells {
  static constexpr std::size_t kReceived = 0, kScan = 1, kLost = 2, kLate = 3, kStarted = 4, kValues = 5;
};

struct SubscriptionStatus {
  bool ok = false;
  bool reacting = false;
  bool fresh = false;            // this latch took a new sample
  std::uint32_t age = 0;         // scans
  std::uint64_t scan = 0;        // the publisher's scan of the values shown
  std::uint32_t lost = 0, late = 0;
  // Real time: this scan's start minus the publisher's nearest scan start
  // (the latest fresh sample's), in ns within (-T/2, T/2], T this task's
  // period: how far the two nodes' grids are apart (docs/dds.md, "One grid
  // for all nodes"). has_phase: measured (real time, a sample with a start).
  std::int64_t phase_ns = 0;
  bool has_phase = false;
};

// Static texts of a subscription's events, made (interned) at load.
struct SubscriptionTexts {
  const char* stale = "";
  const char* recovered = "";
};
SubscriptionTexts make_subscription_texts(const std::string& driver, const Subscription& s);

class SubscriptionLatch {
 public:
  SubscriptionLatch() = default;
  SubscriptionLatch(const Subscription& s, SubscriptionTexts texts) : sub_(&s), texts_(texts) {}
  // Before the first scan of a run.
  void reset() noexcept;
  // cells: the newest hand-over (SubscriptionCells layout). values: the
  // channel's cells (sub.values of them) or nullptr when unbound. started:
  // when this scan began on CLOCK_REALTIME (0 in virtual time).
  const SubscriptionStatus& latch(const Cell* cells, const ScanContext& ctx, Cell* values,
                                  std::int64_t started = 0) noexcept;
  const SubscriptionStatus& status() const noexcept { return st_; }

 private:
  const Subscription* sub_ = nullptr;
  SubscriptionTexts texts_;
  SubscriptionStatus st_;
  std::uint64_t seen_ = 0;        // `received` of the newest sample taken
  bool started_ = false;          // the first latch of the run happened
  std::uint64_t since_ = 0;       // the scan the newest sample was taken at (or the run's first scan)
  bool reacted_ = false;          // the reaction's event of this stale period was raised
};

}  // namespace syncplc::dds
