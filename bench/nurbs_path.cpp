// Per-scan cost of NURBS_PATH (issue 24, paper 003 section 4.3), through the
// block harness: one iteration is one scan of a running path (the Taylor
// parameter step, the span search from the last span, C, C', C'' by the
// Cox-de Boor triangle and the derivative control points, the outputs).
//
//   BM_NurbsPath/circle     the exact NURBS circle: 9 points, order 3 (quadratic)
//   BM_NurbsPath/butterfly  projects/contouring/butterfly.yaml's curve: 25 points, order 4 (cubic)
//   BM_NurbsPath/order8     40 points of order 8 (degree 7): the largest basis the block holds
// The path restarts (a falling and a rising Execute) whenever it is done; the
// counter `restarts` says how often per iteration that happened (rarely: the
// feed gives thousands of scans per path).
#include <benchmark/benchmark.h>

#include <cmath>
#include <map>
#include <string>
#include <vector>

#include "fblocks/library.hpp"
#include "runtime/core/block_harness.hpp"

namespace {

using namespace syncplc;

struct NurbsBenchCurve {
  std::vector<double> x, y, w, knots;
  int order;
};

NurbsBenchCurve bench_circle() {
  const double h = std::sqrt(2.0) / 2, R = 0.05;
  return {{R, R, 0, -R, -R, -R, 0, R, R},
          {0, R, R, R, 0, -R, -R, -R, 0},
          {1, h, 1, h, 1, h, 1, h, 1},
          {0, 0, 0, 0.25, 0.25, 0.5, 0.5, 0.75, 0.75, 1, 1, 1},
          3};
}

// The butterfly of projects/contouring/butterfly.yaml, rebuilt from its recipe.
NurbsBenchCurve bench_polar(int n, int order) {
  NurbsBenchCurve c;
  c.order = order;
  for (int j = 0; j < n; ++j) {
    const double th = -M_PI / 2 + 2 * M_PI * j / (n - 1);
    const double s2 = std::sin(2 * th);
    const double r = 0.015 + 0.035 * s2 * s2 * (1 + 0.35 * std::sin(th));
    c.x.push_back(r * std::cos(th));
    c.y.push_back(r * std::sin(th) + 0.015);
    c.w.push_back(1 + std::abs(s2));
  }
  c.x.front() = c.x.back() = 0;
  c.y.front() = c.y.back() = 0;
  c.knots.assign(static_cast<std::size_t>(order), 0.0);
  for (int j = 1; j <= n - order; ++j) c.knots.push_back(static_cast<double>(j) / (n - order + 1));
  c.knots.insert(c.knots.end(), static_cast<std::size_t>(order), 1.0);
  return c;
}

void BM_NurbsPath(benchmark::State& state, NurbsBenchCurve c) {
  BlockHarness::Options o;
  o.params = {{"points", std::to_string(c.x.size())},
              {"order", std::to_string(c.order)},
              {"knots", std::to_string(c.knots.size())},
              {"feed", "0.05"}};
  o.period_ns = 1'000'000;
  BlockHarness h(builtin_blocks(), "NURBS_PATH", o);
  if (!h.ok()) {
    state.SkipWithError("NURBS_PATH did not build");
    return;
  }
  for (std::size_t i = 0; i < c.x.size(); ++i) {
    const auto e = static_cast<std::uint32_t>(i);
    h.set<double>("px", e, c.x[i]);
    h.set<double>("py", e, c.y[i]);
    h.set<double>("w", e, c.w[i]);
  }
  for (std::size_t i = 0; i < c.knots.size(); ++i) h.set<double>("knot", static_cast<std::uint32_t>(i), c.knots[i]);
  h.set<double>("override", 1.0);
  Cell& exec = h.cell("Execute");
  Cell& done = h.cell("Done");
  Cell& x = h.cell("x");
  exec.set<bool>(true);
  h.scan();
  if (!h.get<bool>("Busy")) {
    state.SkipWithError("NURBS_PATH did not start");
    return;
  }
  long restarts = 0, scans = 0;
  for (auto _ : state) {
    h.scan();
    ++scans;
    benchmark::DoNotOptimize(x.raw);
    if (done.get<bool>()) {
      exec.set<bool>(false);
      h.scan();
      exec.set<bool>(true);
      ++restarts;
    }
  }
  state.counters["restarts"] = scans ? static_cast<double>(restarts) / static_cast<double>(scans) : 0.0;
}

BENCHMARK_CAPTURE(BM_NurbsPath, circle, bench_circle());
BENCHMARK_CAPTURE(BM_NurbsPath, butterfly, bench_polar(25, 4));
BENCHMARK_CAPTURE(BM_NurbsPath, order8, bench_polar(40, 8));

}  // namespace
BENCHMARK_MAIN();
