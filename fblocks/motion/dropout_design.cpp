// The numerical search for Ling & Lemmon's optimal dropout compensator
// (dropout_design.hpp). The objective is exact (dropout_loop.cpp) but not
// convex in the taps, and it is only defined where the loop stays
// mean-square stable; outside, it is +inf. Subplex (a Nelder-Mead variant on
// subspaces) tolerates that; L-BFGS with the exact gradient then polishes
// from inside the stable region.
#include "fblocks/motion/dropout_design.hpp"

#include <nlopt.h>

#include <cmath>
#include <limits>
#include <memory>
#include <stdexcept>

namespace syncplc::motion {
namespace dropout_design_impl {

struct Problem {
  const DropoutLoop* loop;
  double eps;
  int evaluations = 0;
};

double objective(unsigned n, const double* x, double* grad, void* data) {
  auto* pr = static_cast<Problem*>(data);
  ++pr->evaluations;
  const LoopPower lp = dropout_loop_power(*pr->loop, std::span<const double>(x, n), pr->eps, grad != nullptr);
  if (!lp.ms_stable) {
    if (grad)
      for (unsigned i = 0; i < n; ++i) grad[i] = 0.0;
    return HUGE_VAL;
  }
  if (grad)
    for (unsigned i = 0; i < n; ++i) grad[i] = lp.gradient[i];
  return lp.output_power;
}

struct OptDeleter {
  void operator()(nlopt_opt o) const { nlopt_destroy(o); }
};
using Opt = std::unique_ptr<std::remove_pointer_t<nlopt_opt>, OptDeleter>;

// One local search from x (in place); returns the value reached (HUGE_VAL
// when it never left the unstable region).
double local_search(nlopt_algorithm alg, Problem& pr, std::vector<double>& x, int max_evaluations) {
  const auto n = static_cast<unsigned>(x.size());
  Opt opt(nlopt_create(alg, n));
  if (!opt) throw std::runtime_error("NLopt: cannot create the optimiser");
  nlopt_set_min_objective(opt.get(), objective, &pr);
  nlopt_set_xtol_rel(opt.get(), 1e-10);
  nlopt_set_ftol_rel(opt.get(), 1e-14);
  nlopt_set_maxeval(opt.get(), max_evaluations);
  nlopt_set_initial_step1(opt.get(), 0.1);
  double f = HUGE_VAL;
  std::vector<double> y = x;
  const nlopt_result r = nlopt_optimize(opt.get(), y.data(), &f);
  if (r < 0 && r != NLOPT_ROUNDOFF_LIMITED) return HUGE_VAL;  // failed: keep x as it was
  if (std::isfinite(f)) x = y;
  return f;
}

}  // namespace dropout_design_impl

DropoutDesign design_dropout_compensator(const DropoutLoop& loop, int order, double eps) {
  using namespace dropout_design_impl;
  if (auto e = dropout_loop_error(loop); !e.empty()) throw std::invalid_argument(e);
  if (order < 1 || order > 16) throw std::invalid_argument("order must be 1..16");
  if (!(eps >= 0.0 && eps < 1.0)) throw std::invalid_argument("dropout rate must be in [0, 1)");
  Problem pr{&loop, eps};
  const auto n = static_cast<std::size_t>(order);

  struct Start {
    const char* name;
    std::vector<double> x;
  };
  std::vector<Start> starts;
  starts.push_back({"zero fill", std::vector<double>(n, 0.0)});
  std::vector<double> hold(n, 0.0);
  hold[0] = 1.0;
  starts.push_back({"hold", hold});
  hold[0] = -0.5;
  starts.push_back({"negative hold", hold});
  // A coarse scan of a_1 alone finds the basin a local search might miss.
  std::vector<double> scan(n, 0.0), best_scan(n, 0.0);
  double best_scan_f = HUGE_VAL;
  for (int i = -40; i <= 40; ++i) {
    scan[0] = 0.05 * i;
    const double f = objective(static_cast<unsigned>(n), scan.data(), nullptr, &pr);
    if (f < best_scan_f) best_scan_f = f, best_scan = scan;
  }
  if (std::isfinite(best_scan_f)) starts.push_back({"scan of a_1", best_scan});

  DropoutDesign best;
  best.output_power = HUGE_VAL;
  for (auto& s : starts) {
    std::vector<double> x = s.x;
    double f = local_search(NLOPT_LN_SBPLX, pr, x, 4000);
    if (!std::isfinite(f)) continue;
    std::vector<double> polished = x;
    const double g = local_search(NLOPT_LD_LBFGS, pr, polished, 200);
    if (std::isfinite(g) && g <= f) x = polished, f = g;
    if (f < best.output_power) {
      best.output_power = f;
      best.taps = x;
      best.start = s.name;
    }
  }
  best.evaluations = pr.evaluations;
  if (!std::isfinite(best.output_power))
    throw std::runtime_error("no mean-square stable compensator found at this dropout rate (zero fill, hold and a scan "
                             "of a_1 all make the loop unstable)");
  const LoopPower at = dropout_loop_power(loop, best.taps, eps, true);
  double g2 = 0;
  for (double v : at.gradient) g2 += v * v;
  best.gradient_norm = std::sqrt(g2);
  best.output_power = at.output_power;
  return best;
}

}  // namespace syncplc::motion
