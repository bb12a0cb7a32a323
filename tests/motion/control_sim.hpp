// Test support for the controller blocks: the paper-000 plant (section 5,
// P(s) = k/(s(τs+1)) per axis, exact zero-order-hold discretization) and a
// closed-loop run of SYNC_CONTROLLER or PD_CONTROLLER instances on it through
// BlockHarness, with the metrics of eqs. (26)–(27).
#pragma once

#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <map>
#include <memory>
#include <numbers>
#include <random>
#include <set>
#include <string>
#include <vector>

#include "fblocks/library.hpp"
#include "runtime/core/block_harness.hpp"

namespace syncplc::motiontest {

inline const BlockRegistry& registry() { return builtin_blocks(); }

inline std::string errors_of(const BlockHarness& h) {
  std::string s;
  for (const auto& e : h.errors()) s += e + "\n";
  return s;
}

#define ASSERT_CTL_OK(h) ASSERT_TRUE((h).ok()) << ::syncplc::motiontest::errors_of(h)

// One axis: x' = w, w' = (k u − w)/τ, i.e. P(s) = k/(s(τs+1)), u in PWM.
// Exact ZOH over T (closed form of exp([A B; 0 0] T), a = e^{−T/τ}):
//   x⁺ = x + τ(1−a) w + k(T − τ(1−a)) u,   w⁺ = a w + k(1−a) u.
struct ZohAxis {
  double tau_c, k, T;
  double phi12, phi22, g1, g2;  // Φ = [1 phi12; 0 phi22], Γ = [g1; g2]
  double x = 0, w = 0;

  ZohAxis(double tau, double gain, double period) : tau_c(tau), k(gain), T(period) {
    const double one_minus_a = -std::expm1(-T / tau);
    phi12 = tau * one_minus_a;
    phi22 = 1.0 - one_minus_a;
    g1 = k * (T - tau * one_minus_a);
    g2 = k * one_minus_a;
  }
  void step(double u) {
    const double xn = x + phi12 * w + g1 * u;
    w = phi22 * w + g2 * u;
    x = xn;
  }
};

// Section 5: τ = 0.055, 0.056, 0.040 s; k = 35.6206, 36.3872, 52.2836 (rad/s)/PWM;
// axis 4 = axis 2 (it gets the input disturbance).
inline std::vector<ZohAxis> paper_plant(double T) {
  return {ZohAxis(0.055, 35.6206, T), ZohAxis(0.056, 36.3872, T), ZohAxis(0.040, 52.2836, T),
          ZohAxis(0.056, 36.3872, T)};
}

// The paper's gains converted to SI (docs/motion/sync-controller.md).
struct PaperGains {
  double K_P = 0.6221;       // PWM/rad
  double K_D = 0.6221e-3;    // PWM·s/rad   (printed 0.6221 PWM·ms/rad)
  double K_H = 0.001544;     // PWM·s²/rad  (printed "ms²", SI: τ_1/k_1)
  double K_C = 0.02807;      // PWM·s/rad   (printed "ms", SI: 1/k_1)
  double m = 258.6268e-3;    // PWM·s/rad   (printed 258.6268 PWM·ms/rad)
  double alpha = 1.3;
};

enum class Ctl { Sync, Pd };

struct Reference {
  // x_d(t), v_d(t), a_d(t)
  std::function<void(double, double&, double&, double&)> at;
};

// x_d = A(1 − cos ωt), A = 4π rad, ω = 1 rad/s: peak speed Aω = 753.98 rad/min.
inline Reference cosine_reference(double A = 4 * std::numbers::pi, double w = 1.0) {
  return {[A, w](double t, double& x, double& v, double& a) {
            x = A * (1 - std::cos(w * t));
            v = A * w * std::sin(w * t);
            a = A * w * w * std::cos(w * t);
          }};
}

inline Reference step_reference(double X) {
  return {[X](double, double& x, double& v, double& a) {
    x = X;
    v = 0;
    a = 0;
  }};
}

struct RunOptions {
  Ctl ctl = Ctl::Sync;
  std::map<std::string, std::string> params;  // extra/overriding block parameters
  double T = 1e-3;
  int samples = 6283;  // one period of the cosine (2π s) at 1 ms
  bool disturbance = true;  // +0.05 PWM on axis 4 for 2 s ≤ t < 4 s
  std::vector<double> x0 = {0, 0, 0, 0};
  // Loss pattern: lost(scan, axis0) → that axis's error does not arrive.
  std::function<bool(int, int)> lost;
  Reference ref = cosine_reference();
  // Called after every scan with the true errors (before the plant moves).
  std::function<void(int, const std::vector<double>&, const std::vector<double>&)> observe;
};

struct RunResult {
  double track_rsme = 0;     // eq. (26): sqrt(mean_j Σ_i e_i²)
  double sync_rsme = 0;      // eq. (27): sqrt(mean_j Σ_{i≥2} ε_i²), ε = T e on the true errors
  double tau_rms = 0;        // sqrt(mean_j mean_i τ_i²)
  double dtau_rms = 0;       // sqrt(mean_j mean_i (τ_i(j) − τ_i(j−1))²), j ≥ 1
  double sat_fraction = 0;   // fraction of (scan, axis) with saturated
  double final_max_e = 0;    // max |e_i| over the last 10 % of the run
  double final_max_eps = 0;  // max |ε_i| over the last 10 % of the run
  std::uint32_t estimated = 0;  // sum of the blocks' estimated counts
  bool ok = true;
  std::string error;
};

// Runs 4 axes of `ctl` blocks on the paper plant. Axis k gets the other axes'
// `e` outputs of the previous scan in e_rx (the one-scan network delay of
// eq. 13), unless params set rx_delay = 0 (then the current scan's true errors).
inline RunResult run_paper_loop(const RunOptions& o) {
  RunResult r;
  const int n = 4;
  auto plant = paper_plant(o.T);
  for (int i = 0; i < n; ++i) plant[static_cast<std::size_t>(i)].x = o.x0[static_cast<std::size_t>(i)];
  PaperGains pg;
  std::vector<std::unique_ptr<BlockHarness>> blocks;
  for (int k = 1; k <= n; ++k) {
    BlockHarness::Options opt;
    opt.period_ns = std::llround(o.T * 1e9);
    std::set<std::string> connected;
    if (o.ctl == Ctl::Sync) {
      opt.params = {{"axis", std::to_string(k)}, {"n", std::to_string(n)}};
      connected = {"x_d", "v_d", "a_d", "x", "e_rx", "e_valid"};  // v unconnected: backward difference
    } else {
      connected = {"x_d", "v_d", "x"};
    }
    for (const auto& [key, v] : o.params) opt.params[key] = v;
    opt.connected = connected;
    blocks.push_back(std::make_unique<BlockHarness>(registry(), o.ctl == Ctl::Sync ? "SYNC_CONTROLLER" : "PD_CONTROLLER", opt));
    if (!blocks.back()->ok()) {
      r.ok = false;
      r.error = errors_of(*blocks.back());
      return r;
    }
  }
  bool rx_now = false;
  if (auto it = o.params.find("rx_delay"); it != o.params.end()) rx_now = it->second == "0";
  std::vector<double> e(n), eps(n), e_sent(n, 0.0), tau(n, 0.0), tau_prev(n, 0.0);
  double sum_track = 0, sum_sync = 0, sum_tau = 0, sum_dtau = 0;
  long sat = 0;
  const int tail_from = o.samples - o.samples / 10;
  for (int j = 0; j < o.samples; ++j) {
    const double t = j * o.T;
    double xd, vd, ad;
    o.ref.at(t, xd, vd, ad);
    for (int i = 0; i < n; ++i) e[static_cast<std::size_t>(i)] = xd - plant[static_cast<std::size_t>(i)].x;
    double mean = 0;
    for (int i = 0; i < n; ++i) {
      eps[static_cast<std::size_t>(i)] = i == 0 ? 0.0 : e[static_cast<std::size_t>(i)] - mean / i;
      mean += e[static_cast<std::size_t>(i)];
    }
    for (int i = 0; i < n; ++i) {
      sum_track += e[static_cast<std::size_t>(i)] * e[static_cast<std::size_t>(i)];
      if (i > 0) sum_sync += eps[static_cast<std::size_t>(i)] * eps[static_cast<std::size_t>(i)];
      if (j >= tail_from) {
        r.final_max_e = std::max(r.final_max_e, std::abs(e[static_cast<std::size_t>(i)]));
        r.final_max_eps = std::max(r.final_max_eps, std::abs(eps[static_cast<std::size_t>(i)]));
      }
    }
    for (int k = 0; k < n; ++k) {
      BlockHarness& h = *blocks[static_cast<std::size_t>(k)];
      h.set<double>("x_d", xd);
      h.set<double>("v_d", vd);
      h.set<double>("x", plant[static_cast<std::size_t>(k)].x);
      if (o.ctl == Ctl::Sync) {
        h.set<double>("a_d", ad);
        for (int i = 0; i < n; ++i) {
          // Nothing has been sent before the first scan: element invalid, as sim_ring does.
          const bool lost = i < k && (j == 0 || (o.lost && o.lost(j, i)));
          h.set<double>("e_rx", static_cast<std::uint32_t>(i),
                        lost ? 1e6 : (rx_now ? e[static_cast<std::size_t>(i)] : e_sent[static_cast<std::size_t>(i)]));
          h.set<bool>("e_valid", static_cast<std::uint32_t>(i), !lost);
        }
      }
      h.scan();
      tau[static_cast<std::size_t>(k)] = h.get<double>("tau");
      if (h.get<bool>("saturated")) ++sat;
    }
    if (o.observe) o.observe(j, e, eps);
    for (int k = 0; k < n; ++k) {
      const double u = tau[static_cast<std::size_t>(k)];
      sum_tau += u * u;
      if (j > 0) sum_dtau += (u - tau_prev[static_cast<std::size_t>(k)]) * (u - tau_prev[static_cast<std::size_t>(k)]);
      tau_prev[static_cast<std::size_t>(k)] = u;
      const double d = (o.disturbance && k == 3 && t >= 2.0 && t < 4.0) ? 0.05 : 0.0;
      plant[static_cast<std::size_t>(k)].step(u + d);
      e_sent[static_cast<std::size_t>(k)] = blocks[static_cast<std::size_t>(k)]->get<double>("e");
    }
  }
  if (o.ctl == Ctl::Sync)
    for (auto& b : blocks) r.estimated += b->get<std::uint32_t>("estimated");
  r.track_rsme = std::sqrt(sum_track / o.samples);
  r.sync_rsme = std::sqrt(sum_sync / o.samples);
  r.tau_rms = std::sqrt(sum_tau / (o.samples * n));
  r.dtau_rms = std::sqrt(sum_dtau / ((o.samples - 1) * n));
  r.sat_fraction = static_cast<double>(sat) / (o.samples * n);
  return r;
}

}  // namespace syncplc::motiontest
