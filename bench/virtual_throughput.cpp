// Virtual-time scan throughput.
//
// A project is generated in code: one 1 ms task and a chain of N standard
// blocks, each block's OUT wired to the next block's first input (pin to pin),
// the first fed from a tag and the last writing a tag. Two mixes:
//   lreal: ADD(+0.5), MUL(*0.5), LIMIT(-100..100), MOVE, repeated, on LREAL
//   bool:  AND(TRUE), OR(FALSE), XOR(TRUE), NOT, repeated, on BOOL
// The second operand of each block is a constant input (no copy per scan);
// the chained operand is one pin-to-pin copy per block per scan.
//
// BM_VirtualClock runs the project in a VirtualClock, one scan per iteration
// (VirtualClock::run_until + Task::scan + publish + account): the number a
// `syncplc sim` user gets. BM_TaskScan calls Task::scan() alone, to separate
// the per-scan overhead of the scheduler from the block chain. BM_Handwritten
// is the same LREAL chain as plain C++ over an array of doubles: the floor.
//
// Counters: scans/s and blocks/s (block executions per second of CPU time),
// t/block (CPU time per block execution, per-scan overhead included).
// Aim (issue): >= 10 million simple block executions per second on one core.
#include <benchmark/benchmark.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>

#include "runtime/core/virtual_clock.hpp"
#include "runtime/project/loader.hpp"

namespace {

using namespace syncplc;

enum class Mix { Lreal, Bool };

struct Kind {
  const char* type;
  const char* chained_pin;  // the pin the previous block's OUT feeds
  const char* inputs;       // constant inputs, YAML flow mapping body
};

constexpr Kind kLreal[4] = {
    {"ADD", "IN1", "IN2: 0.5"},
    {"MUL", "IN1", "IN2: 0.5"},
    {"LIMIT", "IN", "MN: -100.0, MX: 100.0"},
    {"MOVE", "IN", ""},
};
constexpr Kind kBool[4] = {
    {"AND", "IN1", "IN2: TRUE"},
    {"OR", "IN1", "IN2: FALSE"},
    {"XOR", "IN1", "IN2: TRUE"},
    {"NOT", "IN", ""},
};

std::string chain_project(int n, Mix mix) {
  const Kind* kinds = mix == Mix::Lreal ? kLreal : kBool;
  const char* type = mix == Mix::Lreal ? "LREAL" : "BOOL";
  std::string y;
  y += "project: {name: chain, version: 0.0.1}\n";
  y += "tasks:\n  - {name: fast, period: 1ms, priority: 80}\n";
  y += "tags:\n";
  y += std::string("  - {name: x, type: ") + type + ", init: " + (mix == Mix::Lreal ? "1.0" : "TRUE") + "}\n";
  y += std::string("  - {name: y, type: ") + type + "}\n";
  y += "blocks:\n";
  for (int i = 0; i < n; ++i) {
    const Kind& k = kinds[i % 4];
    y += "  - {name: b" + std::to_string(i) + ", type: " + k.type + ", task: fast, datatype: " + type;
    if (*k.inputs) y += std::string(", inputs: {") + k.inputs + "}";
    y += "}\n";
  }
  y += "connections:\n";
  for (int i = 0; i < n; ++i) {
    const Kind& k = kinds[i % 4];
    std::string src = i == 0 ? "x" : "b" + std::to_string(i - 1) + ".OUT";
    y += "  - " + src + " -> b" + std::to_string(i) + "." + k.chained_pin + "\n";
  }
  y += "  - b" + std::to_string(n - 1) + ".OUT -> y\n";
  return y;
}

// What y must be after one scan, computed in plain C++.
double expected_lreal(int n) {
  double v = 1.0;
  for (int i = 0; i < n; ++i) {
    switch (i % 4) {
      case 0: v = v + 0.5; break;
      case 1: v = v * 0.5; break;
      case 2: v = std::fmin(std::fmax(v, -100.0), 100.0); break;
      default: break;
    }
  }
  return v;
}
bool expected_bool(int n) {
  bool v = true;
  for (int i = 0; i < n; ++i) {
    switch (i % 4) {
      case 0: v = v && true; break;
      case 1: v = v || false; break;
      case 2: v = v != true; break;
      default: v = !v; break;
    }
  }
  return v;
}

std::unique_ptr<Program> load_chain(benchmark::State& state, int n, Mix mix) {
  auto r = load_project_text(chain_project(n, mix), "<generated chain>");
  if (!r.ok()) {
    std::string msg = "project did not load:";
    for (const auto& d : r.diagnostics.sorted()) msg += "\n  " + d.text();
    state.SkipWithError(msg.c_str());
    return nullptr;
  }
  return std::move(r.program);
}

// Checks the chain computed what it should (the benchmark measured real work).
void verify(benchmark::State& state, Program& p, int n, Mix mix) {
  const Tag* y = p.find_tag("y");
  // Published (the bench's thread is the task's), then read as any reader does.
  p.tasks[y->owner]->publish();
  Cell c;
  p.read_tag(*y, &c);
  bool ok = mix == Mix::Lreal ? c.get<double>() == expected_lreal(n) : c.get<bool>() == expected_bool(n);
  if (!ok) state.SkipWithError("the chain's output is wrong");
}

void set_counters(benchmark::State& state, int n) {
  using benchmark::Counter;
  const auto scans = static_cast<double>(state.iterations());
  state.counters["blocks"] = n;
  state.counters["scans/s"] = Counter(scans, Counter::kIsRate);
  state.counters["blocks/s"] = Counter(scans * n, Counter::kIsRate);
  state.counters["t/block"] = Counter(scans * n, Counter::kIsRate | Counter::kInvert);
}

void BM_VirtualClock(benchmark::State& state, Mix mix) {
  const int n = static_cast<int>(state.range(0));
  auto p = load_chain(state, n, mix);
  if (!p) return;
  VirtualClock clock(*p);
  std::int64_t t = 0;
  for (auto _ : state) {
    t += 1'000'000;
    clock.run_until(t);  // exactly one scan: the one released at t - 1 ms
  }
  if (clock.scans(0) != static_cast<std::uint64_t>(state.iterations())) state.SkipWithError("scan count mismatch");
  verify(state, *p, n, mix);
  set_counters(state, n);
}

void BM_TaskScan(benchmark::State& state, Mix mix) {
  const int n = static_cast<int>(state.range(0));
  auto p = load_chain(state, n, mix);
  if (!p) return;
  Task& task = *p->tasks[0];
  task.reset_timing();
  std::uint64_t k = 0;
  for (auto _ : state) {
    ScanContext ctx;
    ctx.now_ns = static_cast<std::int64_t>(k) * 1'000'000;
    ctx.dt_ns = 1'000'000;
    ctx.scan = k++;
    task.scan(ctx);
  }
  verify(state, *p, n, mix);
  set_counters(state, n);
}

// The LREAL chain as straight C++ on an array (one slot per pin, the chained
// value copied between slots like the runtime's pin-to-pin copy), without
// virtual calls: what the same arithmetic costs with no engine around it.
void BM_Handwritten(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  std::vector<double> in(static_cast<std::size_t>(n) + 1), out(static_cast<std::size_t>(n));
  for (auto _ : state) {
    double v = 1.0;
    benchmark::DoNotOptimize(v);
    for (int i = 0; i < n; ++i) {
      in[static_cast<std::size_t>(i)] = v;
      switch (i % 4) {
        case 0: v = v + 0.5; break;
        case 1: v = v * 0.5; break;
        case 2: v = std::fmin(std::fmax(v, -100.0), 100.0); break;
        default: break;
      }
      out[static_cast<std::size_t>(i)] = v;
    }
    benchmark::DoNotOptimize(out.data());
    benchmark::ClobberMemory();
  }
  set_counters(state, n);
}

BENCHMARK_CAPTURE(BM_VirtualClock, lreal, Mix::Lreal)->Arg(10)->Arg(100)->Arg(1000);
BENCHMARK_CAPTURE(BM_VirtualClock, bool, Mix::Bool)->Arg(10)->Arg(100)->Arg(1000);
BENCHMARK_CAPTURE(BM_TaskScan, lreal, Mix::Lreal)->Arg(10)->Arg(100)->Arg(1000);
BENCHMARK_CAPTURE(BM_TaskScan, bool, Mix::Bool)->Arg(10)->Arg(100)->Arg(1000);
BENCHMARK(BM_Handwritten)->Arg(10)->Arg(100)->Arg(1000);

}  // namespace

BENCHMARK_MAIN();
