// The TCP side of one device connection: non-blocking sockets with poll, so
// every wait has a deadline and ends early when the driver closes (the stop
// eventfd). Only the device's own thread uses it.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

#include "runtime/io/modbus_client/client_error.hpp"

namespace syncplc {

// `host` as a numeric IPv4 address: itself when it is one, else looked up
// (getaddrinfo, which may block for the resolver's timeouts: call it where a
// wait is harmless, never on a device thread that stop() must end at once).
bool resolve_ipv4(const std::string& host, std::string* address);

class TcpLink {
 public:
  TcpLink() = default;
  TcpLink(const TcpLink&) = delete;
  TcpLink& operator=(const TcpLink&) = delete;
  ~TcpLink() { close(); }

  void set_stop_fd(int fd) { stop_fd_ = fd; }
  // An eventfd that ends wait_until early (and is drained by it), never an exchange's wait.
  void set_wake_fd(int fd) { wake_fd_ = fd; }
  // ConnectFailed (refused, unreachable, not within timeout_ns, host unknown) or None.
  ClientError connect(const std::string& host, std::uint16_t port, std::int64_t timeout_ns);
  bool connected() const { return fd_ >= 0; }
  void close() noexcept;
  // Online change: the open socket given away (-1 when none), and taken.
  int release() noexcept {
    const int fd = fd_;
    fd_ = -1;
    return fd;
  }
  void adopt(int fd) noexcept {
    close();
    fd_ = fd;
  }

  // deadline: the driver's clock (monotonic ns). ConnectionLost when the
  // peer closed or the send failed, Timeout at the deadline.
  ClientError send_all(const std::uint8_t* p, std::size_t n, std::int64_t deadline);
  // Exactly n bytes: Timeout at the deadline, ConnectionLost when the peer
  // closed before the first byte, Short when it closed after some.
  ClientError receive(std::uint8_t* p, std::size_t n, std::int64_t deadline);
  // Sleeps until `deadline` or until the stop or wake fd is signalled (returns true then).
  bool wait_until(std::int64_t deadline) const;

 private:
  // Waits for `events` on the socket: 1 ready, 0 deadline, -1 stop or error.
  int wait(short events, std::int64_t deadline) const;
  int fd_ = -1;
  int stop_fd_ = -1;
  int wake_fd_ = -1;
};

}  // namespace syncplc
