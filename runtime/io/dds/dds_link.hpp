// The `dds` driver's side on Cyclone DDS (docs/dds.md, "Threads"): one
// participant in the project's domain, a writer per publication and a reader
// per subscription, and two threads of the driver's own, so that no DDS call
// is ever made on the scan path (Cyclone allocates and locks on write and
// take):
//
//   send     sleeps on the scans' hand-over signal; at each hand-over writes
//            the newest sample of every publication (TripleBuffer from
//            write_outputs).
//   receive  sleeps in a waitset on the readers' data and a stop guard; takes
//            every sample, drops the late and the mismatched, counts the
//            lost, and hands the newest of each subscription to latch_inputs
//            (TripleBuffer, SubscriptionCells layout).
#pragma once

#include <atomic>
#include <cstdint>
#include <latch>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "runtime/core/triple_buffer.hpp"
#include "runtime/io/dds/dds_settings.hpp"
#include "runtime/io/modbus_client/cycle_signal.hpp"

namespace syncplc::dds {

// The hand-over cells of one publication (write_outputs -> send thread):
// [scan, time, started, values...].
struct PublicationCells {
  static constexpr std::size_t kScan = 0, kTime = 1, kStarted = 2, kValues = 3;
};

struct LinkCounters {
  std::atomic<std::uint64_t> sent{0}, write_errors{0}, received{0}, lost{0}, late{0}, mismatched{0}, writers_changed{0},
      injected_lost{0};  // dropped by the injection (docs/dds.md)
};

class DdsLink {
 public:
  explicit DdsLink(const DdsSettings& s);
  ~DdsLink();
  DdsLink(const DdsLink&) = delete;
  DdsLink& operator=(const DdsLink&) = delete;

  // Creates the domain (the project's network settings), participant,
  // topics, writers and readers, and starts the threads. False with *error.
  bool open(std::string* error);
  // Stops and joins the threads, deletes the participant.
  void close() noexcept;

  TripleBuffer& publication(std::size_t i) { return pubs_[i]; }
  TripleBuffer& subscription(std::size_t i) { return subs_[i]; }
  // The scan: the publications' newest values are in their buffers.
  void hand_over() noexcept { signal_.hand_over(); }
  const LinkCounters& counters() const { return counters_; }

  // The XML of Cyclone's configuration for these settings (docs/dds.md, "Network").
  static std::string cyclone_config(const DdsSettings& s);

 private:
  // Waits up to startup_check for every writer and reader to meet a peer;
  // false with *error when a peer has another layout for the topic.
  bool check_peers(std::string* error);
  void send_loop(std::latch& ready) noexcept;
  void receive_loop(std::latch& ready) noexcept;

  const DdsSettings& s_;
  std::vector<TripleBuffer> pubs_, subs_;
  CycleSignal signal_;
  std::atomic<bool> stop_{false};
  std::thread send_, receive_;
  LinkCounters counters_;
  std::int32_t participant_ = 0, waitset_ = 0, guard_ = 0;
  bool domain_held_ = false;
  std::vector<std::int32_t> writers_, readers_, conditions_;
};

}  // namespace syncplc::dds
