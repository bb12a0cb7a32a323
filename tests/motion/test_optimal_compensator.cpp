// The optimal dropout compensator (paper 003 §4's comparison, Ling & Lemmon):
// its load-time coefficients against closed forms (AR(1), AR(2)), their
// optimality for the model's cost, the parameter errors, the block against
// hold on a signal of its design spectrum, and a scan that allocates nothing.
#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <cstdlib>
#include <map>
#include <new>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include "fblocks/library.hpp"
#include "fblocks/motion/message_estimator.hpp"
#include "fblocks/motion/optimal_compensator_math.hpp"
#include "runtime/core/block_harness.hpp"

#include "tests/support/allocation_counter.hpp"

// The no-allocation test below counts this binary's operator new
// (tests/support/allocation_counter.*).
namespace test_optimal_compensator_alloc {
std::atomic<bool>& counting = syncplc::test::counting_allocations;
std::atomic<long>& allocations = syncplc::test::allocations_counted;
}  // namespace test_optimal_compensator_alloc

namespace syncplc::motion {
namespace {

std::vector<double> optimal_test_ar1(double rho, int n) {
  std::vector<double> r(static_cast<std::size_t>(n) + 1);
  for (int j = 0; j <= n; ++j) r[static_cast<std::size_t>(j)] = std::pow(rho, j);
  return r;
}

// x[k] = a1 x[k-1] + a2 x[k-2] + w[k]: normalised autocorrelation from its
// Yule-Walker equations, rho1 = a1 / (1 - a2), rho_j = a1 rho_(j-1) + a2 rho_(j-2).
std::vector<double> optimal_test_ar2(double a1, double a2, int n) {
  std::vector<double> r(static_cast<std::size_t>(n) + 1);
  r[0] = 1.0;
  r[1] = a1 / (1.0 - a2);
  for (int j = 2; j <= n; ++j) r[static_cast<std::size_t>(j)] = a1 * r[static_cast<std::size_t>(j - 1)] + a2 * r[static_cast<std::size_t>(j - 2)];
  return r;
}

TEST(OptimalDropoutPredictor, Ar1OneStepCoefficientIsRhoAtEveryOrder) {
  for (int n = 1; n <= kOptimalMaxOrder; ++n) {
    const auto r = optimal_test_ar1(0.8, n);
    const OptimalDropoutPredictor p = optimal_dropout_predictor(r, n, 0.0);
    EXPECT_NEAR(p.a[0], 0.8, 1e-12) << n;
    for (int j = 1; j < n; ++j) EXPECT_NEAR(p.a[j], 0.0, 1e-12) << n << " " << j;
    EXPECT_NEAR(p.error_variance, 1.0 - 0.64, 1e-12);  // the AR(1) innovation variance
    EXPECT_EQ(p.loading, 0.0);
  }
}

TEST(OptimalDropoutPredictor, Ar2RecoversItsOwnCoefficients) {
  const auto r = optimal_test_ar2(1.6, -0.8, 4);
  const OptimalDropoutPredictor p = optimal_dropout_predictor(r, 4, 0.0);
  EXPECT_NEAR(p.a[0], 1.6, 1e-10);
  EXPECT_NEAR(p.a[1], -0.8, 1e-10);
  EXPECT_NEAR(p.a[2], 0.0, 1e-10);
  EXPECT_NEAR(p.a[3], 0.0, 1e-10);
  EXPECT_NEAR(p.error_variance, 1.0 - 1.6 * r[1] + 0.8 * r[2], 1e-10);
}

// Order 1, AR(1), rate eps: a = rho / (1 + lambda), lambda = eps (1 - a rho),
// so lambda^2 + (1 - eps) lambda - eps (1 - rho^2) = 0 (the positive root).
TEST(OptimalDropoutPredictor, Ar1WithDropoutsMatchesTheClosedForm) {
  for (double eps : {0.05, 0.2, 0.5, 0.9}) {
    const double rho = 0.9;
    const double lambda = (-(1 - eps) + std::sqrt((1 - eps) * (1 - eps) + 4 * eps * (1 - rho * rho))) / 2;
    const OptimalDropoutPredictor p = optimal_dropout_predictor(optimal_test_ar1(rho, 1), 1, eps);
    EXPECT_NEAR(p.loading, lambda, 1e-11) << eps;
    EXPECT_NEAR(p.a[0], rho / (1 + lambda), 1e-11) << eps;
    EXPECT_LT(p.a[0], rho);  // dropouts shrink the predictor toward the mean
  }
}

// Brute force: at the fixed point, every small change of any coefficient
// raises the model's mean-square error; and lambda = eps * s2.
TEST(OptimalDropoutPredictor, CoefficientsMinimiseTheModelCost) {
  const std::vector<double> r = {1.0, 0.658608, 0.393834, 0.018494, -0.218310};  // the paper-003 loop's output
  const double eps = 0.2;
  const OptimalDropoutPredictor p = optimal_dropout_predictor(r, 4, eps);
  EXPECT_NEAR(p.loading, eps * p.error_variance, 1e-12);
  std::vector<double> a(p.a, p.a + 4);
  const double best = optimal_dropout_cost(r, a, p.loading);
  EXPECT_NEAR(best, p.error_variance, 1e-12);
  for (int j = 0; j < 4; ++j)
    for (double d : {-1e-3, 1e-3}) {
      auto b = a;
      b[static_cast<std::size_t>(j)] += d;
      EXPECT_GT(optimal_dropout_cost(r, b, p.loading), best) << j << " " << d;
    }
}

TEST(OptimalDropoutPredictor, RejectsWhatIsNotAnAutocorrelationOrOutOfRange) {
  const auto r = optimal_test_ar1(0.5, 8);
  auto message = [](auto&& f) {
    try {
      f();
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_NE(message([&] { optimal_dropout_predictor(r, 0, 0.1); }).find("order must be 1..8"), std::string::npos);
  EXPECT_NE(message([&] { optimal_dropout_predictor(r, 9, 0.1); }).find("order must be 1..8"), std::string::npos);
  EXPECT_NE(message([&] { optimal_dropout_predictor(r, 2, 1.0); }).find("dropout rate"), std::string::npos);
  EXPECT_NE(message([&] { optimal_dropout_predictor(r, 2, -0.1); }).find("dropout rate"), std::string::npos);
  EXPECT_NE(message([&] { optimal_dropout_predictor(r, 2, std::nan("")); }).find("dropout rate"), std::string::npos);
  const std::vector<double> zero_power = {0.0, 0.0, 0.0};
  EXPECT_NE(message([&] { optimal_dropout_predictor(zero_power, 2, 0.1); }).find("lag 0"), std::string::npos);
  const std::vector<double> not_pd = {1.0, 0.9, -0.9};  // |rho2 - rho1^2| too large for any process
  EXPECT_NE(message([&] { optimal_dropout_predictor(not_pd, 2, 0.1); }).find("not an autocorrelation"), std::string::npos);
  const std::vector<double> sinusoid = {1.0, 1.0, 1.0};  // singular: a constant, perfectly predictable
  EXPECT_NE(message([&] { optimal_dropout_predictor(sinusoid, 2, 0.1); }).find("not an autocorrelation"), std::string::npos);
  const std::vector<double> short_r = {1.0, 0.5};
  EXPECT_NE(message([&] { optimal_dropout_predictor(short_r, 2, 0.1); }).find("lags 0..2"), std::string::npos);
}

BlockHarness make_optimal(std::map<std::string, std::string> params = {}) {
  BlockHarness::Options o;
  o.params = std::move(params);
  return BlockHarness(builtin_blocks(), "OPTIMAL_COMPENSATOR", o);
}

std::string optimal_errors(const BlockHarness& h) {
  std::string s;
  for (const auto& e : h.errors()) s += e + "\n";
  return s;
}

TEST(OptimalCompensatorBlock, Declaration) {
  const BlockTypeInfo* t = builtin_blocks().find("OPTIMAL_COMPENSATOR");
  ASSERT_NE(t, nullptr);
  EXPECT_EQ(t->category, "Motion");
  for (const char* p : {"in", "valid", "out", "estimated", "consecutive"}) EXPECT_GE(t->pin_index(p), 0) << p;
  for (const char* p : {"order", "dropout_rate", "rho1", "rho2", "rho3", "rho4"}) EXPECT_GE(t->param_index(p), 0) << p;
  EXPECT_NE(t->reference.find("Ling"), std::string::npos);
}

TEST(OptimalCompensatorBlock, BadParametersAreLoadErrorsWithTheReason) {
  EXPECT_NE(optimal_errors(make_optimal({{"order", "0"}})).find("order"), std::string::npos);
  EXPECT_NE(optimal_errors(make_optimal({{"order", "5"}})).find("order"), std::string::npos);
  EXPECT_NE(optimal_errors(make_optimal({{"dropout_rate", "0.99"}})).find("dropout_rate must be <="), std::string::npos);
  EXPECT_NE(optimal_errors(make_optimal({{"rho1", "1.5"}})).find("rho1 must be <="), std::string::npos);
  const std::string e = optimal_errors(make_optimal({{"order", "2"}, {"rho1", "0.9"}, {"rho2", "-0.9"}}));
  EXPECT_NE(e.find("OPTIMAL_COMPENSATOR: rho1..rho2"), std::string::npos) << e;
  EXPECT_NE(e.find("not an autocorrelation"), std::string::npos) << e;
  EXPECT_TRUE(make_optimal({{"order", "2"}, {"rho1", "0.9"}, {"rho2", "0.81"}}).ok());
  EXPECT_TRUE(make_optimal().ok()) << optimal_errors(make_optimal());  // defaults: white signal
}

TEST(OptimalCompensatorBlock, PassesSamplesAndFeedsItsEstimatesBack) {
  auto h = make_optimal({{"order", "2"}, {"dropout_rate", "0"}, {"rho1", "0.5"}, {"rho2", "0.25"}});  // AR(1), a = [0.5, 0]
  ASSERT_TRUE(h.ok()) << optimal_errors(h);
  h.set<double>("in", 8.0);
  h.set<bool>("valid", true);
  h.scan();
  EXPECT_EQ(h.get<double>("out"), 8.0);
  EXPECT_FALSE(h.get<bool>("estimated"));
  h.set<bool>("valid", false);
  h.scan();
  EXPECT_NEAR(h.get<double>("out"), 4.0, 1e-12);
  EXPECT_TRUE(h.get<bool>("estimated"));
  h.scan();
  EXPECT_NEAR(h.get<double>("out"), 2.0, 1e-12);  // the estimate became history (paper 003 Fig. 3)
  EXPECT_EQ(h.get<std::uint32_t>("consecutive"), 2u);
  h.scan();
  EXPECT_NEAR(h.get<double>("out"), 1.0, 1e-12);
  EXPECT_EQ(h.get<std::uint32_t>("consecutive"), 3u);
  h.set<double>("in", -3.0);
  h.set<bool>("valid", true);
  h.scan();
  EXPECT_EQ(h.get<double>("out"), -3.0);
  EXPECT_EQ(h.get<std::uint32_t>("consecutive"), 0u);
}

// design 1: the taps as given (from `syncplc design-compensator`), the same
// recursion over the compensated stream.
TEST(OptimalCompensatorBlock, GivenTapsAreUsedAsWritten) {
  auto h = make_optimal({{"design", "1"}, {"order", "2"}, {"a1", "-0.5"}, {"a2", "0.25"}});
  ASSERT_TRUE(h.ok()) << optimal_errors(h);
  h.set<double>("in", 8.0);
  h.set<bool>("valid", true);
  h.scan();
  h.set<double>("in", 4.0);
  h.scan();
  h.set<bool>("valid", false);
  h.scan();
  EXPECT_NEAR(h.get<double>("out"), -0.5 * 4.0 + 0.25 * 8.0, 1e-15);
  h.scan();
  EXPECT_NEAR(h.get<double>("out"), -0.5 * 0.0 + 0.25 * 4.0, 1e-15);
  EXPECT_TRUE(h.get<bool>("estimated"));
  // A tap beyond the order is refused, not silently dropped; out of range too.
  const std::string e = optimal_errors(make_optimal({{"design", "1"}, {"order", "2"}, {"a3", "0.1"}}));
  EXPECT_NE(e.find("a3 is set but order is 2"), std::string::npos) << e;
  EXPECT_NE(optimal_errors(make_optimal({{"design", "1"}, {"a1", "200"}})).find("a1 must be <="), std::string::npos);
  EXPECT_NE(optimal_errors(make_optimal({{"design", "2"}})).find("design"), std::string::npos);
}

// On a signal of the spectrum it was designed for (AR(2) x = 1.6 x1 - 0.8 x2
// + w) at 20 % Bernoulli loss, the optimal compensator's error on the lost
// samples is well below hold's (theory at eps = 0: innovation variance 0.076
// of the signal's power against 2 (1 - rho1) = 0.22 for a single loss).
TEST(OptimalCompensatorBlock, LossErrorBelowHoldOnItsDesignSpectrum) {
  const auto r = optimal_test_ar2(1.6, -0.8, 4);
  auto h = make_optimal({{"order", "4"}, {"dropout_rate", "0.2"}, {"rho1", std::to_string(r[1])}, {"rho2", std::to_string(r[2])},
                 {"rho3", std::to_string(r[3])}, {"rho4", std::to_string(r[4])}});
  ASSERT_TRUE(h.ok()) << optimal_errors(h);
  MessageEstimator hold(0, EstimatorHistory::Recursive, 1'000'000);
  std::mt19937_64 gen(20261130);
  std::normal_distribution<double> w(0.0, 1.0);
  std::bernoulli_distribution lost(0.2);
  double x1 = 0, x2 = 0, e_opt = 0, e_hold = 0, power = 0;
  int n_lost = 0;
  for (int k = 0; k < 200000; ++k) {
    const double x = 1.6 * x1 - 0.8 * x2 + w(gen);
    x2 = x1;
    x1 = x;
    const bool valid = !lost(gen);
    h.set<double>("in", x);
    h.set<bool>("valid", valid);
    h.scan();
    const double yh = hold.update(valid, x);
    if (k < 1000) continue;  // the AR process' start-up
    power += x * x;
    if (!valid) {
      ++n_lost;
      e_opt += (h.get<double>("out") - x) * (h.get<double>("out") - x);
      e_hold += (yh - x) * (yh - x);
    }
  }
  ASSERT_GT(n_lost, 30000);
  e_opt /= n_lost;
  e_hold /= n_lost;
  power /= 199000;
  EXPECT_LT(e_opt, 0.6 * e_hold) << e_opt << " vs " << e_hold;
  EXPECT_LT(e_opt / power, 0.15) << e_opt / power;
}

TEST(OptimalCompensatorBlock, ScanDoesNotAllocate) {
  auto h = make_optimal({{"order", "4"}, {"dropout_rate", "0.3"}, {"rho1", "0.658608"}, {"rho2", "0.393834"},
                 {"rho3", "0.018494"}, {"rho4", "-0.218310"}});
  ASSERT_TRUE(h.ok()) << optimal_errors(h);
  h.scan();
  test_optimal_compensator_alloc::allocations = 0;
  test_optimal_compensator_alloc::counting = true;
  for (int k = 0; k < 1000; ++k) {
    h.set<double>("in", std::sin(0.01 * k));
    h.set<bool>("valid", k % 3 != 0);
    h.scan();
  }
  test_optimal_compensator_alloc::counting = false;
  EXPECT_EQ(test_optimal_compensator_alloc::allocations.load(), 0);
  // The counter does count: an allocation while counting is seen.
  test_optimal_compensator_alloc::counting = true;
  auto* p = new std::vector<double>(8);
  test_optimal_compensator_alloc::counting = false;
  delete p;
  EXPECT_GE(test_optimal_compensator_alloc::allocations.load(), 1);
}

}  // namespace
}  // namespace syncplc::motion
