// Real-time start jitter of an empty task under RealtimeRunner.
//
// Loads a generated project with one task and no blocks (period and priority
// from the command line, optionally pinned with the task key `cpu:`), runs it
// in real time and prints the start jitter that the task itself recorded
// (Task::stats.jitter: actual start minus planned release; its percentiles are
// bucket upper bounds, within 1/32 of the true value).
//
// The run can be cut into slices with a command run between them (and after
// the last): bench/rt_jitter.sh uses that to interleave slices of cyclictest
// with slices of this task, so both see the same background load. The task's
// statistics accumulate over all slices (RealtimeRunner::start() resets the
// timing state, not the statistics).
//
// Run as root: SCHED_FIFO and mlockall need it. Whether SCHED_FIFO was
// obtained is printed (from RealtimeRunner::warnings() and checked again with
// sched_getscheduler() on the task's thread).
//
// --bare replaces RealtimeRunner by a minimal loop in the same process and
// with the same thread setup (SCHED_FIFO, mlockall, optional pinning):
// clock_nanosleep(TIMER_ABSTIME) on the release, clock_gettime, record. It is a
// control: it separates what the runner's wake-up path costs from what the
// machine does to any sleeping SCHED_FIFO thread. --bare-work is the bare loop
// plus what the runner does each cycle (Task::scan, publish, account; the
// jitter then goes to Task::stats like under the runner).
//
// Usage: bench_rt_jitter [--duration S] [--slices N] [--period-us U] [--priority P]
//                        [--cpu C] [--pm-qos US] [--between CMD] [--bare] [--bare-work]
// The last line is machine-readable: "RESULT key=value ...", all times in ns.
#include <dirent.h>
#include <fcntl.h>
#include <pthread.h>
#include <sched.h>
#include <sys/mman.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <iostream>
#include <set>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "runtime/core/cpu_latency.hpp"
#include "runtime/core/histogram.hpp"
#include "runtime/core/realtime.hpp"
#include "runtime/project/loader.hpp"

namespace {

using namespace syncplc;

struct Options {
  double duration_s = 60;
  int slices = 1;
  long period_us = 1000;
  int priority = 80;
  int cpu = -1;
  int pm_qos_us = 0;  // /dev/cpu_dma_latency while the task runs: RealtimeRunner's default 0; -1 untouched
  std::string between;
  bool bare = false;   // a minimal clock_nanosleep loop instead of RealtimeRunner (a control)
  bool bare_work = false;  // the bare loop, plus the task's scan/publish/account each cycle
};

[[noreturn]] void usage(const char* msg) {
  std::cerr << "bench_rt_jitter: " << msg << "\n"
            << "usage: bench_rt_jitter [--duration S] [--slices N] [--period-us U] [--priority P] [--cpu C]\n"
            << "                       [--pm-qos US] [--between CMD] [--bare] [--bare-work]\n";
  std::exit(2);
}

Options parse(int argc, char** argv) {
  Options o;
  for (int i = 1; i < argc; ++i) {
    std::string a = argv[i];
    auto value = [&]() -> std::string {
      if (i + 1 >= argc) usage(("missing value after " + a).c_str());
      return argv[++i];
    };
    if (a == "--duration") o.duration_s = std::stod(value());
    else if (a == "--slices") o.slices = std::stoi(value());
    else if (a == "--period-us") o.period_us = std::stol(value());
    else if (a == "--priority") o.priority = std::stoi(value());
    else if (a == "--cpu") o.cpu = std::stoi(value());
    else if (a == "--pm-qos") o.pm_qos_us = std::stoi(value());
    else if (a == "--between") o.between = value();
    else if (a == "--bare") o.bare = true;
    else if (a == "--bare-work") o.bare = o.bare_work = true;
    else if (a == "-h" || a == "--help") usage("help");
    else usage(("unknown argument " + a).c_str());
  }
  if (o.duration_s <= 0 || o.slices < 1 || o.period_us < 100) usage("bad duration, slices or period");
  return o;
}

std::string project_text(const Options& o) {
  std::string y = "project: {name: rt_jitter, version: 0.0.1}\ntasks:\n";
  y += "  - {name: empty, period: " + std::to_string(o.period_us) + "us, priority: " + std::to_string(o.priority);
  if (o.cpu >= 0) y += ", cpu: " + std::to_string(o.cpu);
  y += "}\n";
  return y;
}

void sleep_ns(std::int64_t ns) {
  if (ns <= 0) return;
  timespec ts{static_cast<time_t>(ns / 1'000'000'000), static_cast<long>(ns % 1'000'000'000)};
  while (clock_nanosleep(CLOCK_MONOTONIC, 0, &ts, &ts) == EINTR) {
  }
}

// The scheduling policy of the thread named `name` in this process, checked
// from outside the thread: "SCHED_FIFO prio 80", or what it is instead.
std::string thread_policy(const std::string& name) {
  DIR* d = opendir("/proc/self/task");
  if (!d) return "unknown (no /proc/self/task)";
  std::string result = "unknown (thread not found)";
  while (dirent* e = readdir(d)) {
    if (e->d_name[0] == '.') continue;
    std::ifstream comm(std::string("/proc/self/task/") + e->d_name + "/comm");
    std::string c;
    std::getline(comm, c);
    if (c != name) continue;
    pid_t tid = std::atoi(e->d_name);
    int pol = sched_getscheduler(tid);
    sched_param sp{};
    sched_getparam(tid, &sp);
    const char* pn = pol == SCHED_FIFO ? "SCHED_FIFO" : pol == SCHED_RR ? "SCHED_RR" : pol == SCHED_OTHER ? "SCHED_OTHER" : "other";
    result = std::string(pn) + " prio " + std::to_string(sp.sched_priority);
    if (pol == SCHED_FIFO) break;
  }
  closedir(d);
  return result;
}

// The control loop of --bare: what cyclictest does, recorded in a Histogram
// like Task::stats.jitter. Returns a warning text, "" when all went well.
std::string bare_slice(const Options& o, std::int64_t slice_ns, Histogram& jitter, std::uint64_t& scans,
                       Task& task) {
  std::string warning;
  if (mlockall(MCL_CURRENT | MCL_FUTURE) != 0) warning = std::string("mlockall failed: ") + std::strerror(errno);
  std::thread t([&] {
    pthread_setname_np(pthread_self(), "empty");
    sched_param sp{};
    sp.sched_priority = o.priority;
    if (int rc = pthread_setschedparam(pthread_self(), SCHED_FIFO, &sp); rc != 0)
      warning = std::string("cannot use SCHED_FIFO: ") + std::strerror(rc);
    if (o.cpu >= 0) {
      cpu_set_t set;
      CPU_ZERO(&set);
      CPU_SET(o.cpu, &set);
      pthread_setaffinity_np(pthread_self(), sizeof set, &set);
    }
    const std::int64_t epoch = RealtimeRunner::monotonic_ns() + 20'000'000;
    const std::int64_t period = o.period_us * 1000;
    task.reset_timing();
    std::int64_t k = 0;
    for (std::int64_t planned = 0; planned < slice_ns; planned += period, ++k) {
      const std::int64_t deadline = epoch + planned;
      timespec ts{static_cast<time_t>(deadline / 1'000'000'000), static_cast<long>(deadline % 1'000'000'000)};
      while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, nullptr) == EINTR) {
      }
      const std::int64_t start = RealtimeRunner::monotonic_ns() - epoch;
      ++scans;
      if (!o.bare_work) {
        jitter.record(start - planned);
        continue;
      }
      ScanContext ctx;
      ctx.now_ns = planned;
      ctx.dt_ns = period;
      ctx.scan = static_cast<std::uint64_t>(k);
      ctx.virtual_time = false;
      task.scan(ctx);
      const std::int64_t end = RealtimeRunner::monotonic_ns() - epoch;
      task.publish();
      task.account(k, planned, start, end);  // the grid stays fixed here: no skipping
    }
  });
  sleep_ns(120'000'000);
  std::string pol = thread_policy("empty");
  t.join();
  if (pol.rfind("SCHED_FIFO", 0) != 0 && warning.empty()) warning = "thread policy seen: " + pol;
  return warning;
}

std::string us(std::int64_t ns) {
  char b[32];
  std::snprintf(b, sizeof b, "%.1f us", static_cast<double>(ns) * 1e-3);
  return b;
}

}  // namespace

int main(int argc, char** argv) {
  const Options o = parse(argc, argv);
  auto r = load_project_text(project_text(o), "<rt_jitter>");
  if (!r.ok()) {
    for (const auto& d : r.diagnostics.sorted()) std::cerr << d.text() << "\n";
    return 1;
  }
  Program& p = *r.program;
  Task& task = *p.tasks[0];
  const auto slice_ns = static_cast<std::int64_t>(std::llround(o.duration_s * 1e9 / o.slices));

  std::cout << "bench_rt_jitter: " << (o.bare_work ? "bare loop + task work (control)" : o.bare ? "bare loop (control)" : "empty task") << ", period " << o.period_us << " us, priority " << o.priority << ", cpu "
            << (o.cpu >= 0 ? std::to_string(o.cpu) : "any") << ", " << o.slices << " slice(s) of "
            << static_cast<double>(slice_ns) * 1e-9 << " s, pm-qos "
            << (o.pm_qos_us >= 0 ? std::to_string(o.pm_qos_us) + " us" : "untouched") << "\n";
  if (geteuid() != 0) std::cout << "bench_rt_jitter: not running as root: expect no SCHED_FIFO and no mlockall\n";

  std::set<std::string> warnings;
  Histogram bare_jitter;
  bare_jitter.reset();
  std::uint64_t bare_scans = 0;
  std::vector<std::pair<int, std::int64_t>> late_starts;  // slice, ns after its first release
  std::string policy;
  bool fifo = true;
  for (int s = 0; s < o.slices; ++s) {
    CpuLatencyRequest qos;  // the bare loops hold it themselves; RealtimeRunner does through its options
    std::string err;
    if (o.bare && o.pm_qos_us >= 0 && !qos.hold(o.pm_qos_us, &err))
      warnings.insert("cannot set /dev/cpu_dma_latency: " + err);
    if (o.bare) {
      std::string w = bare_slice(o, slice_ns, bare_jitter, bare_scans, task);
      if (policy.empty()) policy = w.empty() ? "SCHED_FIFO prio " + std::to_string(o.priority) : w;
      if (!w.empty()) { warnings.insert(w); fifo = false; }
    } else {
      RealtimeRunner::Options ro;
      ro.cpu_latency_us = o.pm_qos_us;
      RealtimeRunner runner(p, ro);
      const std::uint64_t scans0 = task.stats.scans.load();
      runner.start();
      // Was the slice's first scan late? (Its jitter is in the statistics like
      // any other; this only tells start-up stalls apart from steady state.)
      sleep_ns(runner.epoch_ns() + 2'000'000 - RealtimeRunner::monotonic_ns());
      if (task.stats.scans.load() == scans0) {
        std::int64_t now = RealtimeRunner::monotonic_ns();
        while (task.stats.scans.load() == scans0 && now - runner.epoch_ns() < 1'000'000'000) {
          sleep_ns(100'000);
          now = RealtimeRunner::monotonic_ns();
        }
        late_starts.emplace_back(s, now - runner.epoch_ns());
      }
      sleep_ns(runner.epoch_ns() - RealtimeRunner::monotonic_ns() + 100'000'000);
      std::string pol = thread_policy("empty");
      if (policy.empty()) policy = pol;
      if (pol.rfind("SCHED_FIFO", 0) != 0) fifo = false;
      sleep_ns(runner.epoch_ns() + slice_ns - RealtimeRunner::monotonic_ns());
      runner.request_stop();
      runner.join();
      for (const auto& w : runner.warnings()) {
        warnings.insert(w);
        if (w.find("SCHED_FIFO") != std::string::npos) fifo = false;
      }
    }
    qos.release();
    if (!o.between.empty()) {
      std::cout.flush();
      int rc = std::system(o.between.c_str());
      if (rc != 0) {
        std::cerr << "bench_rt_jitter: --between command failed (" << rc << "): " << o.between << "\n";
        return 1;
      }
    }
  }

  for (const auto& [slice, ns] : late_starts)
    std::cout << "bench_rt_jitter: slice " << slice << ": first scan not started " << us(ns)
              << " after its release (thread start-up, not steady state)\n";
  if (!o.bare)
    std::cout << "bench_rt_jitter: slices whose first scan was more than 2 ms late: " << late_starts.size() << " of "
              << o.slices << "\n";
  for (const auto& w : warnings) std::cout << "bench_rt_jitter: warning: " << w << "\n";
  std::cout << "bench_rt_jitter: SCHED_FIFO " << (fifo ? "obtained" : "NOT obtained") << " (thread policy seen: "
            << policy << ")\n";
  auto st = task.stats.summary();
  if (o.bare && !o.bare_work) {
    st = TaskStats::Summary{};
    st.scans = bare_scans;
    st.jitter = bare_jitter.summary();
    std::cout << "bench_rt_jitter: --bare: a minimal clock_nanosleep loop, not RealtimeRunner\n";
  } else if (o.bare_work) {
    std::cout << "bench_rt_jitter: --bare-work: the minimal loop plus Task::scan/publish/account, not RealtimeRunner\n";
  }
  std::cout << "bench_rt_jitter: scans " << st.scans << ", overruns " << st.overruns << ", skipped " << st.skipped
            << "\n";
  std::cout << "bench_rt_jitter: start jitter  min " << us(st.jitter.min) << "  mean "
            << us(static_cast<std::int64_t>(st.jitter.mean)) << "  p50 " << us(st.jitter.p50) << "  p99 "
            << us(st.jitter.p99) << "  max " << us(st.jitter.max) << "\n";
  std::cout << "bench_rt_jitter: exec time     min " << us(st.exec.min) << "  p50 " << us(st.exec.p50) << "  p99 "
            << us(st.exec.p99) << "  max " << us(st.exec.max) << "\n";
  std::cout << "RESULT fifo=" << (fifo ? 1 : 0) << " scans=" << st.scans << " overruns=" << st.overruns
            << " skipped=" << st.skipped << " min_ns=" << st.jitter.min << " mean_ns="
            << static_cast<std::int64_t>(st.jitter.mean) << " p50_ns=" << st.jitter.p50 << " p99_ns=" << st.jitter.p99
            << " max_ns=" << st.jitter.max << " exec_p99_ns=" << st.exec.p99 << " exec_max_ns=" << st.exec.max << "\n";
  return 0;
}
