// Per-scan cost of the motion blocks (issue 3), through the block harness.
//
// Paper 004 §IV measured, on a 700 MHz Raspberry Pi B with a 20 ms scan and
// references changed at random at least every 0.5 s: 6 filters 17.49 us per
// scan, 6 synchronized filters 50.42 us, 100 synchronized signals 548.93 us.
// The same three cases here, on the same kind of input:
//   BM_SixFilters          six NONLINEAR_FILTER instances, one scan of each
//   BM_SyncFilters/6       TRANSIENT_SYNC with n = 6 (rule 0, unified)
//   BM_SyncFilters/100     TRANSIENT_SYNC with n = 100
//   BM_AsyncFilters/100    TRANSIENT_SYNC n = 100, rule 2 (no synchronization): the filters alone
// plus the per-axis blocks of paper 000 / 003:
//   BM_SyncController      SYNC_CONTROLLER, axis 4 of 4 (three preceding errors, Taylor compensation)
//   BM_TaylorEstimator     TAYLOR_ESTIMATOR, order 3, robust history, 20 % loss
// References: steps and ramps from a seeded generator, held 0.1-0.5 s, with
// Table II-like random bounds (|U| 20-40, |v| 4-6), T = 20 ms as in the paper.
// Each iteration is one scan; the sequence is long enough (50,000 scans) to
// mix transients and tracking as the paper's runs did. Aim: 100 synchronized
// axes under 10 us per scan.
#include <benchmark/benchmark.h>

#include <cmath>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "fblocks/library.hpp"
#include "runtime/core/block_harness.hpp"

namespace {

using namespace syncplc;

constexpr std::int64_t kPeriod = 20'000'000;  // 20 ms, as paper 004's experiment
constexpr int kSteps = 50'000;

struct Axis {
  double lo_u, hi_u, lo_v, hi_v;
};

// r, r_dot for `n` axes over kSteps scans: steps and ramps held 0.1-0.5 s.
struct Refs {
  std::vector<double> r, rd;  // scan-major: [k * n + i]
  std::vector<Axis> bounds;
  int n;
};

Refs make_refs(int n, std::uint64_t seed) {
  std::mt19937_64 g(seed);
  std::uniform_real_distribution<double> u01(0, 1);
  Refs f;
  f.n = n;
  f.r.resize(static_cast<std::size_t>(kSteps) * n);
  f.rd.resize(f.r.size());
  for (int i = 0; i < n; ++i) {
    f.bounds.push_back({-(20 + 20 * u01(g)), 20 + 20 * u01(g), -(4 + 2 * u01(g)), 4 + 2 * u01(g)});
    double r = 0, rd = 0;
    int left = 0;
    for (int k = 0; k < kSteps; ++k) {
      if (left-- <= 0) {
        left = 5 + static_cast<int>(u01(g) * 20);  // 0.1 .. 0.5 s at 20 ms
        r = -5 + 10 * u01(g);
        rd = u01(g) < 0.5 ? 0.0 : (-2 + 4 * u01(g));
      } else {
        r += rd * 0.02;
      }
      f.r[static_cast<std::size_t>(k) * n + i] = r;
      f.rd[static_cast<std::size_t>(k) * n + i] = rd;
    }
  }
  return f;
}

BlockHarness::Options opts(std::map<std::string, std::string> params) {
  BlockHarness::Options o;
  o.params = std::move(params);
  o.period_ns = kPeriod;
  return o;
}

void BM_SixFilters(benchmark::State& state) {
  const int n = 6;
  Refs f = make_refs(n, 1);
  std::vector<std::unique_ptr<BlockHarness>> h;
  for (int i = 0; i < n; ++i) {
    h.push_back(std::make_unique<BlockHarness>(builtin_blocks(), "NONLINEAR_FILTER", opts({})));
    if (!h.back()->ok()) state.SkipWithError("NONLINEAR_FILTER did not build");
    const auto& b = f.bounds[static_cast<std::size_t>(i)];
    h.back()->set<double>("a_min", b.lo_u);
    h.back()->set<double>("a_max", b.hi_u);
    h.back()->set<double>("v_min", b.lo_v);
    h.back()->set<double>("v_max", b.hi_v);
  }
  // Cells looked up once: the loop measures the blocks, not the harness's pin lookup.
  std::vector<Cell*> r, rd;
  for (auto& x : h) {
    r.push_back(&x->cell("r"));
    rd.push_back(&x->cell("r_dot"));
  }
  std::size_t k = 0;
  for (auto _ : state) {
    for (std::size_t i = 0; i < static_cast<std::size_t>(n); ++i) {
      r[i]->set<double>(f.r[k * n + i]);
      rd[i]->set<double>(f.rd[k * n + i]);
      h[i]->scan();
    }
    if (++k == static_cast<std::size_t>(kSteps)) k = 0;
  }
}
BENCHMARK(BM_SixFilters);

void sync_filters(benchmark::State& state, int rule) {
  const int n = static_cast<int>(state.range(0));
  Refs f = make_refs(n, 2);
  BlockHarness h(builtin_blocks(), "TRANSIENT_SYNC",
                 opts({{"n", std::to_string(n)}, {"rule", std::to_string(rule)}}));
  if (!h.ok()) {
    state.SkipWithError("TRANSIENT_SYNC did not build");
    return;
  }
  for (int i = 0; i < n; ++i) {
    const auto& b = f.bounds[static_cast<std::size_t>(i)];
    h.set<double>("a_min", static_cast<std::uint32_t>(i), b.lo_u);
    h.set<double>("a_max", static_cast<std::uint32_t>(i), b.hi_u);
    h.set<double>("v_min", static_cast<std::uint32_t>(i), b.lo_v);
    h.set<double>("v_max", static_cast<std::uint32_t>(i), b.hi_v);
  }
  Cell* r = &h.cell("r", 0);  // array pins: consecutive cells
  Cell* rd = &h.cell("r_dot", 0);
  std::size_t k = 0;
  for (auto _ : state) {
    for (std::size_t i = 0; i < static_cast<std::size_t>(n); ++i) {
      r[i].set<double>(f.r[k * n + i]);
      rd[i].set<double>(f.rd[k * n + i]);
    }
    h.scan();
    if (++k == static_cast<std::size_t>(kSteps)) k = 0;
  }
}
void BM_SyncFilters(benchmark::State& state) { sync_filters(state, 0); }
void BM_AsyncFilters(benchmark::State& state) { sync_filters(state, 2); }
BENCHMARK(BM_SyncFilters)->Arg(6)->Arg(100);
BENCHMARK(BM_AsyncFilters)->Arg(6)->Arg(100);

void BM_SyncController(benchmark::State& state) {
  BlockHarness h(builtin_blocks(), "SYNC_CONTROLLER", opts({{"axis", "4"}, {"n", "4"}}));
  if (!h.ok()) {
    state.SkipWithError("SYNC_CONTROLLER did not build");
    return;
  }
  std::mt19937_64 g(3);
  std::uniform_real_distribution<double> u(-1e-3, 1e-3);
  // Inputs precomputed, cells looked up once: the loop measures the block.
  constexpr int kN = 4096;
  std::vector<double> in(kN * 7);
  for (int k = 0; k < kN; ++k) {
    double t = 1e-3 * k;
    double v[7] = {std::sin(t), std::cos(t), -std::sin(t), std::sin(t) + u(g), u(g), u(g), u(g)};
    for (int j = 0; j < 7; ++j) in[static_cast<std::size_t>(k * 7 + j)] = v[j];
  }
  Cell* c[7] = {&h.cell("x_d"), &h.cell("v_d"), &h.cell("a_d"), &h.cell("x"),
                &h.cell("e_rx", 0), &h.cell("e_rx", 1), &h.cell("e_rx", 2)};
  Cell& tau = h.cell("tau");
  std::size_t k = 0;
  for (auto _ : state) {
    for (std::size_t j = 0; j < 7; ++j) c[j]->set<double>(in[k * 7 + j]);
    h.scan();
    benchmark::DoNotOptimize(tau.get<double>());
    if (++k == kN) k = 0;
  }
}
BENCHMARK(BM_SyncController);

void BM_TaylorEstimator(benchmark::State& state) {
  BlockHarness h(builtin_blocks(), "TAYLOR_ESTIMATOR", opts({{"order", "3"}}));
  if (!h.ok()) {
    state.SkipWithError("TAYLOR_ESTIMATOR did not build");
    return;
  }
  std::mt19937_64 g(4);
  std::bernoulli_distribution lost(0.2);
  constexpr int kN = 4096;
  std::vector<double> x(kN);
  std::vector<char> ok(kN);
  for (int k = 0; k < kN; ++k) {
    x[static_cast<std::size_t>(k)] = 0.05 * std::sin(1e-3 * k);
    ok[static_cast<std::size_t>(k)] = !lost(g);
  }
  Cell& in = h.cell("in");
  Cell& valid = h.cell("valid");
  Cell& out = h.cell("out");
  std::size_t k = 0;
  for (auto _ : state) {
    in.set<double>(x[k]);
    valid.set<bool>(ok[k] != 0);
    h.scan();
    benchmark::DoNotOptimize(out.get<double>());
    if (++k == kN) k = 0;
  }
}
BENCHMARK(BM_TaylorEstimator);

}  // namespace

BENCHMARK_MAIN();
