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

#include "runtime/io/dds/link.hpp"
#include "runtime/io/modbus_client/cycle_signal.hpp"

namespace syncplc::dds {

class DdsLink final : public Link {
 public:
  explicit DdsLink(const DdsSettings& s) : Link(s) {}
  ~DdsLink() override;

  // Creates the domain (the project's network settings), participant,
  // topics, writers and readers, and starts the threads. False with *error.
  bool open(std::string* error) override;
  // Stops and joins the threads, deletes the participant.
  void close() noexcept override;
  void hand_over() noexcept override { signal_.hand_over(); }

  // The XML of Cyclone's configuration for these settings (docs/dds.md, "Network").
  static std::string cyclone_config(const DdsSettings& s);

 private:
  // Waits up to startup_check for every writer and reader to meet a peer;
  // false with *error when a peer has another layout for the topic.
  bool check_peers(std::string* error);
  void send_loop(std::latch& ready) noexcept;
  void receive_loop(std::latch& ready) noexcept;

  CycleSignal signal_;
  std::atomic<bool> stop_{false};
  std::thread send_, receive_;
  std::int32_t participant_ = 0, waitset_ = 0, guard_ = 0;
  bool domain_held_ = false;
  std::vector<std::int32_t> writers_, readers_, conditions_;
};

}  // namespace syncplc::dds
