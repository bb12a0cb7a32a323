// A Modbus TCP load generator for bench/modbus_bench.sh (docs/benchmarks.md,
// "Modbus TCP server").
//
// N client threads, each with its own libmodbus TCP connection, loop
// modbus_read_registers(address, count) (FC 3, by default 125 holding
// registers from 1024) back to back, one request in flight per connection:
// the next request goes out when the previous reply is in. All threads
// connect first, then start together; requests that start during the warm-up
// are not counted, then every request that starts within the measured window
// of --duration seconds is: a success (the reply carried `count` registers)
// or a failure (timeout, exception, connection lost: the thread then
// reconnects, and stops if it cannot). Per-request latency is the wall time of
// modbus_read_registers, successes only.
//
// Prints one human-readable line and a last, machine-readable one:
//   RESULT clients=N ok=... fail=... rps=... p50_us=... p99_us=... max_us=... all_ok=...
// with rps = successes / --duration (the window, not the threads' own times)
// and all_ok the successes including the warm-up.
//
// Usage: bench_modbus_load --port P [--host H] [--clients N] [--duration S]
//                          [--warmup S] [--address A] [--count N] [--timeout-ms T]
#include <modbus/modbus.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <atomic>
#include <barrier>
#include <cerrno>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <string>
#include <thread>
#include <vector>

namespace {

using Clock = std::chrono::steady_clock;

struct Options {
  std::string host = "127.0.0.1";
  int port = 502;
  int clients = 1;
  double duration_s = 5;
  double warmup_s = 1;
  int address = 1024;
  int count = 125;
  int timeout_ms = 1000;
};

struct ClientResult {
  std::uint64_t all_ok = 0;  // successes, warm-up included (the server's CPU time per request needs them all)
  std::uint64_t ok = 0;
  std::uint64_t fail = 0;
  std::uint64_t reconnects = 0;
  bool connected = false;
  bool gave_up = false;
  std::string first_error;
  std::vector<std::uint32_t> latency_ns;  // successes in the window
};

modbus_t* connect(const Options& o, std::string* error) {
  modbus_t* ctx = modbus_new_tcp(o.host.c_str(), o.port);
  if (!ctx) {
    *error = modbus_strerror(errno);
    return nullptr;
  }
  modbus_set_response_timeout(ctx, static_cast<std::uint32_t>(o.timeout_ms / 1000),
                              static_cast<std::uint32_t>(o.timeout_ms % 1000) * 1000);
  if (modbus_connect(ctx) != 0) {
    *error = std::string("connect: ") + modbus_strerror(errno);
    modbus_free(ctx);
    return nullptr;
  }
  return ctx;
}

void client(const Options& o, ClientResult& r, std::barrier<>& start, const Clock::time_point& t_measure,
            const Clock::time_point& t_end) {
  std::string err;
  modbus_t* ctx = connect(o, &err);
  r.connected = ctx != nullptr;
  if (!ctx) r.first_error = err;
  start.arrive_and_wait();  // the main thread sets t_measure and t_end before it arrives
  if (!ctx) return;
  std::vector<std::uint16_t> regs(static_cast<std::size_t>(o.count));
  r.latency_ns.reserve(1 << 16);
  for (;;) {
    const Clock::time_point t0 = Clock::now();
    if (t0 >= t_end) break;
    const int rc = modbus_read_registers(ctx, o.address, o.count, regs.data());
    const Clock::time_point t1 = Clock::now();
    if (rc == o.count) ++r.all_ok;
    if (t0 < t_measure) {
      if (rc == o.count) continue;
    } else if (rc == o.count) {
      ++r.ok;
      r.latency_ns.push_back(static_cast<std::uint32_t>(
          std::min<std::int64_t>(std::chrono::duration_cast<std::chrono::nanoseconds>(t1 - t0).count(), UINT32_MAX)));
      continue;
    } else {
      ++r.fail;
    }
    // A failed request: note why, and start again on a fresh connection (a
    // late reply would otherwise answer the next request).
    if (r.first_error.empty()) r.first_error = rc < 0 ? modbus_strerror(errno) : "short reply";
    modbus_close(ctx);
    modbus_free(ctx);
    ctx = connect(o, &err);
    if (!ctx) {
      r.gave_up = true;
      break;
    }
    ++r.reconnects;
  }
  if (ctx) {
    modbus_close(ctx);
    modbus_free(ctx);
  }
}

double us(std::uint64_t ns) { return static_cast<double>(ns) * 1e-3; }

}  // namespace

int main(int argc, char** argv) {
  Options o;
  CLI::App app{"bench_modbus_load: N Modbus TCP clients reading holding registers (FC 3) back to back"};
  app.add_option("--host", o.host, "server address");
  app.add_option("--port", o.port, "server port")->required()->check(CLI::Range(1, 65535));
  app.add_option("--clients,-n", o.clients, "client threads, one connection each")->check(CLI::Range(1, 4096));
  app.add_option("--duration,-d", o.duration_s, "measured window, seconds")->check(CLI::PositiveNumber);
  app.add_option("--warmup", o.warmup_s, "seconds of requests before the window (not counted)")
      ->check(CLI::NonNegativeNumber);
  app.add_option("--address", o.address, "first holding register")->check(CLI::Range(0, 65535));
  app.add_option("--count", o.count, "registers per request (1..125)")->check(CLI::Range(1, 125));
  app.add_option("--timeout-ms", o.timeout_ms, "response timeout")->check(CLI::Range(1, 60000));
  CLI11_PARSE(app, argc, argv);

  std::vector<ClientResult> results(static_cast<std::size_t>(o.clients));
  std::barrier<> start(o.clients + 1);
  Clock::time_point t_measure, t_end;
  std::vector<std::thread> threads;
  threads.reserve(results.size());
  for (auto& r : results) threads.emplace_back([&, rp = &r] { client(o, *rp, start, t_measure, t_end); });
  // Every client has connected (or failed to) when the barrier opens.
  const auto warm = std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(o.warmup_s));
  const auto window = std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(o.duration_s));
  t_measure = Clock::now() + warm;
  t_end = t_measure + window;
  start.arrive_and_wait();
  for (auto& t : threads) t.join();

  std::uint64_t all_ok = 0, ok = 0, fail = 0, reconnects = 0;
  int not_connected = 0, gave_up = 0;
  std::string first_error;
  std::vector<std::uint32_t> lat;
  for (auto& r : results) {
    all_ok += r.all_ok;
    ok += r.ok;
    fail += r.fail;
    reconnects += r.reconnects;
    not_connected += r.connected ? 0 : 1;
    gave_up += r.gave_up ? 1 : 0;
    if (first_error.empty()) first_error = r.first_error;
    lat.insert(lat.end(), r.latency_ns.begin(), r.latency_ns.end());
  }
  // Percentile q: the smallest sample with at least q of all samples at or below it.
  auto pct = [&lat](double q) -> std::uint64_t {
    if (lat.empty()) return 0;
    auto k = static_cast<std::size_t>(q * static_cast<double>(lat.size()));
    if (k >= lat.size()) k = lat.size() - 1;
    std::nth_element(lat.begin(), lat.begin() + static_cast<std::ptrdiff_t>(k), lat.end());
    return lat[k];
  };
  const std::uint64_t p50 = pct(0.50), p99 = pct(0.99);
  const std::uint64_t mx = lat.empty() ? 0 : *std::max_element(lat.begin(), lat.end());
  const double rps = static_cast<double>(ok) / o.duration_s;

  std::printf("bench_modbus_load: %s:%d, %d client(s), FC 3 x %d registers at %d, %.1f s (+%.1f s warm-up): "
              "%.0f req/s, %llu ok, %llu failed, latency p50 %.1f us p99 %.1f us max %.1f us\n",
              o.host.c_str(), o.port, o.clients, o.count, o.address, o.duration_s, o.warmup_s, rps,
              static_cast<unsigned long long>(ok), static_cast<unsigned long long>(fail), us(p50), us(p99), us(mx));
  if (not_connected || gave_up || fail)
    std::printf("bench_modbus_load: %d client(s) could not connect, %d gave up after a failure, %llu reconnect(s); "
                "first error: %s\n",
                not_connected, gave_up, static_cast<unsigned long long>(reconnects),
                first_error.empty() ? "-" : first_error.c_str());
  std::printf("RESULT clients=%d ok=%llu fail=%llu not_connected=%d rps=%.0f p50_us=%.1f p99_us=%.1f max_us=%.1f "
              "all_ok=%llu\n",
              o.clients, static_cast<unsigned long long>(ok), static_cast<unsigned long long>(fail), not_connected,
              rps, us(p50), us(p99), us(mx), static_cast<unsigned long long>(all_ok));
  return not_connected == o.clients ? 1 : 0;
}
