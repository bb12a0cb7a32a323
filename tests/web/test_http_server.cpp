// The Beast server itself (runtime/web/http_server) on loopback with a
// handler of the test's own: keep-alive, a refusal's answer, the connection
// limit, a stream, and a stop with a stream and idle connections open.
#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <gtest/gtest.h>

#include <atomic>
#include <cerrno>
#include <chrono>
#include <string>
#include <thread>

#include "runtime/web/http_server.hpp"

namespace syncplc::web::http {
namespace {

int connect_to(int port) {
  const int fd = socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_port = htons(static_cast<std::uint16_t>(port));
  a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  timeval tv{30, 0};  // a hang guard only
  setsockopt(fd, SOL_SOCKET, SO_RCVTIMEO, &tv, sizeof tv);
  EXPECT_EQ(connect(fd, reinterpret_cast<sockaddr*>(&a), sizeof a), 0);
  return fd;
}

void send_all(int fd, const std::string& s) { ASSERT_EQ(send(fd, s.data(), s.size(), MSG_NOSIGNAL), static_cast<ssize_t>(s.size())); }

// Reads until `until` is in what came (or the connection ends).
std::string read_until(int fd, const std::string& until) {
  std::string got;
  char buf[4096];
  while (got.find(until) == std::string::npos) {
    const ssize_t n = recv(fd, buf, sizeof buf, 0);
    if (n <= 0) break;
    got.append(buf, static_cast<std::size_t>(n));
  }
  return got;
}

// The server closed the connection: an orderly end (0) or a reset. The hang
// guard's timeout (EAGAIN) is not a close: a connection left open for 30 s
// must fail the test, not pass it.
bool closed_by_peer(int fd) {
  char c;
  const ssize_t n = recv(fd, &c, 1, 0);
  return n == 0 || (n < 0 && errno != EAGAIN && errno != EWOULDBLOCK);
}

struct Fixture {
  explicit Fixture(ServerOptions o = {}) {
    o.bind = "127.0.0.1";
    o.port = 0;
    o.workers = 4;
    server = std::make_unique<HttpServer>(
        o,
        [this](Request& req, Response& res) {
          handled.fetch_add(1);
          if (req.path == "/stream") {
            res.set_chunked_content_provider(
                "text/event-stream",
                [this](std::size_t, DataSink& sink) {
                  const int n = events.fetch_add(1);
                  if (n >= 3 && !endless) {
                    sink.done();
                    return true;
                  }
                  const std::string e = "data: " + std::to_string(n) + "\n\n";
                  if (endless) std::this_thread::sleep_for(std::chrono::milliseconds(1));
                  return sink.is_writable() && sink.write(e.data(), e.size());
                },
                [this](bool ok) { released.store(ok ? 1 : 2); });
            return;
          }
          res.set_content("path " + req.path + " q " + req.get_param_value("q"), "text/plain");
        },
        [](const Refusal& r, Response& res) {
          res.status = r.status;
          res.set_content("refused: " + r.message, "text/plain");
        });
    std::string why;
    EXPECT_TRUE(server->start(&why)) << why;
  }
  std::unique_ptr<HttpServer> server;
  std::atomic<int> handled{0}, events{0}, released{0};
  std::atomic<bool> endless{false};
};

TEST(HttpServer, AnswersRequestsOnOneKeptConnection) {
  Fixture f;
  const int fd = connect_to(f.server->port());
  send_all(fd, "GET /a?q=x%20y HTTP/1.1\r\nHost: h\r\n\r\n");
  std::string got = read_until(fd, "q x y");
  EXPECT_EQ(got.rfind("HTTP/1.1 200", 0), 0u) << got;
  send_all(fd, "GET /b HTTP/1.1\r\nHost: h\r\n\r\n");
  got = read_until(fd, "path /b");
  EXPECT_EQ(got.rfind("HTTP/1.1 200", 0), 0u) << got;
  close(fd);
  EXPECT_EQ(f.handled.load(), 2);
}

TEST(HttpServer, RefusesAHeaderBlockPastTheLimitAndCloses) {
  Fixture f;
  const int fd = connect_to(f.server->port());
  std::string big = "GET / HTTP/1.1\r\nHost: h\r\n";
  while (big.size() < 40 * 1024) big += "X-Filler: " + std::string(1000, 'y') + "\r\n";
  send_all(fd, big);
  const std::string got = read_until(fd, "refused: ");
  EXPECT_EQ(got.rfind("HTTP/1.1 431", 0), 0u) << got.substr(0, 200);
  EXPECT_NE(got.find("Connection: close"), std::string::npos);
  EXPECT_TRUE(closed_by_peer(fd));
  close(fd);
  EXPECT_EQ(f.handled.load(), 0);
}

TEST(HttpServer, ConnectionsPastTheLimitAreRefusedAtOnce) {
  ServerOptions o;
  o.max_connections = 2;
  Fixture f(o);
  const int a = connect_to(f.server->port()), b = connect_to(f.server->port());
  // Both taken (counted, not timed): the third is then past the limit.
  while (f.server->connections() < 2) std::this_thread::sleep_for(std::chrono::milliseconds(1));
  const int c = connect_to(f.server->port());
  const std::string got = read_until(c, "try again later");
  EXPECT_EQ(got.rfind("HTTP/1.1 503", 0), 0u) << got;
  EXPECT_TRUE(closed_by_peer(c));
  EXPECT_EQ(f.server->refused_connections(), 1u);
  close(c);
  close(a);
  while (f.server->connections() > 1) std::this_thread::sleep_for(std::chrono::milliseconds(1));
  const int d = connect_to(f.server->port());
  send_all(d, "GET /d HTTP/1.1\r\nHost: h\r\n\r\n");
  EXPECT_EQ(read_until(d, "path /d").rfind("HTTP/1.1 200", 0), 0u);
  close(d);
  close(b);
}

TEST(HttpServer, StreamsChunkedUntilDone) {
  Fixture f;
  const int fd = connect_to(f.server->port());
  send_all(fd, "GET /stream HTTP/1.1\r\nHost: h\r\n\r\n");
  const std::string got = read_until(fd, "\r\n0\r\n\r\n");
  EXPECT_NE(got.find("Transfer-Encoding: chunked"), std::string::npos) << got;
  EXPECT_NE(got.find("data: 0"), std::string::npos);
  EXPECT_NE(got.find("data: 2"), std::string::npos);
  EXPECT_TRUE(closed_by_peer(fd));
  close(fd);
  while (f.released.load() == 0) std::this_thread::sleep_for(std::chrono::milliseconds(1));
  EXPECT_EQ(f.released.load(), 1);
}

TEST(HttpServer, StopEndsStreamsAndIdleConnections) {
  Fixture f;
  f.endless = true;
  const int idle = connect_to(f.server->port());
  const int fd = connect_to(f.server->port());
  send_all(fd, "GET /stream HTTP/1.1\r\nHost: h\r\n\r\n");
  read_until(fd, "data: 1");
  f.server->stop();
  EXPECT_EQ(f.released.load(), 2);  // ended by the stop, not by done()
  EXPECT_TRUE(closed_by_peer(idle));
  close(idle);
  close(fd);
}

}  // namespace
}  // namespace syncplc::web::http
