// One remote device's thread (`mb:<device>`): connects, runs its request
// groups' exchanges one at a time, each when due, and hands every result
// over (group_handover.hpp). Nothing here waits for a scan and no scan waits
// for it; each device has its own thread, so a slow or dead device delays
// only its own groups.
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
#include "runtime/io/modbus_client/group_handover.hpp"
#include "runtime/io/modbus_client/tcp_link.hpp"

namespace syncplc {

class DeviceLink {
 public:
  using Clock = std::int64_t (*)();
  DeviceLink(const ClientDevice& d, std::vector<GroupHandover*> groups, Clock clock);
  DeviceLink(const DeviceLink&) = delete;
  DeviceLink& operator=(const DeviceLink&) = delete;
  ~DeviceLink() { stop(); }

  bool start(std::string* error);
  void stop() noexcept;  // wakes the thread and joins it

  const ClientDevice& device() const { return *device_; }
  std::atomic<std::uint64_t> reconnects{0};
  std::atomic<std::uint64_t> connects{0};

 private:
  void run();
  // One exchange of group g; false when there was nothing to send (a write
  // group before its first outputs, or on_change without a change).
  bool exchange(GroupHandover& g, std::uint16_t* error);
  void fail_others(const GroupHandover* except, ClientError e);

  const ClientDevice* device_;
  std::vector<GroupHandover*> groups_;
  Clock clock_;
  TcpLink link_;
  std::uint16_t transaction_ = 0;
  int stop_fd_ = -1;
  std::atomic<bool> stopping_{false};
  std::thread thread_;
};

}  // namespace syncplc
