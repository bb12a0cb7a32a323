// How a scan signals a Modbus client driver's device threads (timing cycle,
// runtime/io/modbus_client/cycle_signal.hpp): three ways compared, each with
// one signalling thread (SCHED_FIFO 80 when permitted, as a task) that
// signals every period, and --waiters waiting threads (SCHED_OTHER, as the
// `mb:*` device threads):
//
//   futex    CycleSignal: an atomic increment and one FUTEX_WAKE for all waiters when any sleeps
//   eventfd  write(2) of 1 to each waiter's eventfd, which it ppolls (as the stop fd)
//   poll     an atomic increment; each waiter looks every --poll-us with clock_nanosleep
//
// Per way: the signal's cost on the signalling thread (what the scan pays
// for all waiters), the wake latency (signal start -> a waiter runs, all
// waiters' samples), both p50/p99/max, and the waiters' CPU
// (CLOCK_THREAD_CPUTIME_ID) as % of one core, summed.
//
// Usage: bench_cycle_wake [--n N] [--period-us U] [--poll-us U] [--waiters W]. Plain program.
#include <pthread.h>
#include <sched.h>
#include <sys/eventfd.h>
#include <poll.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <thread>
#include <vector>

#include "runtime/io/modbus_client/cycle_signal.hpp"

using syncplc::CycleSignal;
using syncplc::monotonic_ns;

namespace {

struct Result {
  std::vector<std::int64_t> cost, latency;
  double waiter_cpu = 0;
};

std::int64_t thread_cpu_ns() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return static_cast<std::int64_t>(t.tv_sec) * 1'000'000'000 + t.tv_nsec;
}

void sleep_until(std::int64_t at) {
  const timespec t{static_cast<time_t>(at / 1'000'000'000), static_cast<long>(at % 1'000'000'000)};
  while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &t, nullptr) == EINTR) {
  }
}

Result run(const std::string& way, int n, std::int64_t period, std::int64_t poll, int waiters) {
  Result r;
  r.cost.resize(n);
  CycleSignal sig;
  std::atomic<std::uint32_t> count{0};
  std::atomic<std::int64_t> started{0};
  std::atomic<bool> done{false};
  std::vector<int> efd(waiters);
  for (auto& f : efd) f = eventfd(0, EFD_CLOEXEC | EFD_NONBLOCK);
  std::atomic<std::int64_t> cpu{0};
  std::vector<std::vector<std::int64_t>> lat(waiters);
  std::vector<std::thread> threads;
  for (int w = 0; w < waiters; ++w)
    threads.emplace_back([&, w] {
      const std::int64_t c0 = thread_cpu_ns();
      std::uint32_t seen = 0;
      lat[w].reserve(n);
      while (!done.load(std::memory_order_acquire)) {
        std::uint32_t now_count = seen;
        if (way == "futex") {
          now_count = sig.wait(seen, monotonic_ns() + 100'000'000, done);
        } else if (way == "eventfd") {
          pollfd p{efd[w], POLLIN, 0};
          const timespec t{0, 100'000'000};
          if (ppoll(&p, 1, &t, nullptr) > 0) {
            std::uint64_t v;
            if (read(efd[w], &v, sizeof v) == sizeof v) now_count = seen + static_cast<std::uint32_t>(v);
          }
        } else {
          now_count = count.load(std::memory_order_acquire);
          if (now_count == seen) {
            sleep_until(monotonic_ns() + poll);
            continue;
          }
        }
        if (now_count == seen || done.load()) continue;
        lat[w].push_back(monotonic_ns() - started.load(std::memory_order_acquire));
        seen = now_count;
      }
      cpu.fetch_add(thread_cpu_ns() - c0);
    });
  sched_param sp{80};
  pthread_setschedparam(pthread_self(), SCHED_FIFO, &sp);
  const std::int64_t t0 = monotonic_ns();
  std::int64_t next = t0 + period;
  for (int k = 0; k < n; ++k) {
    sleep_until(next);
    next += period;
    const std::int64_t a = monotonic_ns();
    started.store(a, std::memory_order_release);
    if (way == "futex") sig.hand_over();
    else if (way == "eventfd") {
      const std::uint64_t one = 1;
      for (int f : efd) [[maybe_unused]] ssize_t w = write(f, &one, sizeof one);
    } else count.fetch_add(1, std::memory_order_seq_cst);
    r.cost[k] = monotonic_ns() - a;
  }
  sleep_until(next);
  done.store(true, std::memory_order_seq_cst);
  sig.hand_over();
  for (int f : efd) {
    const std::uint64_t one = 1;
    [[maybe_unused]] ssize_t w = write(f, &one, sizeof one);
  }
  for (auto& t : threads) t.join();
  sched_param other{0};
  pthread_setschedparam(pthread_self(), SCHED_OTHER, &other);
  r.waiter_cpu = 100.0 * static_cast<double>(cpu.load()) / static_cast<double>(monotonic_ns() - t0);
  for (auto& l : lat) r.latency.insert(r.latency.end(), l.begin(), l.end());
  for (int f : efd) close(f);
  return r;
}

std::int64_t pct(std::vector<std::int64_t> v, double p) {
  if (v.empty()) return -1;
  std::sort(v.begin(), v.end());
  return v[std::min(v.size() - 1, static_cast<std::size_t>(p * static_cast<double>(v.size())))];
}

}  // namespace

int main(int argc, char** argv) {
  int n = 5000;
  std::int64_t period = 1'000'000, poll = 50'000;
  int waiters = 4;
  for (int i = 1; i + 1 < argc; i += 2) {
    const std::string k = argv[i];
    if (k == "--n") n = std::atoi(argv[i + 1]);
    else if (k == "--period-us") period = std::atoll(argv[i + 1]) * 1000;
    else if (k == "--poll-us") poll = std::atoll(argv[i + 1]) * 1000;
    else if (k == "--waiters") waiters = std::atoi(argv[i + 1]);
  }
  std::printf("%d signals every %lld us to %d waiters; poll every %lld us\n", n, static_cast<long long>(period / 1000),
              waiters, static_cast<long long>(poll / 1000));
  std::printf("%-8s %28s %30s %12s\n", "way", "signal cost p50/p99/max ns", "wake latency p50/p99/max us", "waiter CPU");
  for (const char* way : {"futex", "eventfd", "poll"}) {
    const Result r = run(way, n, period, poll, waiters);
    std::printf("%-8s %10lld %8lld %8lld %10.1f %9.1f %9.1f %11.2f%%\n", way, static_cast<long long>(pct(r.cost, 0.5)),
                static_cast<long long>(pct(r.cost, 0.99)), static_cast<long long>(pct(r.cost, 1.0)),
                pct(r.latency, 0.5) * 1e-3, pct(r.latency, 0.99) * 1e-3, pct(r.latency, 1.0) * 1e-3, r.waiter_cpu);
  }
  return 0;
}
