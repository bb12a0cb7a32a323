// Virtual-time speed of the four-axis demo (issue 4): how many times faster
// than real time `syncplc sim` runs projects/four_axis_table/sync.yaml (and
// pd.yaml) at its 1 ms period: the table's exact ZOH plant, the ring, 12
// Taylor estimators, the reference, four SYNC_CONTROLLERs, the scheduler.
// One iteration = one virtual second (1000 scans). Aim: >= 1000x real time.
#include <benchmark/benchmark.h>

#include <string>

#include "runtime/core/virtual_clock.hpp"
#include "runtime/project/loader.hpp"

namespace {

using namespace syncplc;

void run_project(benchmark::State& state, const char* file, double loss) {
  LoadOptions o;
  if (loss > 0) o.overrides = {{"ring", "loss.p", std::to_string(loss)}};
  auto r = load_project(std::string(SYNCPLC_SOURCE_DIR) + "/projects/four_axis_table/" + file, o);
  if (!r.ok()) {
    state.SkipWithError("the project did not load");
    return;
  }
  std::string err;
  r.program->open_drivers(&err);
  VirtualClock clock(*r.program);
  std::int64_t t = 0;
  for (auto _ : state) {
    t += 1'000'000'000;
    clock.run_until(t);
  }
  r.program->close_drivers();
  // Virtual seconds per second of CPU time: the factor over real time.
  state.counters["x_real_time"] = benchmark::Counter(static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
  state.counters["scans/s"] =
      benchmark::Counter(static_cast<double>(state.iterations()) * 1000.0, benchmark::Counter::kIsRate);
}

void BM_FourAxisSync(benchmark::State& s) { run_project(s, "sync.yaml", 0); }
void BM_FourAxisSyncLoss20(benchmark::State& s) { run_project(s, "sync.yaml", 0.2); }
void BM_FourAxisPd(benchmark::State& s) { run_project(s, "pd.yaml", 0); }
BENCHMARK(BM_FourAxisSync)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_FourAxisSyncLoss20)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_FourAxisPd)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
