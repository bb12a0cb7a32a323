// One remote device's thread (`mb:<device>`): connects, runs its request
// groups' exchanges one at a time and hands every result over
// (group_handover.hpp). No scan waits for it; each device has its own
// thread, so a slow or dead device delays only its own groups.
//
// When (the device's `timing`):
// - cycle (default): each scan's write_outputs signals the driver's device
//   threads (CycleSignal::hand_over, cycle_signal.hpp) right after handing its outputs over;
//   the thread then runs, in one burst, the groups due at this scan (every
//   `every: scan` group, and a duration group whose time has come within
//   half a period), writes first, then reads, so the reply is in before the
//   next scan latches it. At most one burst per wake: hand-overs that come
//   during a burst are one more burst, never a queue of them. Without a
//   hand-over for kFallbackPeriods task periods (a task that stopped
//   scanning, an online change, a long stall) the thread runs the groups on
//   their own grid as `free` does, so the connection and the staleness
//   logic live on, until the next hand-over.
// - free: each group on its own grid of `every`, counted from the
//   connection, free-running against the task's scans.
//
// Writes wait for reads (the write gate): on every connection, a write
// group sends nothing until the outputs handed over come from a scan that
// latched good replies of every reading group of the device on this
// connection (their epoch, group_handover.hpp); until then an FC 23 group
// sends its read side alone (FC 3), so a device whose only group is FC 23
// is read before it is written too. A device after a reconnect, or at the
// start, is read first: nothing computed from stale data reaches it.
//
// A failure that leaves the byte stream in doubt (everything but an
// exception reply, client_error.hpp) closes the connection; the failing
// group publishes its error and the device's other groups `not connected`,
// so all go stale together. Reconnection waits reconnect_min after the first
// failure, doubling up to reconnect_max; one successful exchange resets it
// (a device that accepts connections but never answers backs off too).
#pragma once

#include <atomic>
#include <cstdint>
#include <thread>
#include <vector>

#include "runtime/io/modbus_client/client_config.hpp"
#include "runtime/io/modbus_client/cycle_signal.hpp"
#include "runtime/io/modbus_client/group_handover.hpp"
#include "runtime/io/modbus_client/tcp_link.hpp"

namespace syncplc {

class DeviceLink {
 public:
  using Clock = std::int64_t (*)();
  // signal: the driver's hand-over count (timing cycle), outlives the link.
  DeviceLink(const ClientDevice& d, std::vector<GroupHandover*> groups, Clock clock, CycleSignal* signal);
  DeviceLink(const DeviceLink&) = delete;
  DeviceLink& operator=(const DeviceLink&) = delete;
  ~DeviceLink() { stop(); }

  bool start(std::string* error);
  void stop() noexcept;  // wakes the thread and joins it
  // at_stop safe: the write groups due at once (after the exchange under way),
  // and a connection attempt at once when there is none.
  void flush() noexcept;

  // Online change (modbus_client.hpp, take_over): the connection handed from
  // the running driver's link to its successor's, never closed in between
  // (a device that takes one connection, or treats a closed one as a lost
  // master, sees nothing). A link made with `inherit` does not connect until
  // adopt(): adopt(fd) takes an open socket, adopt(-1) connects itself.
  // release() ends the thread after the exchange under way (at most one
  // response_timeout, or connect_timeout while connecting) and gives away
  // its socket (-1 when not connected).
  void set_inherit() { inherit_ = true; }
  bool inherits() const { return inherit_; }
  int release() noexcept;
  void adopt(int fd) noexcept;

  static constexpr std::int64_t kFallbackPeriods = 3;

  const ClientDevice& device() const { return *device_; }
  std::atomic<std::uint64_t> reconnects{0};
  std::atomic<std::uint64_t> connects{0};

 private:
  void run();
  // One exchange of group g; false when there was nothing to send (a write
  // group before its first outputs, or on_change without a change).
  bool exchange(GroupHandover& g, std::uint16_t* error);
  void fail_others(const GroupHandover* except, ClientError e);
  // The exchange's outcome for the connection: closed (and the back-off
  // started) on a failure that leaves the byte stream in doubt. False then.
  bool settle(GroupHandover& g, std::uint16_t err);
  // The earliest group on its own grid: exchanged when due, else waited for
  // (timing cycle, the fallback: a hand-over ends the wait too).
  void run_free();
  // timing cycle: the groups due at the hand-over at `now`, writes first.
  void run_burst(std::int64_t now);
  void backoff_after_failure();
  // The scans' hand-over count a request sent now belongs to (results' cycle).
  std::uint32_t request_cycle() const noexcept;

  const ClientDevice* device_;
  std::vector<GroupHandover*> groups_;
  Clock clock_;
  TcpLink link_;
  std::uint16_t transaction_ = 0;
  std::uint64_t epoch_ = 0;           // the connection's number (connects, counted from 1)
  std::int64_t backoff_ = 0, next_connect_ = 0;
  CycleSignal* signal_;
  bool follows_scan_ = false;         // timing cycle (and a task period to fall back on)
  std::uint32_t seen_ = 0;            // the hand-over count of the last burst
  std::int64_t last_hand_over_ = 0;   // when the device thread saw it (monotonic ns)
  int stop_fd_ = -1;
  int wake_fd_ = -1;
  std::atomic<bool> stopping_{false};
  std::atomic<bool> flush_{false};
  std::atomic<bool> releasing_{false};
  static constexpr int kAwaiting = -2;
  std::atomic<int> adopted_{kAwaiting};
  bool inherit_ = false;
  std::thread thread_;
};

}  // namespace syncplc
