#include "runtime/io/modbus_client/tcp_link.hpp"

#include <arpa/inet.h>
#include <fcntl.h>
#include <netdb.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

#include "runtime/core/monotonic_clock.hpp"

namespace syncplc {
namespace {

timespec remaining(std::int64_t deadline) {
  std::int64_t left = deadline - monotonic_ns();
  if (left < 0) left = 0;
  return timespec{static_cast<time_t>(left / 1'000'000'000), static_cast<long>(left % 1'000'000'000)};
}

bool resolve(const std::string& host, std::uint16_t port, sockaddr_in& out) {
  std::memset(&out, 0, sizeof out);
  out.sin_family = AF_INET;
  out.sin_port = htons(port);
  if (inet_pton(AF_INET, host.c_str(), &out.sin_addr) == 1) return true;
  addrinfo hints{};
  hints.ai_family = AF_INET;
  hints.ai_socktype = SOCK_STREAM;
  addrinfo* res = nullptr;
  if (getaddrinfo(host.c_str(), nullptr, &hints, &res) != 0 || !res) return false;
  out.sin_addr = reinterpret_cast<sockaddr_in*>(res->ai_addr)->sin_addr;
  freeaddrinfo(res);
  return true;
}

}  // namespace

bool resolve_ipv4(const std::string& host, std::string* address) {
  sockaddr_in a{};
  if (!resolve(host, 0, a)) return false;
  char text[INET_ADDRSTRLEN] = {};
  if (!inet_ntop(AF_INET, &a.sin_addr, text, sizeof text)) return false;
  *address = text;
  return true;
}

void TcpLink::close() noexcept {
  if (fd_ >= 0) ::close(fd_);
  fd_ = -1;
}

int TcpLink::wait(short events, std::int64_t deadline) const {
  pollfd p[2] = {{fd_, events, 0}, {stop_fd_, POLLIN, 0}};
  for (;;) {
    timespec ts = remaining(deadline);
    int rc = ppoll(p, stop_fd_ >= 0 ? 2 : 1, &ts, nullptr);
    if (rc < 0 && errno == EINTR) continue;
    if (rc < 0) return -1;
    if (stop_fd_ >= 0 && (p[1].revents & POLLIN)) return -1;
    if (rc == 0) return 0;
    return 1;  // ready, or an error/hang-up the following call reports
  }
}

bool TcpLink::wait_until(std::int64_t deadline) const {
  pollfd p[2] = {{stop_fd_, POLLIN, 0}, {wake_fd_, POLLIN, 0}};  // poll ignores a negative fd
  for (;;) {
    if (monotonic_ns() >= deadline) return false;
    timespec ts = remaining(deadline);
    int rc = ppoll(p, 2, &ts, nullptr);
    if (rc > 0 && (p[1].revents & POLLIN)) {
      std::uint64_t n;
      [[maybe_unused]] ssize_t k = ::read(wake_fd_, &n, sizeof n);
    }
    if (rc > 0) return true;
    if (rc == 0) return false;
    if (errno != EINTR) return false;
  }
}

ClientError TcpLink::connect(const std::string& host, std::uint16_t port, std::int64_t timeout_ns) {
  close();
  sockaddr_in addr;
  if (!resolve(host, port, addr)) return ClientError::ConnectFailed;
  fd_ = ::socket(AF_INET, SOCK_STREAM | SOCK_NONBLOCK | SOCK_CLOEXEC, 0);
  if (fd_ < 0) return ClientError::ConnectFailed;
  int one = 1;
  setsockopt(fd_, IPPROTO_TCP, TCP_NODELAY, &one, sizeof one);  // one request a frame, no Nagle delay
  if (::connect(fd_, reinterpret_cast<sockaddr*>(&addr), sizeof addr) != 0) {
    if (errno != EINPROGRESS || wait(POLLOUT, monotonic_ns() + timeout_ns) != 1) {
      close();
      return ClientError::ConnectFailed;
    }
    int err = 0;
    socklen_t len = sizeof err;
    if (getsockopt(fd_, SOL_SOCKET, SO_ERROR, &err, &len) != 0 || err != 0) {
      close();
      return ClientError::ConnectFailed;
    }
  }
  return ClientError::None;
}

ClientError TcpLink::send_all(const std::uint8_t* p, std::size_t n, std::int64_t deadline) {
  std::size_t done = 0;
  while (done < n) {
    ssize_t k = ::send(fd_, p + done, n - done, MSG_NOSIGNAL);
    if (k > 0) { done += static_cast<std::size_t>(k); continue; }
    if (k < 0 && (errno == EAGAIN || errno == EWOULDBLOCK || errno == EINTR)) {
      int w = wait(POLLOUT, deadline);
      if (w == 0) return ClientError::Timeout;
      if (w < 0) return ClientError::ConnectionLost;
      continue;
    }
    return ClientError::ConnectionLost;
  }
  return ClientError::None;
}

ClientError TcpLink::receive(std::uint8_t* p, std::size_t n, std::int64_t deadline) {
  std::size_t done = 0;
  while (done < n) {
    ssize_t k = ::recv(fd_, p + done, n - done, 0);
    if (k > 0) { done += static_cast<std::size_t>(k); continue; }
    if (k == 0) return done == 0 ? ClientError::ConnectionLost : ClientError::Short;
    if (errno == EAGAIN || errno == EWOULDBLOCK || errno == EINTR) {
      int w = wait(POLLIN, deadline);
      if (w == 0) return ClientError::Timeout;
      if (w < 0) return ClientError::ConnectionLost;
      continue;
    }
    return ClientError::ConnectionLost;
  }
  return ClientError::None;
}

}  // namespace syncplc
