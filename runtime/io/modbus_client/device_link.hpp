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
