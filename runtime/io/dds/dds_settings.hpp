// The settings of a `dds` driver (docs/dds.md): which DDS domain and network,
// what this node publishes, what it subscribes to, and how a subscription
// that goes stale is treated. Read from the driver's project-file entry by
// read_dds_settings; every problem is a load error at its file:line:col.
//
//   - name: net
//     type: dds
//     node: axis1                      # this node's name, in every sample it sends
//     domain: 0                        # DDS domain id
//     peers: [127.0.0.1]               # unicast discovery; multicast is then off
//     interface: lo                    # the network interface (name or address)
//     shared_memory: false             # Cyclone's iceoryx transport (needs iox-roudi)
//     qos: {reliability: best_effort, deadline: 2ms, liveliness: 10ms}
//     startup_check: 2s                # wait for peers at start, refuse a layout mismatch
//     inject: {loss: 0.05, delay: 2ms, seed: 7}   # fault injection (tests, measurements)
//     publish:
//       - {topic: axis1_state, values: 2}
//     subscribe:
//       - {topic: master_ref, values: 4, stale_after: 3, reaction: hold, safe: 0}
//     bind: {axis1_state: state, master_ref: ref, master_ref_ok: ref_ok}
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "runtime/core/config_node.hpp"
#include "runtime/core/io_driver.hpp"

namespace syncplc::dds {

// One sample carries at most this many values (the fixed layout of
// node_sample.idl).
inline constexpr std::uint32_t kMaxValues = 64;

enum class StaleReaction : std::uint8_t { Hold, Safe, Stop };

struct Publication {
  std::string topic;
  std::uint32_t values = 1;
};

struct Subscription {
  std::string topic;
  std::uint32_t values = 1;
  std::uint32_t stale_after = 0;  // scans without a new sample before the reaction applies
  StaleReaction reaction = StaleReaction::Hold;
  std::vector<double> safe;       // one per value, for reaction safe
};

enum class Reliability : std::uint8_t { BestEffort, Reliable };

// Fault injection in the receive thread, for tests and measurements
// (docs/dds.md, "Injected loss and delay"): every subscription of the node
// drops a received sample with probability `loss` (seeded) and shows the
// others `delay` after they arrived.
struct Injection {
  double loss = 0;
  std::int64_t delay_ns = 0;
  std::uint64_t seed = 1;
  bool on() const { return loss > 0 || delay_ns > 0; }
};

struct DdsSettings {
  std::string node;
  std::uint32_t domain = 0;
  std::vector<std::string> peers;
  std::string interface;
  bool shared_memory = false;
  Reliability reliability = Reliability::BestEffort;
  std::int64_t deadline_ns = 0;    // 0: none
  std::int64_t liveliness_ns = 0;  // 0: none (automatic liveliness, infinite lease)
  // How long open() waits for every topic to meet its peers, checking that
  // they agree on its layout (docs/dds.md, "Starting a node"); 0: no check.
  std::int64_t startup_check_ns = 2'000'000'000;
  // SCHED_FIFO priority of the driver's send and receive threads, so that a
  // sample leaves right after its scan even when the machine is busy; 0:
  // normal scheduling. Where the process may not (no RLIMIT_RTPRIO), normal.
  int thread_priority = 1;
  Injection inject;
  std::vector<Publication> publish;
  std::vector<Subscription> subscribe;
};

// False after reporting every error through `setup`.
bool read_dds_settings(const ConfigNode& entry, DriverSetup& setup, DdsSettings& out);

// The topic's name on the wire: "syncplc_" + topic (topics of other
// applications in the same domain cannot collide with ours).
std::string wire_topic(const std::string& topic);

// What a sample's `layout` word holds for `values` values: a check that
// publisher and subscriber agree on the topic's layout (FNV-1a of the
// layout's version, the topic and the count).
std::uint32_t layout_word(const std::string& topic, std::uint32_t values);

}  // namespace syncplc::dds
