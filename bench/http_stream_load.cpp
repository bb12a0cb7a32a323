// Load generator for the HTTP API's live stream (docs/http-api.md, GET
// /api/v1/stream; docs/benchmarks.md, "HTTP live streams"): N clients, each
// one Server-Sent Events stream of the same M refs at R updates/s, on one
// thread (epoll, plain sockets, no HTTP library), like N HMI pages open at
// once.
//
// Per event it records, with the receive time taken on CLOCK_REALTIME right
// after the recv() that completed the event's bytes (before any parsing):
//
//   latency    receive time minus the planned release, in wall time, of the
//              scan whose values the event carries: the scan's logical
//              release comes in the event itself (--release-ref, a tag the
//              project fills with a TON's ET in ms: the tasks' time axis),
//              and GET /status's runtime.epoch_wall_ns puts that axis on the
//              wall clock. Scan release -> the browser's socket.
//   age        the server's t_ns (CLOCK_REALTIME when it built the event)
//              minus the same release: how old the snapshot was when read.
//   transport  receive time minus t_ns: serialise, send, loopback, wake-up.
//
// latency = age + transport. All three use CLOCK_REALTIME of one machine;
// the offset CLOCK_REALTIME - CLOCK_MONOTONIC is checked at the start and the
// end, and a step of the wall clock in between is reported (it would shift
// every number by the step).
//
// Events received in the first --warmup seconds after the last client has
// connected (the first event of each stream, anything queued while
// connecting) are counted apart and left out of the statistics; then it
// prints "bench_http_stream_load: measuring" and measures for --duration
// seconds. The time each connect() took is reported: the server's listen
// backlog drops SYNs when many clients connect at once, and a dropped SYN is
// retried after 1 s, then 3 s.
//
// A "repeated" event carries the same scan as the stream's previous one: the
// server sent two ticks back to back (a tick more than a period late is
// followed at once by the next).
//
// Usage: bench_http_stream_load --port P --refs a,b,... [--clients 50] [--rate 20]
//          [--duration 20] [--warmup 2] [--release-ref release_ms] [--host 127.0.0.1] [--no-stagger]
//
// The clients connect one after the other, spread over one period (1/rate):
// client i at a random instant of the i-th N-th of it (a fixed seed). Each
// stream's server-side ticks keep the phase of its connection, so the
// streams' events are spread over the period as those of independent HMI
// pages would be, and their phases against the task's scan grid are random
// (evenly spaced connections 1/(rate N) apart would all have the same phase
// against a 1 ms grid when 1/(rate N) is a multiple of 1 ms, and the age of
// the data would be the same for all). --no-stagger connects them all at
// once (their events then come in bursts of N).
// The last line is machine-readable: "RESULT key=value ...", times in ns.
#include <arpa/inet.h>
#include <fcntl.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <sys/epoll.h>
#include <sys/resource.h>
#include <sys/socket.h>
#include <time.h>
#include <unistd.h>

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <iostream>
#include <random>
#include <string>
#include <vector>

namespace {

struct Options {
  std::string host = "127.0.0.1";
  int port = 8080;
  int clients = 50;
  double rate = 20;
  std::string refs;
  std::string release_ref = "release_ms";
  double duration_s = 20;
  double warmup_s = 2;
  bool stagger = true;  // connect the clients evenly over one period (independent pages), not all at once
};

[[noreturn]] void usage(const std::string& msg) {
  std::cerr << "bench_http_stream_load: " << msg << "\n"
            << "usage: bench_http_stream_load --port P --refs a,b,... [--clients N] [--rate R] [--duration S]\n"
            << "                              [--warmup S] [--release-ref TAG] [--host ADDR] [--no-stagger]\n";
  std::exit(2);
}

Options parse(int argc, char** argv) {
  Options o;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto value = [&]() -> std::string {
      if (i + 1 >= argc) usage("missing value after " + a);
      return argv[++i];
    };
    if (a == "--host") o.host = value();
    else if (a == "--port") o.port = std::stoi(value());
    else if (a == "--clients") o.clients = std::stoi(value());
    else if (a == "--rate") o.rate = std::stod(value());
    else if (a == "--refs") o.refs = value();
    else if (a == "--release-ref") o.release_ref = value();
    else if (a == "--duration") o.duration_s = std::stod(value());
    else if (a == "--warmup") o.warmup_s = std::stod(value());
    else if (a == "--no-stagger") o.stagger = false;
    else if (a == "-h" || a == "--help") usage("help");
    else usage("unknown argument " + a);
  }
  if (o.refs.empty()) usage("--refs is required");
  if (o.clients < 1 || o.duration_s <= 0 || o.warmup_s < 0 || o.rate <= 0) usage("bad --clients, --rate, --duration or --warmup");
  return o;
}

std::int64_t now(clockid_t c) {
  timespec ts;
  clock_gettime(c, &ts);
  return static_cast<std::int64_t>(ts.tv_sec) * 1'000'000'000 + ts.tv_nsec;
}
std::int64_t wall_ns() { return now(CLOCK_REALTIME); }
std::int64_t mono_ns() { return now(CLOCK_MONOTONIC); }

int connect_to(const Options& o) {
  const int fd = socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
  if (fd < 0) return -1;
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_port = htons(static_cast<std::uint16_t>(o.port));
  if (inet_pton(AF_INET, o.host.c_str(), &a.sin_addr) != 1 || connect(fd, reinterpret_cast<sockaddr*>(&a), sizeof a) != 0) {
    close(fd);
    return -1;
  }
  const int one = 1;
  setsockopt(fd, IPPROTO_TCP, TCP_NODELAY, &one, sizeof one);
  return fd;
}

bool send_all(int fd, const std::string& s) {
  std::size_t at = 0;
  while (at < s.size()) {
    const ssize_t n = send(fd, s.data() + at, s.size() - at, MSG_NOSIGNAL);
    if (n <= 0) return false;
    at += static_cast<std::size_t>(n);
  }
  return true;
}

std::string request(const Options& o, const std::string& target, bool close_after) {
  return "GET " + target + " HTTP/1.1\r\nHost: " + o.host + ":" + std::to_string(o.port) +
         "\r\nAccept: " + (close_after ? "application/json" : "text/event-stream") +
         (close_after ? "\r\nConnection: close" : "") + "\r\n\r\n";
}

// GET /api/v1/status once (Connection: close): runtime.epoch_wall_ns.
std::int64_t epoch_wall_ns(const Options& o) {
  const int fd = connect_to(o);
  if (fd < 0) return 0;
  std::string in;
  if (send_all(fd, request(o, "/api/v1/status", true))) {
    char buf[65536];
    for (ssize_t n; (n = recv(fd, buf, sizeof buf, 0)) > 0;) in.append(buf, static_cast<std::size_t>(n));
  }
  close(fd);
  const auto body = in.find("\r\n\r\n");
  if (body == std::string::npos) return 0;
  auto j = nlohmann::json::parse(in.substr(body + 4), nullptr, false);
  if (j.is_discarded()) return 0;
  return j["runtime"].value("epoch_wall_ns", std::int64_t{0});
}

struct Conn {
  int fd = -1;
  int index = 0;
  bool headers_done = false;
  bool chunked = false;
  bool closed = false;
  std::string raw;    // bytes as received, not yet decoded
  std::string sse;    // the decoded body, not yet split into events
  std::uint64_t events = 0;        // in the measuring window
  std::uint64_t warmup_events = 0;
};

struct Totals {
  std::vector<std::int64_t> latency, age, transport;
  std::uint64_t events = 0, warmup_events = 0, bad_events = 0, error_events = 0, missing_values = 0;
  std::uint64_t bytes = 0, disconnects = 0, repeated = 0;
  std::string first_problem;
};

void problem(Totals& t, const std::string& what) {
  if (t.first_problem.empty()) t.first_problem = what;
}

// One SSE event's text (without the blank line that ends it).
void on_event(const Options& o, std::int64_t epoch_wall, std::size_t want_values, Conn& c, const std::string& text,
              std::int64_t recv_ns, bool measuring, Totals& t, std::vector<double>& last_release) {
  std::string name, data;
  for (std::size_t at = 0; at < text.size();) {
    std::size_t nl = text.find('\n', at);
    if (nl == std::string::npos) nl = text.size();
    const std::string line = text.substr(at, nl - at);
    if (line.rfind("event: ", 0) == 0) name = line.substr(7);
    else if (line.rfind("data: ", 0) == 0) data += line.substr(6);
    at = nl + 1;
  }
  if (name == "error") {
    ++t.error_events;
    problem(t, "client " + std::to_string(c.index) + ": error event: " + data);
    return;
  }
  if (name != "values") {
    ++t.bad_events;
    problem(t, "client " + std::to_string(c.index) + ": unexpected event '" + name + "'");
    return;
  }
  auto j = nlohmann::json::parse(data, nullptr, false);
  if (j.is_discarded() || !j.contains("t_ns") || !j.contains("values")) {
    ++t.bad_events;
    problem(t, "client " + std::to_string(c.index) + ": unreadable event data");
    return;
  }
  const auto& values = j["values"];
  if (values.size() != want_values) ++t.missing_values;
  if (!values.contains(o.release_ref) || !values[o.release_ref].is_number()) {
    ++t.bad_events;
    problem(t, "client " + std::to_string(c.index) + ": no number '" + o.release_ref + "' in the event");
    return;
  }
  if (!measuring) {
    ++c.warmup_events;
    ++t.warmup_events;
    return;
  }
  const double release_ms = values[o.release_ref].get<double>();
  if (release_ms == last_release[static_cast<std::size_t>(c.index)]) ++t.repeated;
  last_release[static_cast<std::size_t>(c.index)] = release_ms;
  const std::int64_t release_wall = epoch_wall + std::llround(release_ms * 1e6);
  const std::int64_t t_ns = j["t_ns"].get<std::int64_t>();
  ++c.events;
  ++t.events;
  t.latency.push_back(recv_ns - release_wall);
  t.age.push_back(t_ns - release_wall);
  t.transport.push_back(recv_ns - t_ns);
}

// Decodes what arrived: headers once, then the chunked (or plain) body into
// c.sse, then every complete event.
void on_data(const Options& o, std::int64_t epoch_wall, std::size_t want_values, Conn& c, std::int64_t recv_ns,
             bool measuring, Totals& t, std::vector<double>& last_release) {
  if (!c.headers_done) {
    const auto end = c.raw.find("\r\n\r\n");
    if (end == std::string::npos) return;
    const std::string head = c.raw.substr(0, end);
    if (head.rfind("HTTP/1.1 200", 0) != 0) {
      problem(t, "client " + std::to_string(c.index) + ": " + head.substr(0, head.find('\r')) + " " + c.raw.substr(end + 4, 200));
      c.closed = true;
      return;
    }
    std::string lower = head;
    std::transform(lower.begin(), lower.end(), lower.begin(), [](unsigned char ch) { return std::tolower(ch); });
    c.chunked = lower.find("transfer-encoding: chunked") != std::string::npos;
    c.headers_done = true;
    c.raw.erase(0, end + 4);
  }
  if (c.chunked) {
    for (;;) {
      const auto eol = c.raw.find("\r\n");
      if (eol == std::string::npos) break;
      const std::size_t size = std::strtoul(c.raw.substr(0, eol).c_str(), nullptr, 16);
      if (size == 0) {  // the server ended the stream
        c.closed = true;
        break;
      }
      if (c.raw.size() < eol + 2 + size + 2) break;
      c.sse.append(c.raw, eol + 2, size);
      c.raw.erase(0, eol + 2 + size + 2);
    }
  } else {
    c.sse += c.raw;
    c.raw.clear();
  }
  for (std::size_t end; (end = c.sse.find("\n\n")) != std::string::npos;) {
    on_event(o, epoch_wall, want_values, c, c.sse.substr(0, end), recv_ns, measuring, t, last_release);
    c.sse.erase(0, end + 2);
  }
}

struct Quantiles {
  std::int64_t p50 = 0, p99 = 0, max = 0, min = 0;
};
Quantiles quantiles(std::vector<std::int64_t>& v) {
  Quantiles q;
  if (v.empty()) return q;
  std::sort(v.begin(), v.end());
  auto at = [&](double p) {
    auto r = static_cast<std::size_t>(p * static_cast<double>(v.size()));
    return v[std::min(r, v.size() - 1)];
  };
  q.p50 = at(0.50);
  q.p99 = at(0.99);
  q.max = v.back();
  q.min = v.front();
  return q;
}

double cpu_s() {
  rusage ru{};
  getrusage(RUSAGE_SELF, &ru);
  return static_cast<double>(ru.ru_utime.tv_sec + ru.ru_stime.tv_sec) +
         1e-6 * static_cast<double>(ru.ru_utime.tv_usec + ru.ru_stime.tv_usec);
}

std::string us(std::int64_t ns) {
  char b[32];
  std::snprintf(b, sizeof b, "%.1f", static_cast<double>(ns) * 1e-3);
  return b;
}

}  // namespace

int main(int argc, char** argv) {
  const Options o = parse(argc, argv);
  std::size_t want_values = 1;
  for (char ch : o.refs) want_values += ch == ',';

  const std::int64_t offset0 = wall_ns() - mono_ns();
  const std::int64_t epoch_wall = epoch_wall_ns(o);
  if (epoch_wall <= 0) {
    std::cerr << "bench_http_stream_load: no runtime.epoch_wall_ns from GET http://" << o.host << ":" << o.port
              << "/api/v1/status\n";
    return 1;
  }

  const int ep = epoll_create1(EPOLL_CLOEXEC);
  std::vector<Conn> conns(static_cast<std::size_t>(o.clients));
  char rate[32];
  std::snprintf(rate, sizeof rate, "%g", o.rate);
  const std::string req = request(o, "/api/v1/stream?refs=" + o.refs + "&rate=" + rate, false);
  const std::int64_t t0 = mono_ns();
  const auto spacing_ns = std::max<std::int64_t>(1, static_cast<std::int64_t>(1e9 / o.rate / o.clients));
  std::mt19937_64 rng(14);
  std::int64_t connect_max_ns = 0;
  int connects_over_1s = 0;
  for (int i = 0; i < o.clients; ++i) {
    Conn& c = conns[static_cast<std::size_t>(i)];
    c.index = i;
    if (o.stagger) {
      const std::int64_t at = t0 + i * spacing_ns + static_cast<std::int64_t>(rng() % static_cast<std::uint64_t>(spacing_ns));
      timespec ts{static_cast<time_t>(at / 1'000'000'000), static_cast<long>(at % 1'000'000'000)};
      while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, nullptr) == EINTR) {
      }
    }
    const std::int64_t c0 = mono_ns();
    c.fd = connect_to(o);
    const std::int64_t took = mono_ns() - c0;
    connect_max_ns = std::max(connect_max_ns, took);
    connects_over_1s += took >= 1'000'000'000;
    if (c.fd < 0 || !send_all(c.fd, req)) {
      std::cerr << "bench_http_stream_load: client " << i << ": cannot connect or send: " << std::strerror(errno) << "\n";
      return 1;
    }
    fcntl(c.fd, F_SETFL, fcntl(c.fd, F_GETFL) | O_NONBLOCK);
    epoll_event ev{};
    ev.events = EPOLLIN | EPOLLRDHUP;
    ev.data.u32 = static_cast<std::uint32_t>(i);
    epoll_ctl(ep, EPOLL_CTL_ADD, c.fd, &ev);
  }
  const std::int64_t connected_ns = mono_ns() - t0;

  Totals t;
  t.latency.reserve(static_cast<std::size_t>(o.clients * o.rate * o.duration_s * 1.1));
  t.age.reserve(t.latency.capacity());
  t.transport.reserve(t.latency.capacity());
  std::vector<double> last_release(conns.size(), -1.0);
  const std::int64_t warm_end = t0 + connected_ns + static_cast<std::int64_t>(o.warmup_s * 1e9);
  const std::int64_t end = warm_end + static_cast<std::int64_t>(o.duration_s * 1e9);
  double cpu_at_warm = -1;
  std::int64_t warm_mono = 0;
  std::vector<epoll_event> ready(conns.size());
  char buf[65536];
  for (;;) {
    const std::int64_t m = mono_ns();
    if (m >= end) break;
    if (cpu_at_warm < 0 && m >= warm_end) {
      cpu_at_warm = cpu_s();
      warm_mono = m;
      std::cout << "bench_http_stream_load: measuring" << std::endl;
    }
    const int timeout_ms = static_cast<int>(std::max<std::int64_t>(1, std::min<std::int64_t>(end - m, warm_end > m ? warm_end - m : end - m) / 1'000'000));
    const int n = epoll_wait(ep, ready.data(), static_cast<int>(ready.size()), timeout_ms);
    for (int k = 0; k < n; ++k) {
      Conn& c = conns[ready[static_cast<std::size_t>(k)].data.u32];
      for (;;) {
        const ssize_t got = recv(c.fd, buf, sizeof buf, 0);
        if (got > 0) {
          const std::int64_t recv_ns = wall_ns();
          const bool measuring = mono_ns() >= warm_end;
          t.bytes += static_cast<std::uint64_t>(got);
          c.raw.append(buf, static_cast<std::size_t>(got));
          on_data(o, epoch_wall, want_values, c, recv_ns, measuring, t, last_release);
          if (c.closed) break;
          continue;
        }
        if (got < 0 && (errno == EAGAIN || errno == EWOULDBLOCK)) break;
        c.closed = true;  // EOF or an error
        break;
      }
      if (c.closed) {
        epoll_ctl(ep, EPOLL_CTL_DEL, c.fd, nullptr);
        close(c.fd);
        c.fd = -1;
        ++t.disconnects;
        problem(t, "client " + std::to_string(c.index) + ": the server closed the stream");
      }
    }
  }
  const double window_s = static_cast<double>(mono_ns() - (warm_mono ? warm_mono : warm_end)) * 1e-9;
  const double cpu = cpu_s() - std::max(0.0, cpu_at_warm);
  for (auto& c : conns)
    if (c.fd >= 0) close(c.fd);
  close(ep);
  const std::int64_t offset1 = wall_ns() - mono_ns();

  std::uint64_t per_min = ~std::uint64_t{0}, per_max = 0;
  for (const auto& c : conns) {
    per_min = std::min(per_min, c.events);
    per_max = std::max(per_max, c.events);
  }
  const Quantiles lat = quantiles(t.latency), age = quantiles(t.age), tr = quantiles(t.transport);
  const double eps = static_cast<double>(t.events) / window_s;
  std::cout << "bench_http_stream_load: " << o.clients << " streams x " << want_values << " refs at " << o.rate
            << "/s, connected in " << us(connected_ns) << " us (" << (o.stagger ? "staggered" : "all at once")
            << "; slowest connect() " << us(connect_max_ns) << " us, " << connects_over_1s << " took >= 1 s); measured " << window_s << " s after " << o.warmup_s
            << " s warm-up\n";
  std::cout << "bench_http_stream_load: events " << t.events << " (" << eps << "/s; per stream " << per_min << ".."
            << per_max << "), warm-up events " << t.warmup_events << ", repeated (same scan as the stream's previous event) " << t.repeated
            << ", bytes " << t.bytes << "\n";
  std::cout << "bench_http_stream_load: scan release -> client  p50 " << us(lat.p50) << "  p99 " << us(lat.p99)
            << "  max " << us(lat.max) << " us (min " << us(lat.min) << ")\n";
  std::cout << "bench_http_stream_load: scan release -> server t_ns  p50 " << us(age.p50) << "  p99 " << us(age.p99)
            << "  max " << us(age.max) << " us (min " << us(age.min) << ")\n";
  std::cout << "bench_http_stream_load: server t_ns -> client  p50 " << us(tr.p50) << "  p99 " << us(tr.p99)
            << "  max " << us(tr.max) << " us (min " << us(tr.min) << ")\n";
  std::cout << "bench_http_stream_load: own CPU " << cpu << " s in the window (" << 100 * cpu / window_s << " %)\n";
  if (std::llabs(offset1 - offset0) > 100'000)
    std::cout << "bench_http_stream_load: WARNING: the wall clock stepped by " << us(offset1 - offset0)
              << " us against CLOCK_MONOTONIC during the run\n";
  if (!t.first_problem.empty()) std::cout << "bench_http_stream_load: first problem: " << t.first_problem << "\n";
  std::cout << "RESULT clients=" << o.clients << " events=" << t.events << " events_per_s=" << eps
            << " per_stream_min=" << per_min << " per_stream_max=" << per_max << " window_s=" << window_s
            << " lat_p50_ns=" << lat.p50 << " lat_p99_ns=" << lat.p99 << " lat_max_ns=" << lat.max
            << " lat_min_ns=" << lat.min << " age_p50_ns=" << age.p50 << " age_p99_ns=" << age.p99
            << " age_max_ns=" << age.max << " age_min_ns=" << age.min << " tr_p50_ns=" << tr.p50
            << " tr_p99_ns=" << tr.p99 << " tr_max_ns=" << tr.max << " bad=" << t.bad_events
            << " errors=" << t.error_events << " missing=" << t.missing_values << " disconnects=" << t.disconnects
            << " repeated=" << t.repeated << " cpu_pct=" << 100 * cpu / window_s
            << " clock_step_ns=" << (offset1 - offset0) << " connect_max_ns=" << connect_max_ns
            << " connects_over_1s=" << connects_over_1s << "\n";
  return (t.disconnects || t.bad_events || t.error_events) ? 3 : 0;
}
