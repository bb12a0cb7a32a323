// The cycle of a master and N nodes over Cyclone DDS, side by side with bare
// UDP in the same run (issue 25; docs/benchmarks.md section 20). Every
// period the master sends one sample to all nodes; each node answers at
// once; the master's complete cycle ends when every node's answer is in.
// Each node is a process of its own (fork), as a node of the table would be.
//
//   bench_dds_cycle --nodes 4 --period 1ms --duration 10s
//
// Reported per transport: the complete-cycle time (send -> last answer in)
// and the round trip of single answers (send -> that answer in; half of it
// is the node-to-node latency), as percentiles over the cycles; the cycles
// whose answers were not all in by the next period (missed); and each node
// process's CPU time over the run (user + system, wait4's rusage), per
// node, as a percentage of one CPU. DDS: the sample type of the dds driver
// (runtime/io/dds/node_sample.idl), best effort, keep-last, unicast
// discovery on loopback, as the driver sets it up.
#include <arpa/inet.h>
#include <dds/dds.h>
#include <netinet/in.h>
#include <poll.h>
#include <sched.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <cinttypes>
#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

#include "runtime/core/iec_type.hpp"
#include "runtime/core/monotonic_clock.hpp"
#include "runtime/io/dds/node_sample.h"

namespace {

using syncplc::monotonic_ns;

struct Result {
  std::vector<std::int64_t> complete, single;  // ns
  std::uint64_t cycles = 0, missed = 0;
  double cpu_per_node = 0;  // % of one CPU
};

void sleep_until(std::int64_t t) {
  timespec ts{static_cast<time_t>(t / 1'000'000'000), static_cast<long>(t % 1'000'000'000)};
  while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, nullptr) == EINTR) {
  }
}

void realtime_priority(int prio) {
  sched_param p{};
  p.sched_priority = prio;
  sched_setscheduler(0, SCHED_FIFO, &p);  // where permitted; else normal
}

// --- DDS -------------------------------------------------------------------

std::string cyclone_config() {
  return "<CycloneDDS><Domain id=\"any\"><General><Interfaces><NetworkInterface address=\"127.0.0.1\"/></Interfaces>"
         "<AllowMulticast>false</AllowMulticast></General><Discovery><ParticipantIndex>auto</ParticipantIndex>"
         "<MaxAutoParticipantIndex>120</MaxAutoParticipantIndex><Peers><Peer address=\"127.0.0.1\"/></Peers>"
         "</Discovery></Domain></CycloneDDS>";
}

dds_qos_t* qos(int depth) {
  dds_qos_t* q = dds_create_qos();
  dds_qset_reliability(q, DDS_RELIABILITY_BEST_EFFORT, 0);
  dds_qset_history(q, DDS_HISTORY_KEEP_LAST, depth);
  dds_qset_durability(q, DDS_DURABILITY_VOLATILE);
  return q;
}

struct DdsEnds {
  dds_entity_t participant, writer, reader, waitset;
};

DdsEnds dds_ends(std::uint32_t domain, const char* out, const char* in) {
  const std::string cfg = cyclone_config();
  dds_entity_t d = dds_create_domain(domain, cfg.c_str());
  if (d < 0) std::fprintf(stderr, "dds_create_domain: %s\n", dds_strretcode(d));
  DdsEnds e{};
  e.participant = dds_create_participant(domain, nullptr, nullptr);
  dds_entity_t tout = dds_create_topic(e.participant, &syncplc_NodeSample_desc, out, nullptr, nullptr);
  dds_entity_t tin = dds_create_topic(e.participant, &syncplc_NodeSample_desc, in, nullptr, nullptr);
  dds_qos_t* wq = qos(1);
  dds_qos_t* rq = qos(256);
  e.writer = dds_create_writer(e.participant, tout, wq, nullptr);
  e.reader = dds_create_reader(e.participant, tin, rq, nullptr);
  dds_delete_qos(wq);
  dds_delete_qos(rq);
  e.waitset = dds_create_waitset(e.participant);
  dds_waitset_attach(e.waitset, dds_create_readcondition(e.reader, DDS_ANY_STATE), 0);
  return e;
}

[[noreturn]] void dds_node(std::uint32_t domain, int index, std::int64_t until) {
  realtime_priority(50);
  DdsEnds e = dds_ends(domain, "bench_pong", "bench_ping");
  syncplc_NodeSample s{};
  void* ptr = &s;
  dds_sample_info_t info;
  dds_attach_t a;
  while (monotonic_ns() < until) {
    if (dds_waitset_wait(e.waitset, &a, 1, DDS_MSECS(100)) <= 0) continue;
    while (dds_take(e.reader, &ptr, &info, 1, 1) > 0) {
      if (!info.valid_data) continue;
      s.values[0] = index;
      dds_write(e.writer, &s);
    }
  }
  dds_delete(e.participant);
  _exit(0);
}

void dds_master(std::uint32_t domain, int nodes, std::int64_t period, std::int64_t duration, Result& r) {
  DdsEnds e = dds_ends(domain, "bench_ping", "bench_pong");
  // Wait until every node is matched both ways.
  dds_instance_handle_t h[256];
  while (dds_get_matched_subscriptions(e.writer, h, 256) < nodes || dds_get_matched_publications(e.reader, h, 256) < nodes)
    dds_sleepfor(DDS_MSECS(10));
  dds_sleepfor(DDS_MSECS(200));
  const std::int64_t until = monotonic_ns() + duration;
  std::vector<syncplc_NodeSample> buf(64);
  std::vector<void*> ptrs(64);
  for (std::size_t i = 0; i < 64; ++i) ptrs[i] = &buf[i];
  dds_sample_info_t infos[64];
  syncplc_NodeSample ping{};
  std::int64_t next = monotonic_ns() + period;
  for (std::uint64_t k = 1; next < until; ++k, next += period) {
    sleep_until(next);
    const std::int64_t t0 = monotonic_ns();
    ping.scan = k;
    dds_write(e.writer, &ping);
    int got = 0;
    std::int64_t last = 0;
    const std::int64_t deadline = next + period;
    while (got < nodes) {
      const std::int64_t now = monotonic_ns();
      if (now >= deadline) break;
      dds_attach_t a;
      dds_waitset_wait(e.waitset, &a, 1, deadline - now);
      const dds_return_t n = dds_take(e.reader, ptrs.data(), infos, 64, 64);
      const std::int64_t in = monotonic_ns();
      for (dds_return_t j = 0; j < n; ++j)
        if (infos[j].valid_data && buf[static_cast<std::size_t>(j)].scan == k) {
          ++got;
          last = in;
          r.single.push_back(in - t0);
        }
    }
    ++r.cycles;
    if (got < nodes) ++r.missed;
    else r.complete.push_back(last - t0);
  }
  dds_delete(e.participant);
}

// --- bare UDP ----------------------------------------------------------------

int udp_socket(std::uint16_t port) {
  int s = socket(AF_INET, SOCK_DGRAM, 0);
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_port = htons(port);
  a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  if (bind(s, reinterpret_cast<sockaddr*>(&a), sizeof a) != 0) std::perror("bind");
  return s;
}

std::uint16_t port_of(int s) {
  sockaddr_in a{};
  socklen_t len = sizeof a;
  getsockname(s, reinterpret_cast<sockaddr*>(&a), &len);
  return ntohs(a.sin_port);
}

[[noreturn]] void udp_node(int s, std::int64_t until) {
  realtime_priority(50);
  syncplc_NodeSample m{};
  while (monotonic_ns() < until) {
    pollfd p{s, POLLIN, 0};
    if (poll(&p, 1, 100) <= 0) continue;
    sockaddr_in from{};
    socklen_t len = sizeof from;
    const ssize_t n = recvfrom(s, &m, sizeof m, 0, reinterpret_cast<sockaddr*>(&from), &len);
    if (n == static_cast<ssize_t>(sizeof m)) sendto(s, &m, sizeof m, 0, reinterpret_cast<sockaddr*>(&from), len);
  }
  _exit(0);
}

void udp_master(int s, const std::vector<std::uint16_t>& ports, std::int64_t period, std::int64_t until, Result& r) {
  const int nodes = static_cast<int>(ports.size());
  std::vector<sockaddr_in> to(ports.size());
  for (std::size_t i = 0; i < ports.size(); ++i) {
    to[i].sin_family = AF_INET;
    to[i].sin_port = htons(ports[i]);
    to[i].sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  }
  syncplc_NodeSample m{};
  std::int64_t next = monotonic_ns() + 100'000'000;
  for (std::uint64_t k = 1; next < until; ++k, next += period) {
    sleep_until(next);
    const std::int64_t t0 = monotonic_ns();
    m.scan = k;
    for (auto& a : to) sendto(s, &m, sizeof m, 0, reinterpret_cast<sockaddr*>(&a), sizeof a);
    int got = 0;
    std::int64_t last = 0;
    const std::int64_t deadline = next + period;
    while (got < nodes) {
      const std::int64_t now = monotonic_ns();
      if (now >= deadline) break;
      pollfd p{s, POLLIN, 0};
      timespec ts{0, static_cast<long>(deadline - now)};
      if (ppoll(&p, 1, &ts, nullptr) <= 0) continue;
      syncplc_NodeSample in{};
      while (recv(s, &in, sizeof in, MSG_DONTWAIT) == static_cast<ssize_t>(sizeof in)) {
        const std::int64_t at = monotonic_ns();
        if (in.scan == k) {
          ++got;
          last = at;
          r.single.push_back(at - t0);
        }
      }
    }
    ++r.cycles;
    if (got < nodes) ++r.missed;
    else r.complete.push_back(last - t0);
  }
}

// --- report --------------------------------------------------------------------

double pct(std::vector<std::int64_t> v, double q) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  return static_cast<double>(v[std::min(v.size() - 1, static_cast<std::size_t>(q * static_cast<double>(v.size())))]) / 1000.0;
}

// Ends the node processes and returns their mean CPU time over `seconds`.
double children_cpu(const std::vector<pid_t>& pids, double seconds) {
  double total = 0;
  for (pid_t p : pids) kill(p, SIGTERM);
  for (pid_t p : pids) {
    int status = 0;
    rusage ru{};
    wait4(p, &status, 0, &ru);
    total += static_cast<double>(ru.ru_utime.tv_sec + ru.ru_stime.tv_sec) +
             static_cast<double>(ru.ru_utime.tv_usec + ru.ru_stime.tv_usec) / 1e6;
  }
  return pids.empty() ? 0 : 100.0 * total / static_cast<double>(pids.size()) / seconds;
}

void print(const char* transport, int nodes, const Result& r) {
  std::printf("| %s | %d | %" PRIu64 " | %.0f / %.0f / %.0f | %.0f / %.0f | %.3f %% | %.1f %% |\n", transport, nodes,
              r.cycles, pct(r.complete, 0.5), pct(r.complete, 0.99),
              r.complete.empty() ? 0.0 : static_cast<double>(*std::max_element(r.complete.begin(), r.complete.end())) / 1000,
              pct(r.single, 0.5), pct(r.single, 0.99),
              r.cycles ? 100.0 * static_cast<double>(r.missed) / static_cast<double>(r.cycles) : 0.0, r.cpu_per_node);
  std::fflush(stdout);
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"bench_dds_cycle: a master and N node processes over Cyclone DDS and bare UDP"};
  int nodes = 4;
  std::string period_text = "1ms", duration_text = "10s";
  std::uint32_t domain = 90;
  app.add_option("--nodes", nodes, "node processes")->check(CLI::Range(1, 100));
  app.add_option("--period", period_text, "the master's cycle");
  app.add_option("--duration", duration_text, "per transport");
  app.add_option("--domain", domain, "DDS domain")->check(CLI::Range(0, 230));
  CLI11_PARSE(app, argc, argv);
  std::string err;
  const auto period = syncplc::parse_duration_ns(period_text, &err);
  const auto duration = syncplc::parse_duration_ns(duration_text, &err);
  if (!period || !duration || *period <= 0 || *duration <= 0) {
    std::fprintf(stderr, "bad --period or --duration: %s\n", err.c_str());
    return 2;
  }

  {  // DDS: the master's cycles last `duration` once every node is matched;
     // the nodes are ended then (their CPU time includes discovery).
    Result r;
    std::vector<pid_t> pids;
    const std::int64_t start = syncplc::monotonic_ns();
    for (int i = 0; i < nodes; ++i) {
      const pid_t p = fork();
      if (p == 0) dds_node(domain, i, start + *duration + 120'000'000'000);
      pids.push_back(p);
    }
    realtime_priority(60);
    dds_master(domain, nodes, *period, *duration, r);
    r.cpu_per_node = children_cpu(pids, static_cast<double>(syncplc::monotonic_ns() - start) / 1e9);
    print("Cyclone DDS", nodes, r);
  }
  {  // bare UDP
    Result r;
    const std::int64_t start = syncplc::monotonic_ns();
    const std::int64_t until = start + 100'000'000 + *duration;
    std::vector<pid_t> pids;
    std::vector<std::uint16_t> ports;
    for (int i = 0; i < nodes; ++i) {
      const int s = udp_socket(0);
      ports.push_back(port_of(s));
      const pid_t p = fork();
      if (p == 0) udp_node(s, until + 120'000'000'000);
      close(s);
      pids.push_back(p);
    }
    const int s = udp_socket(0);
    udp_master(s, ports, *period, until, r);
    r.cpu_per_node = children_cpu(pids, static_cast<double>(syncplc::monotonic_ns() - start) / 1e9);
    print("bare UDP", nodes, r);
  }
  return 0;
}
