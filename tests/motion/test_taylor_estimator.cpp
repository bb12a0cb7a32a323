// MessageEstimator algebra: the Taylor coefficients of paper 003 eqs. (3)-(5),
// exactness on constant and linear signals, the constant-acceleration error,
// start-up without zero padding, the extrapolation limit, predict_next().
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <vector>

#include "fblocks/motion/message_estimator.hpp"
#include "runtime/core/sim_random.hpp"

namespace syncplc::motion {
namespace {

constexpr EstimatorHistory kRobust = EstimatorHistory::Robust;
constexpr EstimatorHistory kRecursive = EstimatorHistory::Recursive;
constexpr EstimatorHistory kZero = EstimatorHistory::Zero;

// Deterministic stream (splitmix64) for reproducible loss patterns.
using Rng = SimRandom;

TEST(TaylorCoefficients, SumToOneForEveryOrder) {
  for (int order = 0; order <= 3; ++order) {
    const double* c = taylor_coefficients(order);
    double sum = 0;
    for (int i = 0; i <= order; ++i) sum += c[i];
    EXPECT_DOUBLE_EQ(sum, 1.0) << order;
  }
  EXPECT_EQ(taylor_coefficients(-1), kTaylor0);
  EXPECT_EQ(taylor_coefficients(7), kTaylor3);
}

TEST(TaylorCoefficients, PaperEquation5IsEquations3And4) {
  EXPECT_DOUBLE_EQ(kTaylor3[0], 21.0 / 8);
  EXPECT_DOUBLE_EQ(kTaylor3[1], -19.0 / 8);
  EXPECT_DOUBLE_EQ(kTaylor3[2], 7.0 / 8);
  EXPECT_DOUBLE_EQ(kTaylor3[3], -1.0 / 8);
  Rng rng{11};
  for (int trial = 0; trial < 100; ++trial) {
    double p[5];  // p[i] = P(k-i), i = 1..4
    for (int i = 1; i <= 4; ++i) p[i] = rng.uniform() * 200 - 100;
    const double d1 = p[1] - p[2], d2 = p[2] - p[3], d3 = p[3] - p[4];        // dP(k-1), dP(k-2), dP(k-3)
    const double v = d1 + 0.5 * (d1 - d2) + 0.125 * (d1 - 2 * d2 + d3);       // eq. (3)
    const double eq4 = p[1] + v;                                               // eq. (4)
    const double eq5 = kTaylor3[0] * p[1] + kTaylor3[1] * p[2] + kTaylor3[2] * p[3] + kTaylor3[3] * p[4];
    EXPECT_NEAR(eq4, eq5, 1e-12) << trial;
    // The lower orders are the truncations of the same series.
    const double nab2 = p[1] - 2 * p[2] + p[3];
    EXPECT_NEAR(kTaylor2[0] * p[1] + kTaylor2[1] * p[2] + kTaylor2[2] * p[3], p[1] + d1 + 0.5 * nab2, 1e-12);
    EXPECT_NEAR(kTaylor1[0] * p[1] + kTaylor1[1] * p[2], p[1] + d1, 1e-12);
  }
}

// Feeds n samples x(0..n-1), then loses `lost` samples; returns the estimates.
template <class F>
std::vector<double> run_then_lose(MessageEstimator& e, F x, int n, int lost) {
  for (int k = 0; k < n; ++k) EXPECT_EQ(e.update(true, x(k)), x(k));
  std::vector<double> est;
  for (int k = n; k < n + lost; ++k) est.push_back(e.update(false, 0.0));
  return est;
}

TEST(MessageEstimator, ExactOnConstantForEveryOrderAndHistory) {
  for (auto h : {kRobust, kRecursive})
    for (int order = 0; order <= 3; ++order) {
      MessageEstimator e(order, h);
      auto est = run_then_lose(e, [](int) { return 17.25; }, 6, 30);
      for (double v : est) EXPECT_DOUBLE_EQ(v, 17.25) << order << " " << int(h);
    }
}

TEST(MessageEstimator, ExactOnLinearForOrders1To3) {
  const auto x = [](int k) { return -3.0 + 0.75 * k; };
  for (auto h : {kRobust, kRecursive})
    for (int order = 1; order <= 3; ++order) {
      MessageEstimator e(order, h, 1000);
      auto est = run_then_lose(e, x, 8, 25);
      for (int i = 0; i < 25; ++i) EXPECT_NEAR(est[static_cast<std::size_t>(i)], x(8 + i), 1e-10) << order << " " << i;
    }
  // Order 0 holds: its error grows by one slope per lost sample.
  MessageEstimator hold(0);
  auto est = run_then_lose(hold, x, 8, 5);
  for (int i = 0; i < 5; ++i) EXPECT_DOUBLE_EQ(est[static_cast<std::size_t>(i)] - x(8 + i), -0.75 * (i + 1));
}

// The robust form stays exact on a linear signal under any loss pattern, as
// long as it extrapolates (it uses the secant across a gap when a single
// sample arrived after it).
TEST(MessageEstimator, RobustExactOnLinearUnderRandomLoss) {
  const auto x = [](int k) { return 5.0 - 0.01 * k; };
  for (int order = 1; order <= 3; ++order) {
    MessageEstimator e(order, kRobust, 50);
    Rng rng{static_cast<std::uint64_t>(order)};
    int checked = 0;
    for (int k = 0; k < 20000; ++k) {
      const bool lost = k > 1 && rng.chance(0.4);
      // Keep gaps short enough that the secant and ramp always apply.
      const bool valid = !lost || e.consecutive() >= 20;
      const double y = e.update(valid, x(k));
      if (!valid && k > 2) {
        EXPECT_NEAR(y, x(k), 1e-9) << order << " " << k;
        ++checked;
      }
    }
    EXPECT_GT(checked, 7000);
  }
}

// On x = a t^2 / 2 the increment the predictor extrapolates is exactly the
// velocity at the last sample times T, so the single-step error is
// -a T^2 / 2 (orders 2, 3) or -a T^2 (order 1, the 2-tap), and the h-th
// frozen-velocity estimate misses by -a (h T)^2 / 2.
TEST(MessageEstimator, ConstantAccelerationError) {
  const double a = 50.0, T = 1e-3;  // mm/s^2 and s: the paper's sinusoid's peak acceleration at 1 ms
  const auto x = [&](int k) { return 0.5 * a * (k * T) * (k * T) + 20.0 * k * T + 1.0; };
  for (int order = 1; order <= 3; ++order) {
    MessageEstimator rob(order, kRobust, 100), rec(order, kRecursive, 100);
    auto er = run_then_lose(rob, x, 10, 8);
    auto ec = run_then_lose(rec, x, 10, 1);
    const double c = order == 1 ? 1.0 : 0.5;  // error = -c a T^2
    EXPECT_NEAR(er[0] - x(10), -c * a * T * T, 1e-12) << order;
    EXPECT_NEAR(ec[0] - x(10), -c * a * T * T, 1e-12) << order;
    if (order >= 2) {
      for (int h = 1; h <= 8; ++h)
        EXPECT_NEAR(er[static_cast<std::size_t>(h - 1)] - x(9 + h), -a * (h * T) * (h * T) / 2, 1e-11) << h;
    }
  }
}

TEST(MessageEstimator, StartupRampsTheOrderUpWithoutZeroPadding) {
  const auto x = [](int k) { return 500.0 + 2.0 * k; };  // far from 0: zero padding would show
  for (auto h : {kRobust, kRecursive}) {
    {  // nothing received yet: 0, counted as an estimate
      MessageEstimator e(3, h);
      EXPECT_EQ(e.update(false, 123.0), 0.0);
      EXPECT_TRUE(e.estimated());
      EXPECT_EQ(e.consecutive(), 1u);
      EXPECT_EQ(e.update(true, 7.0), 7.0);  // the first sample is taken as is
      EXPECT_FALSE(e.estimated());
      EXPECT_EQ(e.consecutive(), 0u);
    }
    {  // one sample: hold
      MessageEstimator e(3, h);
      EXPECT_EQ(e.effective_order(), 0);
      auto est = run_then_lose(e, x, 1, 1);
      EXPECT_DOUBLE_EQ(est[0], 500.0);
    }
    for (int n = 2; n <= 4; ++n) {  // n samples: order n-1, exact on the ramp
      MessageEstimator e(3, h);
      for (int k = 0; k < n; ++k) e.update(true, x(k));
      EXPECT_EQ(e.effective_order(), n - 1);
      EXPECT_DOUBLE_EQ(e.update(false, 0.0), x(n)) << n;
    }
  }
  // The zero-padded history (history = Zero) is what the ramp-up avoids: an
  // error the size of the signal.
  MessageEstimator z(3, kZero);
  auto est = run_then_lose(z, x, 1, 1);
  EXPECT_DOUBLE_EQ(est[0], 21.0 / 8 * 500.0);
  EXPECT_GT(std::abs(est[0] - x(1)), 500.0);
}

TEST(MessageEstimator, ZeroHistoryRecordsLostSamplesAsZero) {
  MessageEstimator z(3, kZero), r(3, kRecursive);
  for (int k = 0; k < 10; ++k) {
    z.update(true, 100.0);
    r.update(true, 100.0);
  }
  EXPECT_DOUBLE_EQ(z.update(false, 0), 100.0);  // the first loss still sees true samples
  z.update(true, 100.0);
  // History now 100, 0, 100, 100: the estimate is off by 19/8 * 100.
  EXPECT_DOUBLE_EQ(z.update(false, 0), 21.0 / 8 * 100 + 7.0 / 8 * 100 - 1.0 / 8 * 100);
  EXPECT_DOUBLE_EQ(r.update(false, 0), 100.0);
}

TEST(MessageEstimator, RobustRampsThenHoldsAfterMaxExtrapolation) {
  const auto x = [](int k) { return 2.0 * k; };
  MessageEstimator e(3, kRobust, 5);
  auto est = run_then_lose(e, x, 6, 12);
  for (int h = 1; h <= 12; ++h) {
    const double expect = x(5) + 2.0 * std::min(h, 5);
    EXPECT_NEAR(est[static_cast<std::size_t>(h - 1)], expect, 1e-12) << h;
  }
  EXPECT_EQ(e.consecutive(), 12u);
  EXPECT_TRUE(e.estimated());
  // max_extrapolation 0: hold from the first loss.
  MessageEstimator h0(3, kRobust, 0);
  auto e0 = run_then_lose(h0, x, 6, 3);
  for (double v : e0) EXPECT_DOUBLE_EQ(v, x(5));
}

TEST(MessageEstimator, RecursiveHoldsAfterMaxExtrapolation) {
  const auto x = [](int k) { return 1.0 + 0.5 * k; };
  MessageEstimator e(3, kRecursive, 4);
  auto est = run_then_lose(e, x, 6, 10);
  for (int h = 1; h <= 10; ++h) EXPECT_NEAR(est[static_cast<std::size_t>(h - 1)], x(5 + std::min(h, 4)), 1e-12) << h;
}

// After a gap with a single new sample, the robust form uses the secant to
// the sample before the gap, unless that one is too old: then it holds.
TEST(MessageEstimator, RobustSecantAcrossAGap) {
  const auto x = [](int k) { return 10.0 + 3.0 * k; };
  MessageEstimator e(3, kRobust, 4);
  for (int k = 0; k < 5; ++k) e.update(true, x(k));
  for (int k = 5; k < 8; ++k) e.update(false, 0);  // gap of 3
  e.update(true, x(8));                             // 4 scans after x(4)
  EXPECT_EQ(e.effective_order(), 1);
  EXPECT_DOUBLE_EQ(e.update(false, 0), x(9));
  EXPECT_DOUBLE_EQ(e.update(false, 0), x(10));
  MessageEstimator old(3, kRobust, 4);
  for (int k = 0; k < 5; ++k) old.update(true, x(k));
  for (int k = 5; k < 10; ++k) old.update(false, 0);  // 6 scans between samples > max_extrapolation + 1
  old.update(true, x(10));
  EXPECT_EQ(old.effective_order(), 0);
  EXPECT_DOUBLE_EQ(old.update(false, 0), x(10));
  // The contiguous run then ramps the order up again.
  MessageEstimator r(3, kRobust, 4);
  for (int k = 0; k < 5; ++k) r.update(true, x(k));
  r.update(false, 0);
  for (int k = 6; k < 9; ++k) r.update(true, x(k));
  EXPECT_EQ(r.effective_order(), 2);
  r.update(true, x(9));
  EXPECT_EQ(r.effective_order(), 3);
}

TEST(MessageEstimator, PredictNextIsTheNextEstimate) {
  for (auto h : {kRobust, kRecursive, kZero})
    for (int order = 0; order <= 3; ++order) {
      MessageEstimator e(order, h, 7);
      Rng rng{static_cast<std::uint64_t>(order * 10 + int(h))};
      for (int k = 0; k < 3000; ++k) {
        const double predicted = e.predict_next();
        const bool valid = !rng.chance(0.45);
        const double s = std::sin(0.01 * k) * 40.0;
        const double y = e.update(valid, s);
        if (!valid) {
          EXPECT_EQ(y, predicted) << order << " " << int(h) << " " << k;
        }
      }
    }
}

// Paper 000 eq. (15): a one-scan-late stream, predicted forward by one scan.
TEST(MessageEstimator, PredictNextCompensatesOneScanDelay) {
  const double T = 1e-3, w = 2.0;
  MessageEstimator e(3);
  double worst_pred = 0, worst_delay = 0;
  for (int k = 1; k < 5000; ++k) {
    e.update(true, std::sin(w * (k - 1) * T));  // e_i(t - Ts) arrives at t
    if (k < 5) continue;
    const double truth = std::sin(w * k * T);
    worst_pred = std::max(worst_pred, std::abs(e.predict_next() - truth));
    worst_delay = std::max(worst_delay, std::abs(e.output() - truth));
  }
  EXPECT_LT(worst_pred, w * w * T * T);        // about a T^2 / 2
  EXPECT_GT(worst_delay, 0.9 * w * T);         // the uncompensated delay costs v T
  EXPECT_LT(worst_pred, worst_delay / 500);
}

TEST(MessageEstimator, NonFiniteSampleCountsAsLost) {
  MessageEstimator e(1);
  e.update(true, 1.0);
  e.update(true, 2.0);
  EXPECT_DOUBLE_EQ(e.update(true, std::nan("")), 3.0);
  EXPECT_TRUE(e.estimated());
  EXPECT_DOUBLE_EQ(e.update(true, INFINITY), 4.0);
  EXPECT_EQ(e.consecutive(), 2u);
}

TEST(MessageEstimator, ResetAndConfiguration) {
  MessageEstimator e(9, kRecursive, 3);
  EXPECT_EQ(e.order(), 3);
  EXPECT_EQ(e.history(), kRecursive);
  EXPECT_EQ(e.max_extrapolation(), 3u);
  EXPECT_EQ(MessageEstimator(-2).order(), 0);
  for (int k = 0; k < 5; ++k) e.update(true, 100.0 + k);
  e.update(false, 0);
  MessageEstimator copy = e;  // copyable, state included
  EXPECT_EQ(copy.predict_next(), e.predict_next());
  e.reset();
  EXPECT_EQ(e.consecutive(), 0u);
  EXPECT_EQ(e.output(), 0.0);
  EXPECT_EQ(e.effective_order(), 0);
  EXPECT_EQ(e.update(false, 5.0), 0.0);
  EXPECT_EQ(copy.consecutive(), 1u);
}

}  // namespace
}  // namespace syncplc::motion
