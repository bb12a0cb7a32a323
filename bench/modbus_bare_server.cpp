// A bare libmodbus Modbus TCP server: the reference that bench/modbus_bench.sh
// sets next to syncplc's server (docs/benchmarks.md, "Modbus TCP server").
//
// It is the canonical libmodbus server, as in libmodbus's own
// tests/bandwidth-server-many-up.c, with poll() instead of select(): one
// thread, modbus_tcp_listen, a poll loop over the listening socket and every
// client, accept() for a new client, and for a readable client
// modbus_receive + modbus_reply on a modbus_mapping_t. The mapping holds only
// the holding registers [--address, --address + --count) (by default 1024..1148,
// where the benchmark project's %MW0 array sits), so a read elsewhere gets
// exception 02 as from syncplc. The registers hold fixed values; nothing
// else runs in the process.
//
// Usage: bench_modbus_bare_server [--port P] [--address A] [--count N]
// --port 0 (the default) takes a free port. The first line on stdout is
// "bench_modbus_bare_server: listening on 127.0.0.1:PORT"; SIGINT or SIGTERM
// stops it, and it prints how many requests it answered.
#include <arpa/inet.h>
#include <modbus/modbus.h>
#include <netinet/in.h>
#include <poll.h>
#include <signal.h>
#include <sys/socket.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <cerrno>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <vector>

namespace {

volatile sig_atomic_t g_stop = 0;

void on_signal(int) { g_stop = 1; }

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"bench_modbus_bare_server: a bare libmodbus Modbus TCP server (poll loop), for bench/modbus_bench.sh"};
  int port = 0;
  int address = 1024;
  int count = 125;
  app.add_option("--port", port, "TCP port on 127.0.0.1 (0: any free port)")->check(CLI::Range(0, 65535));
  app.add_option("--address", address, "first holding register mapped")->check(CLI::Range(0, 65535));
  app.add_option("--count", count, "holding registers mapped")->check(CLI::Range(1, 65536));
  CLI11_PARSE(app, argc, argv);

  modbus_t* ctx = modbus_new_tcp("127.0.0.1", port);
  modbus_mapping_t* mapping = modbus_mapping_new_start_address(0, 0, 0, 0, static_cast<unsigned>(address),
                                                               static_cast<unsigned>(count), 0, 0);
  if (!ctx || !mapping) {
    std::fprintf(stderr, "bench_modbus_bare_server: %s\n", modbus_strerror(errno));
    return 1;
  }
  for (int i = 0; i < count; ++i) mapping->tab_registers[i] = static_cast<std::uint16_t>(i);

  const int listen_fd = modbus_tcp_listen(ctx, 128);
  if (listen_fd < 0) {
    std::fprintf(stderr, "bench_modbus_bare_server: cannot listen on port %d: %s\n", port, modbus_strerror(errno));
    return 1;
  }
  sockaddr_in bound{};
  socklen_t len = sizeof bound;
  getsockname(listen_fd, reinterpret_cast<sockaddr*>(&bound), &len);
  std::printf("bench_modbus_bare_server: listening on 127.0.0.1:%d (holding registers %d..%d)\n",
              ntohs(bound.sin_port), address, address + count - 1);
  std::fflush(stdout);

  struct sigaction sa{};
  sa.sa_handler = on_signal;
  sigaction(SIGINT, &sa, nullptr);
  sigaction(SIGTERM, &sa, nullptr);
  signal(SIGPIPE, SIG_IGN);

  std::vector<pollfd> fds{{listen_fd, POLLIN, 0}};
  std::uint8_t query[MODBUS_TCP_MAX_ADU_LENGTH];
  std::uint64_t answered = 0, accepted = 0, closed = 0;
  while (!g_stop) {
    const int n = poll(fds.data(), fds.size(), 200);  // wakes now and then to see g_stop
    if (n < 0) {
      if (errno == EINTR) continue;
      std::perror("bench_modbus_bare_server: poll");
      break;
    }
    if (n == 0) continue;
    // Clients first, in order; the listening socket (slot 0) last, so that a
    // new client's pollfd is only watched from the next round on.
    for (std::size_t i = 1; i < fds.size();) {
      if (!(fds[i].revents & (POLLIN | POLLHUP | POLLERR))) { ++i; continue; }
      modbus_set_socket(ctx, fds[i].fd);
      const int rc = modbus_receive(ctx, query);
      if (rc > 0) {
        modbus_reply(ctx, query, rc, mapping);
        ++answered;
      } else if (rc == -1) {
        // The client closed (or sent garbage): like the libmodbus example, close it.
        close(fds[i].fd);
        fds[i] = fds.back();
        fds.pop_back();
        ++closed;
        continue;  // slot i now holds the last pollfd, whose revents are still this round's
      }
      ++i;
    }
    if (fds[0].revents & POLLIN) {
      sockaddr_in peer{};
      socklen_t plen = sizeof peer;
      const int fd = accept(listen_fd, reinterpret_cast<sockaddr*>(&peer), &plen);
      if (fd >= 0) {
        fds.push_back(pollfd{fd, POLLIN, 0});
        ++accepted;
      }
    }
  }
  for (std::size_t i = 1; i < fds.size(); ++i) close(fds[i].fd);
  close(listen_fd);
  modbus_set_socket(ctx, -1);
  modbus_mapping_free(mapping);
  modbus_free(ctx);
  std::printf("bench_modbus_bare_server: %llu requests answered, %llu connections accepted, %llu closed\n",
              static_cast<unsigned long long>(answered), static_cast<unsigned long long>(accepted),
              static_cast<unsigned long long>(closed));
  return 0;
}
