// Retain of many variables (docs/benchmarks.md, "Retain"): the time of one
// store cycle of the retain job (take the values from the snapshots, write
// the changed ones in one transaction, commit) for N retained tags, with
// PRAGMA synchronous FULL and NORMAL side by side in one run, all values
// changing every cycle (the whole set written) and 1 % changing.
//
// Usage: bench_retain_store [N=10000] [CYCLES=200] [DIR=/tmp]
#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "runtime/core/monotonic_clock.hpp"
#include "runtime/core/virtual_clock.hpp"
#include "runtime/project/loader.hpp"
#include "runtime/store/retain.hpp"

using namespace syncplc;

namespace {

struct Result {
  double median_ms, p99_ms, max_ms;
};

Result measure(const std::string& dir, const char* sync, int n, int cycles, int changed_per_mille) {
  std::string text = "tasks: [{name: main, period: 10ms}]\ntags:\n";
  for (int i = 0; i < n; ++i) text += fmt::format("  - {{name: v{}, type: {}, retain: true}}\n", i, i % 2 ? "LREAL" : "DINT");
  auto loaded = load_project_text(text, "retain_bench.yaml");
  if (!loaded.ok()) {
    std::fprintf(stderr, "project did not load\n");
    std::exit(2);
  }
  Program& p = *loaded.program;
  const std::string path = dir + "/retain_bench_" + sync + ".db";
  for (const char* suffix : {"", "-wal", "-shm", ".lock"}) std::filesystem::remove(path + suffix);
  std::string err;
  auto db = store::Database::open(path, nullptr, &err);
  if (!db) {
    std::fprintf(stderr, "%s\n", err.c_str());
    std::exit(2);
  }
  db->sql().exec(std::string("PRAGMA synchronous=") + sync);
  store::RetainJob job(p, loaded.store, store::StartMode::Warm);
  if (!job.prepare(*db, &err)) {
    std::fprintf(stderr, "%s\n", err.c_str());
    std::exit(2);
  }
  Task& t = *p.tasks[0];
  VirtualClock clock(p);
  std::vector<double> ms;
  std::uint64_t k = 0;
  for (int c = 0; c < cycles; ++c) {
    // Change `changed_per_mille` of the values (a different slice each cycle).
    const int step = changed_per_mille >= 1000 ? 1 : 1000 / std::max(changed_per_mille, 1);
    // Written straight into the image between two scans of the virtual
    // clock, the task's one thread (image_access.hpp).
    auto& image = t.image(clock.image_access());
    for (int i = c % step; i < n; i += step) image[static_cast<std::size_t>(i)].raw = ++k;
    t.publish();
    const std::int64_t t0 = monotonic_ns();
    job.run(*db, t0, false);
    ms.push_back(static_cast<double>(monotonic_ns() - t0) * 1e-6);
  }
  std::sort(ms.begin(), ms.end());
  return {ms[ms.size() / 2], ms[std::min(ms.size() - 1, ms.size() * 99 / 100)], ms.back()};
}

}  // namespace

int main(int argc, char** argv) {
  const int n = argc > 1 ? std::atoi(argv[1]) : 10000;
  const int cycles = argc > 2 ? std::atoi(argv[2]) : 200;
  const std::string dir = argc > 3 ? argv[3] : "/tmp";
  std::printf("retain store cycle, %d retained tags, %d cycles per row, database in %s\n", n, cycles, dir.c_str());
  std::printf("%-10s %-12s %10s %10s %10s\n", "sync", "changed", "median ms", "p99 ms", "max ms");
  for (int per_mille : {1000, 10})
    for (const char* sync : {"FULL", "NORMAL"}) {
      const Result r = measure(dir, sync, n, cycles, per_mille);
      std::printf("%-10s %-12s %10.2f %10.2f %10.2f\n", sync, per_mille >= 1000 ? "all" : "1 %", r.median_ms, r.p99_ms,
                  r.max_ms);
    }
  return 0;
}
