// TRANSIENT_SYNC on the workload of issue 15, the one its Ruckig figures were
// measured on: N axes at rest at 0, seeded asymmetric limits per axis
// (v_max ~ U[1, 3], v_min = -v_max U[0.5, 1], a_max ~ U[5, 20],
// a_min = -a_max U[0.5, 1]), a 1 ms cycle, and every 500 ms a new step target
// ~ U[-0.5, 0.5] for every axis with zero target velocity. Most moves of the
// slowest axis outlast 500 ms, so nearly every axis is in a transient at
// every scan and targets change in the middle of transients.
//
// For each N the block runs through the block harness (the execute() a task
// calls, with the finite-input check a task makes) for --seconds of cycles,
// twice on the same sequence:
//   1. untimed: total time / cycles = the mean per scan, by the wall clock
//      and by the thread's CPU time (the latter leaves out time the CPU spent
//      on other processes);
//   2. every scan timed with clock_gettime (about 20 ns added to each scan):
//      p50, p99 and max per scan, and the mean of the scans at which the
//      targets change (every axis starts a new move: Table I afresh, scaling
//      and lock for each).
// Then, from a third run that reads the outputs: how many times an axis began
// tracking its target ahead of the common arrival (an axis that reached its
// target while others of the same move were still on their way, the
// synchronizer's failure), and the moves. rule 2 (independent filters, no
// synchronization) is run the same way as the floor: what the N filters cost
// alone.
//
// Usage: bench_sync_workload [--axes 6,100,1000] [--seconds 60] [--cpu C]
//                            [--seed S] [--rule 0|1|2] [--no-floor]
// Pin it (--cpu) on an otherwise idle CPU; run as root for mlockall.
#include <sched.h>
#include <sys/mman.h>
#include <time.h>

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <sstream>
#include <string>
#include <vector>

#include "bench/sync_workload.hpp"
#include "fblocks/library.hpp"
#include "runtime/core/block_harness.hpp"

namespace {

using namespace syncplc;

using bench::kMoveEvery;
using Workload = bench::SyncWorkload;

std::int64_t clock_ns(clockid_t id) {
  timespec ts{};
  clock_gettime(id, &ts);
  return static_cast<std::int64_t>(ts.tv_sec) * 1'000'000'000 + ts.tv_nsec;
}
std::int64_t now_ns() { return clock_ns(CLOCK_MONOTONIC); }
// The thread's CPU time: what the scans cost, without the time other
// processes held the CPU (a loaded machine).
std::int64_t cpu_ns() { return clock_ns(CLOCK_THREAD_CPUTIME_ID); }

// One TRANSIENT_SYNC instance fed with the workload.
class Rig {
 public:
  Rig(const Workload& w, int rule) : w_(w), h_(builtin_blocks(), "TRANSIENT_SYNC", options(w.n, rule)) {
    if (!h_.ok()) return;
    for (int i = 0; i < w.n; ++i) {
      const auto k = static_cast<std::uint32_t>(i);
      const bench::AxisLimits& l = w.limits[k];
      h_.set<double>("v_min", k, l.v_min);
      h_.set<double>("v_max", k, l.v_max);
      h_.set<double>("a_min", k, l.a_min);
      h_.set<double>("a_max", k, l.a_max);
      h_.set<double>("r", k, 0.0);
      h_.set<double>("r_dot", k, 0.0);
    }
    r_ = &h_.cell("r", 0);  // array pins: consecutive cells
    tracking_ = &h_.cell("tracking", 0);
    arrival_ = &h_.cell("arrival");
  }
  bool ok() const { return h_.ok(); }
  std::string errors() const {
    std::string s;
    for (const auto& e : h_.errors()) s += e + "; ";
    return s;
  }
  // Sets the targets of the move that starts at `cycle`, if one does.
  void targets_for(int cycle) {
    if (const double* t = w_.targets_at(cycle))
      for (int i = 0; i < w_.n; ++i) r_[i].set<double>(t[i]);
  }
  void scan() { h_.scan(); }
  bool tracking(int i) const { return tracking_[i].get<bool>(); }
  std::int64_t arrival() const { return arrival_->get<std::int64_t>(); }

 private:
  static BlockHarness::Options options(int n, int rule) {
    BlockHarness::Options o;
    o.params = {{"n", std::to_string(n)}, {"rule", std::to_string(rule)}};
    o.period_ns = bench::kWorkloadPeriodNs;
    return o;
  }
  const Workload& w_;
  BlockHarness h_;
  Cell* r_ = nullptr;
  Cell* tracking_ = nullptr;
  Cell* arrival_ = nullptr;
};

struct Timing {
  double mean_ns = 0;      // untimed pass, wall clock
  double mean_cpu_ns = 0;  // untimed pass, the thread's CPU time
  double p50_ns = 0, p99_ns = 0, max_ns = 0;  // timed pass
  double move_mean_ns = 0, move_max_ns = 0;     // timed pass, the scans at which the targets change
};

Timing time_rule(const Workload& w, int rule, int cycles) {
  Timing t;
  {
    Rig rig(w, rule);
    if (!rig.ok()) {
      std::fprintf(stderr, "TRANSIENT_SYNC did not build: %s\n", rig.errors().c_str());
      std::exit(1);
    }
    const std::int64_t t0 = now_ns(), c0 = cpu_ns();
    for (int c = 0; c < cycles; ++c) {
      rig.targets_for(c);
      rig.scan();
    }
    t.mean_cpu_ns = static_cast<double>(cpu_ns() - c0) / cycles;
    t.mean_ns = static_cast<double>(now_ns() - t0) / cycles;
  }
  {
    Rig rig(w, rule);
    std::vector<std::int64_t> d(static_cast<std::size_t>(cycles));
    for (int c = 0; c < cycles; ++c) {
      rig.targets_for(c);
      const std::int64_t a = now_ns();
      rig.scan();
      d[static_cast<std::size_t>(c)] = now_ns() - a;
    }
    double sum = 0;
    int moves = 0;
    for (int c = 0; c < cycles; c += kMoveEvery, ++moves) {
      const auto v = static_cast<double>(d[static_cast<std::size_t>(c)]);
      sum += v;
      t.move_max_ns = std::max(t.move_max_ns, v);
    }
    t.move_mean_ns = moves > 0 ? sum / moves : 0;
    std::sort(d.begin(), d.end());
    auto pct = [&](double p) {
      return static_cast<double>(d[std::min(d.size() - 1, static_cast<std::size_t>(p * static_cast<double>(d.size())))]);
    };
    t.p50_ns = pct(0.50);
    t.p99_ns = pct(0.99);
    t.max_ns = static_cast<double>(d.back());
  }
  return t;
}

// Early arrivals: an axis that begins tracking at a scan at which the block's
// common arrival (t_M) is still ahead (arrival > 0 after this scan's sample:
// another axis of the move has not arrived). `latest` is the largest number
// of scans an axis came early by.
struct Quality {
  std::int64_t early = 0, latest = 0, arrivals = 0;
};

Quality measure_quality(const Workload& w, int rule, int cycles) {
  Rig rig(w, rule);
  Quality q;
  std::vector<char> was(static_cast<std::size_t>(w.n), 1);
  for (int c = 0; c < cycles; ++c) {
    rig.targets_for(c);
    rig.scan();
    const std::int64_t t_m = rig.arrival();  // scans from this one until the common arrival
    for (int i = 0; i < w.n; ++i) {
      const bool t = rig.tracking(i);
      if (t && !was[static_cast<std::size_t>(i)]) {
        ++q.arrivals;
        if (t_m > 0) {
          ++q.early;
          q.latest = std::max(q.latest, t_m);
        }
      }
      was[static_cast<std::size_t>(i)] = t;
    }
  }
  return q;
}

std::vector<int> parse_list(const std::string& s) {
  std::vector<int> v;
  std::stringstream ss(s);
  std::string item;
  while (std::getline(ss, item, ',')) v.push_back(std::atoi(item.c_str()));
  return v;
}

}  // namespace

int main(int argc, char** argv) {
  std::vector<int> axes{6, 100, 1000};
  double seconds = 60;
  int cpu = -1, rule = 0;
  std::uint64_t seed = 15;
  bool floor = true;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto next = [&]() -> std::string {
      if (i + 1 >= argc) {
        std::fprintf(stderr, "%s needs a value\n", a.c_str());
        std::exit(2);
      }
      return argv[++i];
    };
    if (a == "--axes") axes = parse_list(next());
    else if (a == "--seconds") seconds = std::atof(next().c_str());
    else if (a == "--cpu") cpu = std::atoi(next().c_str());
    else if (a == "--seed") seed = std::strtoull(next().c_str(), nullptr, 10);
    else if (a == "--rule") rule = std::atoi(next().c_str());
    else if (a == "--no-floor") floor = false;
    else {
      std::fprintf(stderr,
                   "usage: bench_sync_workload [--axes 6,100,1000] [--seconds 60] [--cpu C] [--seed S] "
                   "[--rule 0|1|2] [--no-floor]\n");
      return 2;
    }
  }
  if (cpu >= 0) {
    cpu_set_t set;
    CPU_ZERO(&set);
    CPU_SET(cpu, &set);
    if (sched_setaffinity(0, sizeof set, &set) != 0) std::perror("sched_setaffinity");
  }
  mlockall(MCL_CURRENT | MCL_FUTURE);  // best effort: no page faults inside the timed loops
  const int cycles = static_cast<int>(seconds * 1000);
  std::printf("TRANSIENT_SYNC, issue 15 workload: 1 ms cycle, new step targets every %d ms, %d cycles, seed %llu, "
              "cpu %d\n",
              kMoveEvery, cycles, static_cast<unsigned long long>(seed), cpu);
  std::printf("%-6s %-5s %10s %10s %10s %10s %10s %12s %12s %9s %7s %9s\n", "axes", "rule", "mean us", "cpu us",
              "p50 us", "p99 us", "max us", "move mean us", "cpu ns/axis", "arrivals", "early", "max early");
  std::vector<int> rules{rule};
  if (floor && rule != 2) rules.push_back(2);
  for (int n : axes) {
    const Workload w = bench::make_sync_workload(n, cycles, seed + static_cast<std::uint64_t>(n));
    for (int r : rules) {
      const Timing t = time_rule(w, r, cycles);
      const Quality q = measure_quality(w, r, cycles);
      std::printf("%-6d %-5d %10.3f %10.3f %10.3f %10.3f %10.1f %12.1f %12.1f %9lld %7lld %9lld\n", n, r,
                  t.mean_ns / 1e3, t.mean_cpu_ns / 1e3, t.p50_ns / 1e3, t.p99_ns / 1e3, t.max_ns / 1e3,
                  t.move_mean_ns / 1e3, t.mean_cpu_ns / n,
                  static_cast<long long>(q.arrivals), static_cast<long long>(q.early),
                  static_cast<long long>(q.latest));
      std::printf("RESULT axes=%d rule=%d mean_ns=%.1f cpu_ns=%.1f p50_ns=%.0f p99_ns=%.0f max_ns=%.0f move_mean_ns=%.0f move_max_ns=%.0f arrivals=%lld early=%lld "
                  "max_early=%lld moves=%d\n",
                  n, r, t.mean_ns, t.mean_cpu_ns, t.p50_ns, t.p99_ns, t.max_ns, t.move_mean_ns, t.move_max_ns,
                  static_cast<long long>(q.arrivals),
                  static_cast<long long>(q.early), static_cast<long long>(q.latest), w.moves);
      std::fflush(stdout);
    }
  }
  return 0;
}
