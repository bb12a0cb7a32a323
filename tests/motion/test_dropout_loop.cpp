// The exact output power of the loop with dropouts (fblocks/motion/dropout_loop.*)
// and Ling & Lemmon's optimal compensator found from it (dropout_design.*),
// against a direct simulation of the loop's difference equations (written
// here, apart from the state-space model under test), finite differences,
// and exhaustive scans of the taps.
#include <gtest/gtest.h>

#include <Eigen/Dense>

#include <cmath>
#include <cstdint>
#include <random>
#include <stdexcept>
#include <vector>

#include "fblocks/motion/dropout_design.hpp"
#include "fblocks/motion/dropout_loop.hpp"
#include "fblocks/motion/optimal_compensator_math.hpp"

namespace syncplc::motion {
namespace dropout_loop_test {

// Paper 003 §4.1's identified DYNA plant; unit feedback; one frame late.
DropoutLoop paper_loop() {
  DropoutLoop l;
  l.plant.num = {0, 0, 0.30554, -0.023766, 0.11104, 0.028834};
  l.plant.den = {1, -0.70669, 0.1934, -0.15112, -0.02566, 0.028011};
  l.delay = 1;
  return l;
}

// The loop run scan by scan from its difference equations, as
// projects/paper003_compensators/loop.st runs it: u = C(r - ybar),
// y = P u, ybar = y[k - delay] when received, else sum a_j ybar[k-j].
class DirectLoop {
 public:
  DirectLoop(const DropoutLoop& l, std::vector<double> taps) : l_(l), a_(std::move(taps)) {
    u_.assign(l.plant.num.size() + 1, 0.0);
    y_.assign(std::max(l.plant.den.size(), static_cast<std::size_t>(l.delay)) + 1, 0.0);
    e_.assign(l.controller.num.size() + 1, 0.0);
    uc_.assign(l.controller.den.size() + 1, 0.0);
    h_.assign(a_.size() + 1, 0.0);
  }
  // One scan; returns y[k].
  double step(double r, bool lost) {
    double ybar = 0;
    if (!lost) {
      ybar = y_[static_cast<std::size_t>(l_.delay) - 1];
    } else {
      for (std::size_t j = 0; j < a_.size(); ++j) ybar += a_[j] * h_[j];
    }
    const double e = r - ybar;
    // Controller: sum_i cn_i e[k-i] = sum_i cd_i u[k-i].
    double u = l_.controller.num[0] * e;
    for (std::size_t i = 1; i < l_.controller.num.size(); ++i) u += l_.controller.num[i] * e_[i - 1];
    for (std::size_t i = 1; i < l_.controller.den.size(); ++i) u -= l_.controller.den[i] * uc_[i - 1];
    u /= l_.controller.den[0];
    double y = l_.plant.num[0] * u;
    for (std::size_t i = 1; i < l_.plant.num.size(); ++i) y += l_.plant.num[i] * u_[i - 1];
    for (std::size_t i = 1; i < l_.plant.den.size(); ++i) y -= l_.plant.den[i] * y_[i - 1];
    y /= l_.plant.den[0];
    push(e_, e);
    push(uc_, u);
    push(u_, u);
    push(y_, y);
    push(h_, ybar);
    return y;
  }

 private:
  static void push(std::vector<double>& v, double x) {
    for (std::size_t i = v.size() - 1; i > 0; --i) v[i] = v[i - 1];
    v[0] = x;
  }
  DropoutLoop l_;
  std::vector<double> a_;
  std::vector<double> u_, y_, e_, uc_, h_;
};

// E[y^2] by simulation: white Gaussian r of the loop's variance, Bernoulli loss.
double simulated_power(const DropoutLoop& l, const std::vector<double>& taps, double eps, int scans, std::uint32_t seed) {
  DirectLoop loop(l, taps);
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> noise(0.0, std::sqrt(l.input_variance));
  std::bernoulli_distribution loss(eps);
  double sum = 0;
  const int warmup = 2000;
  for (int k = 0; k < scans + warmup; ++k) {
    const double y = loop.step(noise(rng), loss(rng));
    if (k >= warmup) sum += y * y;
  }
  return sum / scans;
}

TEST(DropoutLoop, WithoutLossThePowerIsTheSumOfTheSquaredImpulseResponse) {
  // eps = 0: E[y^2] = sigma2 * sum_k h[k]^2, h the closed loop's impulse response from r to y.
  for (double sigma2 : {1.0, 2.5}) {
    DropoutLoop l = paper_loop();
    l.input_variance = sigma2;
    DirectLoop loop(l, {});
    double energy = 0;
    for (int k = 0; k < 20000; ++k) {
      const double y = loop.step(k == 0 ? 1.0 : 0.0, false);
      energy += y * y;
    }
    const LoopPower p = dropout_loop_power(l, std::vector<double>{0.3, -0.1}, 0.0);
    ASSERT_TRUE(p.ms_stable);
    EXPECT_NEAR(p.output_power, sigma2 * energy, 1e-10 * energy);
  }
  // The design lags of the shipped project come from the same loop: R_yy(0) = 0.19703.
  EXPECT_NEAR(dropout_loop_power(paper_loop(), std::vector<double>{}, 0.0).output_power, 0.19703, 5e-6);
}

TEST(DropoutLoop, MatchesAMonteCarloRunOfTheLoopWithDropouts) {
  // Zero fill, hold, the Wiener-predictor taps and a negative tap, at 20 % and 50 % loss.
  const DropoutLoop l = paper_loop();
  const std::vector<std::vector<double>> cases = {{}, {1.0}, {0.548, 0.212, -0.212, -0.156}, {-0.4}};
  for (double eps : {0.2, 0.5}) {
    for (const auto& taps : cases) {
      const LoopPower p = dropout_loop_power(l, taps, eps);
      ASSERT_TRUE(p.ms_stable);
      const double sim = simulated_power(l, taps, eps, 1'000'000, 7);
      // 1e6 correlated samples: the relative standard error of the estimate is ~0.45 %.
      EXPECT_NEAR(sim, p.output_power, 0.02 * p.output_power) << "eps " << eps << " taps " << taps.size();
    }
  }
}

TEST(DropoutLoop, AControllerWithDynamicsAndALongerDelayMatchTheSimulationToo) {
  DropoutLoop l;
  l.plant.num = {0, 0.2};           // 0.2 z^-1 / (1 - 0.9 z^-1)
  l.plant.den = {1, -0.9};
  l.controller.num = {1.5, -1.2};   // a lead-lag controller
  l.controller.den = {1, -0.5};
  l.delay = 3;
  l.input_variance = 0.7;
  for (double eps : {0.0, 0.1, 0.3}) {
    const std::vector<double> taps = {0.8, 0.1};
    const LoopPower p = dropout_loop_power(l, taps, eps);
    ASSERT_TRUE(p.ms_stable) << eps;
    EXPECT_NEAR(simulated_power(l, taps, eps, 2'000'000, 11), p.output_power, 0.015 * p.output_power) << eps;
  }
}

TEST(DropoutLoop, TheGradientIsTheDerivative) {
  const DropoutLoop l = paper_loop();
  const std::vector<double> a = {0.3, -0.2, 0.1, 0.05};
  for (double eps : {0.05, 0.3, 0.6}) {
    const LoopPower p = dropout_loop_power(l, a, eps, true);
    ASSERT_TRUE(p.ms_stable);
    ASSERT_EQ(p.gradient.size(), a.size());
    for (std::size_t i = 0; i < a.size(); ++i) {
      const double h = 1e-6;
      std::vector<double> ap = a, am = a;
      ap[i] += h, am[i] -= h;
      const double fd = (dropout_loop_power(l, ap, eps).output_power - dropout_loop_power(l, am, eps).output_power) / (2 * h);
      EXPECT_NEAR(p.gradient[i], fd, 1e-7 + 1e-6 * std::abs(fd)) << "eps " << eps << " tap " << i;
    }
  }
}

// The spectral radius of the second-moment operator sum_d p_d A_d (x) A_d,
// from its eigenvalues: the textbook test of mean-square stability, which
// dropout_loop_power replaces by a positive-definiteness check.
double second_moment_radius(const DropoutLoop& l, const std::vector<double>& a, double eps) {
  const DropoutLoopSystem s = dropout_loop_system(l, a);
  const auto n = s.A[0].rows();
  Eigen::MatrixXd t = Eigen::MatrixXd::Zero(n * n, n * n);
  const double p[2] = {1 - eps, eps};
  for (int d = 0; d < 2; ++d)
    for (Eigen::Index i = 0; i < n; ++i)
      for (Eigen::Index k = 0; k < n; ++k) t.block(i * n, k * n, n, n) += p[d] * s.A[d](i, k) * s.A[d];
  return t.eigenvalues().cwiseAbs().maxCoeff();
}

TEST(DropoutLoop, MeanSquareStabilityAgreesWithTheSpectralRadius) {
  // Paper 003 eq. (6) as taps (4, -6, 4, -1) in the loop, hold, and a gain
  // that makes the loop ring: on both sides of each threshold.
  const DropoutLoop l = paper_loop();
  for (const std::vector<double>& taps : {std::vector<double>{4, -6, 4, -1}, std::vector<double>{1.0},
                                          std::vector<double>{-1.8}, std::vector<double>{}}) {
    for (double eps : {0.0, 0.005, 0.01, 0.015, 0.02, 0.05, 0.2, 0.5, 0.9}) {
      const double rho = second_moment_radius(l, taps, eps);
      if (std::abs(rho - 1.0) < 1e-6) continue;  // on the boundary either answer is right
      EXPECT_EQ(dropout_loop_power(l, taps, eps).ms_stable, rho < 1.0)
          << "taps " << taps.size() << " eps " << eps << " radius " << rho;
    }
  }
  // The recursive Taylor loop's threshold: between 1 % and 2 % loss.
  double lo = 0.0, hi = 0.6;
  const std::vector<double> taylor = {4, -6, 4, -1};
  for (int i = 0; i < 40; ++i) {
    const double mid = 0.5 * (lo + hi);
    (dropout_loop_power(l, taylor, mid).ms_stable ? lo : hi) = mid;
  }
  EXPECT_GT(lo, 0.01);
  EXPECT_LT(lo, 0.02);
  EXPECT_LT(second_moment_radius(l, taylor, 0.99 * lo), 1.0);
  EXPECT_GT(second_moment_radius(l, taylor, 1.01 * lo), 1.0);
  // Below it, the simulated power settles at the computed one.
  const double below = 0.5 * lo;
  const double p = dropout_loop_power(l, taylor, below).output_power;
  EXPECT_NEAR(simulated_power(l, taylor, below, 2'000'000, 3), p, 0.05 * p);
}

TEST(DropoutDesign, OrderOneFindsTheMinimumOfAFineScan) {
  const DropoutLoop l = paper_loop();
  for (double eps : {0.2, 0.6}) {
    double best = HUGE_VAL, best_a = 0;
    for (int i = -2000; i <= 2000; ++i) {
      const std::vector<double> a = {0.001 * i};
      const LoopPower p = dropout_loop_power(l, a, eps);
      if (p.ms_stable && p.output_power < best) best = p.output_power, best_a = a[0];
    }
    const DropoutDesign d = design_dropout_compensator(l, 1, eps);
    ASSERT_EQ(d.taps.size(), 1u);
    EXPECT_LE(d.output_power, best + 1e-12) << eps;
    EXPECT_NEAR(d.taps[0], best_a, 0.0015) << eps;
    EXPECT_LT(d.gradient_norm, 1e-7) << eps;
  }
}

TEST(DropoutDesign, OrderTwoIsNoWorseThanAnyPointOfAGrid) {
  const DropoutLoop l = paper_loop();
  const double eps = 0.3;
  double best = HUGE_VAL;
  for (int i = -40; i <= 40; ++i)
    for (int j = -40; j <= 40; ++j) {
      const std::vector<double> a = {0.05 * i, 0.05 * j};
      const LoopPower p = dropout_loop_power(l, a, eps);
      if (p.ms_stable) best = std::min(best, p.output_power);
    }
  const DropoutDesign d = design_dropout_compensator(l, 2, eps);
  EXPECT_LE(d.output_power, best + 1e-12);
  EXPECT_LT(d.gradient_norm, 1e-7);
}

TEST(DropoutDesign, BeatsZeroFillHoldAndTheWienerPredictorAtEveryRate) {
  // The design lags of projects/paper003_compensators (R_yy(j)/R_yy(0) without loss).
  const double r[5] = {1.0, 0.658608, 0.393834, 0.018494, -0.218310};
  const DropoutLoop l = paper_loop();
  double previous = 0;
  for (double eps : {0.05, 0.1, 0.2, 0.3, 0.4, 0.5, 0.6}) {
    const DropoutDesign d = design_dropout_compensator(l, 4, eps);
    const double zero = dropout_loop_power(l, std::vector<double>(4, 0.0), eps).output_power;
    const double hold = dropout_loop_power(l, std::vector<double>{1, 0, 0, 0}, eps).output_power;
    const OptimalDropoutPredictor w = optimal_dropout_predictor(r, 4, eps);
    const double wiener = dropout_loop_power(l, std::vector<double>(w.a, w.a + 4), eps).output_power;
    EXPECT_LT(d.output_power, zero) << eps;
    EXPECT_LT(d.output_power, hold) << eps;
    EXPECT_LT(d.output_power, wiener) << eps;
    EXPECT_LT(d.gradient_norm, 1e-7) << eps;
    // Its taps are a local minimum: no coordinate step lowers the power.
    for (std::size_t i = 0; i < 4; ++i)
      for (double h : {-1e-3, 1e-3}) {
        std::vector<double> a = d.taps;
        a[i] += h;
        EXPECT_GE(dropout_loop_power(l, a, eps).output_power, d.output_power - 1e-15) << eps;
      }
    previous = d.output_power;
  }
  EXPECT_GT(previous, 0);
}

TEST(DropoutDesign, RejectsWhatItCannotAnalyse) {
  DropoutLoop l = paper_loop();
  l.plant.den[0] = 0;
  EXPECT_THROW(design_dropout_compensator(l, 2, 0.1), std::invalid_argument);
  l = paper_loop();
  l.delay = 0;
  try {
    dropout_loop_power(l, std::vector<double>{}, 0.1);
    FAIL();
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("delay"), std::string::npos);
  }
  EXPECT_THROW(design_dropout_compensator(paper_loop(), 0, 0.1), std::invalid_argument);
  // Bounded work and memory: a loop of more than 24 states is refused, with the count.
  l = paper_loop();
  l.delay = 17;  // 5 + 17 = 22 states: fine alone, 26 with four taps
  EXPECT_TRUE(dropout_loop_error(l).empty()) << dropout_loop_error(l);
  EXPECT_THROW(dropout_loop_power(l, std::vector<double>(4, 0.0), 0.1), std::invalid_argument);
  l.controller.den.assign(10, 0.1);
  l.controller.den[0] = 1;
  EXPECT_NE(dropout_loop_error(l).find("31 states"), std::string::npos) << dropout_loop_error(l);
  EXPECT_THROW(design_dropout_compensator(paper_loop(), 2, 1.0), std::invalid_argument);
  // An open-loop unstable plant under 95 % loss: nothing holds it.
  DropoutLoop unstable;
  unstable.plant.num = {0, 1.0};
  unstable.plant.den = {1, -1.5};
  unstable.controller.num = {0.8};  // z^2 - 1.5 z + 0.8: stable without loss
  EXPECT_TRUE(dropout_loop_power(unstable, std::vector<double>{}, 0.0).ms_stable);
  EXPECT_THROW(design_dropout_compensator(unstable, 1, 0.95), std::runtime_error);
}

}  // namespace dropout_loop_test
}  // namespace syncplc::motion
