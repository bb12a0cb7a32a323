// Per-scan cost of forcing and pin monitoring (docs/architecture.md,
// "Forces and pin monitoring"): Task::scan + Task::publish of a chain of 100
// LREAL blocks (ADD, MUL, LIMIT, MOVE, pin to pin, as in
// virtual_throughput.cpp) with
//   none:      nothing forced, nobody monitoring (the plain path: one branch per block)
//   forces_10: 10 elements forced (the IN pins of ten MOVEs along the chain)
//   monitor:   nothing forced, the pins copied for a reader at each publication
// Run by hand: build/bench/bench_force; the numbers are in docs/benchmarks.md.
#include <benchmark/benchmark.h>

#include <string>

#include "runtime/core/program.hpp"
#include "runtime/project/loader.hpp"

namespace {

using namespace syncplc;

std::string chain(int n) {
  const char* kinds[4][3] = {{"ADD", "IN1", ", inputs: {IN2: 0.5}"},
                             {"MUL", "IN1", ", inputs: {IN2: 0.5}"},
                             {"LIMIT", "IN", ", inputs: {MN: -100.0, MX: 100.0}"},
                             {"MOVE", "IN", ""}};
  std::string y = "project: {name: chain}\ntasks: [{name: fast, period: 1ms}]\n";
  y += "tags: [{name: x, type: LREAL, init: 1.0}, {name: y, type: LREAL}]\nblocks:\n";
  for (int i = 0; i < n; ++i)
    y += "  - {name: b" + std::to_string(i) + ", type: " + kinds[i % 4][0] + ", task: fast, datatype: LREAL" +
         kinds[i % 4][2] + "}\n";
  y += "connections:\n";
  for (int i = 0; i < n; ++i)
    y += "  - " + (i == 0 ? std::string("x") : "b" + std::to_string(i - 1) + ".OUT") + " -> b" + std::to_string(i) +
         "." + kinds[i % 4][1] + "\n";
  y += "  - b" + std::to_string(n - 1) + ".OUT -> y\n";
  return y;
}

enum class Mode { None, Forces, Monitor };

void BM_ScanAndPublish(benchmark::State& state, Mode mode) {
  constexpr int kBlocks = 100;
  LoadOptions o;
  auto r = load_project_text(chain(kBlocks), "chain.yaml", o);
  if (!r.ok()) {
    state.SkipWithError("project did not load");
    return;
  }
  Program& p = *r.program;
  Task& task = *p.tasks[0];
  if (mode == Mode::Forces)
    for (int i = 0; i < 10; ++i) {
      const int b = i * 8 + 3;  // every other MOVE (b3, b11, ..., b75): its input IN
      auto res = p.force("b" + std::to_string(b) + ".IN", "2.5");
      if (!res.ok) {
        state.SkipWithError(res.error.c_str());
        return;
      }
    }
  Cell v;
  if (mode == Mode::Monitor) p.read_value(*p.resolve("b0.OUT"), &v, 3'600'000'000'000);
  std::uint64_t k = 0;
  for (auto _ : state) {
    ScanContext ctx;
    ctx.now_ns = static_cast<std::int64_t>(k) * 1'000'000;
    ctx.dt_ns = 1'000'000;
    ctx.scan = k++;
    task.scan(ctx);
    task.publish();
  }
  state.counters["forces"] = static_cast<double>(task.force_table().size());
}

BENCHMARK_CAPTURE(BM_ScanAndPublish, none, Mode::None);
BENCHMARK_CAPTURE(BM_ScanAndPublish, forces_10, Mode::Forces);
BENCHMARK_CAPTURE(BM_ScanAndPublish, monitor, Mode::Monitor);

}  // namespace

BENCHMARK_MAIN();
