// NONLINEAR_FILTER as a block: declaration, outputs per scan against the math
// module, r_dot derivation, bound changes mid-transient, invalid bounds,
// reset/start, and the scan interval.
#include <cmath>
#include <limits>
#include <set>
#include <string>

#include "fblocks/library.hpp"
#include "runtime/core/block_harness.hpp"
#include "runtime/core/units.hpp"
#include "tests/motion/nonlinear_filter_test_util.hpp"

namespace syncplc::motion::test {
namespace {

constexpr std::int64_t kMs = 1'000'000;

BlockHarness::Options options(std::optional<std::set<std::string>> connected = std::nullopt,
                              std::int64_t period_ns = kMs, std::map<std::string, std::string> params = {}) {
  BlockHarness::Options o;
  o.connected = std::move(connected);
  o.period_ns = period_ns;
  o.params = std::move(params);
  return o;
}

// Every input but r_dot counts as connected.
std::set<std::string> without_r_dot() { return {"r", "v_min", "v_max", "a_min", "a_max", "reset", "x0", "v0"}; }

struct Filter {
  BlockHarness h;
  explicit Filter(BlockHarness::Options o = options()) : h(builtin_blocks(), "NONLINEAR_FILTER", std::move(o)) {}
  void bounds(const FilterBounds& b) {
    h.set<double>("v_min", b.v_min);
    h.set<double>("v_max", b.v_max);
    h.set<double>("a_min", b.a_min);
    h.set<double>("a_max", b.a_max);
  }
  void ref(double r, double r_dot = 0) {
    h.set<double>("r", r);
    h.set<double>("r_dot", r_dot);
  }
  double x() { return h.get<double>("x"); }
  double v() { return h.get<double>("x_dot"); }
  double a() { return h.get<double>("x_ddot"); }
  bool tracking() { return h.get<bool>("tracking"); }
  std::int64_t steps() { return h.get<std::int64_t>("steps_to_go"); }
  bool error() { return h.get<bool>("error"); }
  long faults() const {
    long n = 0;
    for (const auto& e : h.events()) n += e.kind == EventKind::BlockFault;
    return n;
  }
};

const FilterBounds kBounds{-0.8, 1.2, -3.0, 5.0};

TEST(NonlinearFilterBlock, Declaration) {
  const BlockTypeInfo* t = builtin_blocks().find("NONLINEAR_FILTER");
  ASSERT_NE(t, nullptr);
  EXPECT_EQ(t->category, "Motion");
  EXPECT_NE(t->doc.find("Table I"), std::string::npos);
  EXPECT_NE(t->reference.find("paper 004"), std::string::npos);
  EXPECT_NE(t->reference.find("eqs. (1)-(22)"), std::string::npos);
  EXPECT_FALSE(t->unit_delay);
  const std::map<std::string, std::string> units{{"r", "m"},        {"r_dot", "m/s"}, {"v_min", "m/s"},
                                                 {"v_max", "m/s"},  {"a_min", "m/s^2"}, {"a_max", "m/s^2"},
                                                 {"x0", "m"},       {"v0", "m/s"},    {"x", "m"},
                                                 {"x_dot", "m/s"},  {"x_ddot", "m/s^2"}, {"reset", ""},
                                                 {"tracking", ""},  {"steps_to_go", ""}, {"error", ""},
                                                 {"ENO", ""}};
  EXPECT_EQ(t->pins.size(), units.size());
  for (const auto& p : t->pins) {
    SCOPED_TRACE(p.name);
    ASSERT_TRUE(units.count(p.name));
    EXPECT_EQ(p.unit, units.at(p.name));
    std::string err;
    EXPECT_TRUE(parse_unit(p.unit, &err).has_value()) << err;
    EXPECT_FALSE(p.doc.empty());
    EXPECT_EQ(p.doc.find('|'), std::string::npos);  // rendered into a Markdown table
    const bool required = p.name == "r" || p.name == "v_min" || p.name == "v_max" || p.name == "a_min" ||
                          p.name == "a_max";
    EXPECT_EQ(p.required, required);
  }
  EXPECT_EQ(t->pins[static_cast<std::size_t>(t->pin_index("steps_to_go"))].type, IecType::LINT);
  EXPECT_EQ(t->pins[static_cast<std::size_t>(t->pin_index("tracking"))].type, IecType::BOOL);
  ASSERT_EQ(t->params.size(), 1u);
  EXPECT_EQ(t->params[0].name, "start_at_r");
  EXPECT_EQ(t->params[0].default_value, "TRUE");
}

TEST(NonlinearFilterBlock, StartsAtTheReference) {
  Filter f;
  ASSERT_TRUE(f.h.ok());
  f.bounds(kBounds);
  f.ref(1.5, 0.25);
  f.h.scan();
  EXPECT_EQ(f.x(), 1.5);
  EXPECT_EQ(f.v(), 0.25);
  EXPECT_TRUE(f.tracking());
  EXPECT_EQ(f.steps(), 0);
  EXPECT_FALSE(f.error());
  for (int k = 1; k <= 20; ++k) {
    f.ref(1.5 + 0.25 * k * 1e-3, 0.25);
    f.h.scan();
    EXPECT_TRUE(f.tracking()) << k;
    EXPECT_NEAR(f.x(), 1.5 + 0.25 * k * 1e-3, 1e-12);
    EXPECT_NEAR(f.a(), 0, 1e-6);
  }
}

// A step with r_dot connected: the outputs are the math module's state at
// each sample, steps_to_go counts down by one per scan to the scan tracking
// becomes TRUE, and the bounds hold.
TEST(NonlinearFilterBlock, StepCountsDownToTracking) {
  Filter f;
  f.bounds(kBounds);
  f.ref(0);
  f.h.scan();
  const double T = 1e-3;
  FilterState s{0, 0};
  s = filter_step(s, {0, 0}, kBounds, T).next;
  f.ref(0.9);  // step
  std::int64_t expected = -1;
  int k = 0;
  for (; k < 5000; ++k) {
    f.h.scan();
    ASSERT_EQ(f.x(), s.x) << k;
    ASSERT_EQ(f.v(), s.v) << k;
    const FilterStep st = filter_step(s, {0.9, 0}, kBounds, T);
    ASSERT_EQ(f.a(), st.u) << k;
    ASSERT_LE(f.v(), kBounds.v_max);
    ASSERT_GE(f.a(), kBounds.a_min - 1e-6);
    ASSERT_LE(f.a(), kBounds.a_max + 1e-6);
    if (k == 0) {
      expected = f.steps();
      ASSERT_GT(expected, 100);
    } else {
      ASSERT_EQ(f.steps(), expected) << k;
    }
    ASSERT_EQ(f.tracking(), f.steps() == 0) << k;
    if (f.tracking()) break;
    --expected;
    s = st.next;
  }
  EXPECT_TRUE(f.tracking());
  EXPECT_NEAR(f.x(), 0.9, 1e-9);
  f.h.scan();
  EXPECT_TRUE(f.tracking());
  EXPECT_EQ(f.steps(), 0);
}

// r_dot unconnected: derived as (r_k - r_(k-1))/T, 0 on the first scan. A
// ramp then looks like a velocity step at the first scan, and the block's
// outputs equal the math module fed with those differences.
TEST(NonlinearFilterBlock, DerivesRDotWhenNotConnected) {
  Filter f(options(without_r_dot()));
  ASSERT_TRUE(f.h.ok());
  f.bounds(kBounds);
  const double T = 1e-3, slope = 0.7;
  FilterState s{};
  double r_prev = 0;
  std::int64_t arrival = -1, predicted = -1;
  for (int k = 0; k < 3000; ++k) {
    const double r = 0.2 + slope * k * T;
    f.h.set<double>("r", r);
    f.h.set<double>("r_dot", 123.0);  // not connected: ignored
    f.h.scan();
    const double r_dot = k == 0 ? 0 : (r - r_prev) / T;
    if (k == 0) s = {r, 0};
    ASSERT_EQ(f.x(), s.x) << k;
    ASSERT_EQ(f.v(), s.v) << k;
    const FilterStep st = filter_step(s, {r, r_dot}, kBounds, T);
    ASSERT_EQ(f.a(), st.u) << k;
    if (k == 1) predicted = f.steps();  // the ramp is known from the second scan on
    if (k >= 1 && arrival < 0) {
      ASSERT_EQ(f.steps(), predicted - (k - 1)) << k;
    }
    if (k >= 1 && f.tracking() && arrival < 0) arrival = k;
    s = st.next;
    r_prev = r;
  }
  ASSERT_GT(arrival, 1);
  EXPECT_EQ(arrival, 1 + predicted);
  EXPECT_NEAR(f.v(), slope, 1e-9);
  // Connected, the same ramp with its true r_dot is tracked from the start.
  Filter g;
  g.bounds(kBounds);
  for (int k = 0; k < 10; ++k) {
    g.ref(0.2 + slope * k * T, slope);
    g.h.scan();
    EXPECT_TRUE(g.tracking()) << k;
  }
}

// The documented price of a derived r_dot: a step of r looks like a one-scan
// ramp, and a step much smaller than a_max T^2 then overshoots. With r_dot
// given as 0 (a constant counts as connected) the same step does not.
TEST(NonlinearFilterBlock, DerivedRDotMakesAStepARampForOneScan) {
  auto run = [](bool derive) {
    Filter f(derive ? options(without_r_dot()) : options());
    f.bounds(kBounds);
    f.ref(0.0, 0.0);
    f.h.scan();
    f.ref(1e-7, 0.0);  // 0.1 um, a_max T^2 = 5 um
    double overshoot = 0;
    for (int k = 0; k < 20; ++k) {
      f.h.scan();
      overshoot = std::fmax(overshoot, f.x() - 1e-7);
    }
    EXPECT_TRUE(f.tracking());
    return overshoot;
  };
  EXPECT_GT(run(true), 0.5e-7);  // most of the step again, past r
  EXPECT_LE(run(false), 1e-18);
}

// Reducing v_max below the current velocity mid-transient: full braking at
// a_min, never beyond it, then the new bound; steps_to_go re-predicts at the
// change and counts down exactly from there.
TEST(NonlinearFilterBlock, BoundReductionMidTransient) {
  Filter f;
  f.bounds(kBounds);
  f.ref(0);
  f.h.scan();
  f.ref(3.0);
  for (int k = 0; k < 1500; ++k) f.h.scan();  // cruising at v_max by now
  ASSERT_NEAR(f.v(), kBounds.v_max, 1e-12);
  FilterBounds reduced = kBounds;
  reduced.v_max = 0.4;
  f.bounds(reduced);
  f.h.scan();
  const std::int64_t predicted = f.steps();
  ASSERT_GT(predicted, 0);
  EXPECT_EQ(f.a(), reduced.a_min);
  std::int64_t k = 0;
  double v_prev = f.v();
  while (!f.tracking() && k < 100000) {
    f.h.scan();
    ++k;
    ASSERT_EQ(f.steps(), predicted - k) << k;
    ASSERT_GE(f.a(), reduced.a_min - 1e-6);
    ASSERT_LE(f.a(), reduced.a_max + 1e-6);
    if (v_prev > reduced.v_max + 1e-12) {
      // braking: by the full bound, or onto the new bound
      ASSERT_LE(f.v(), std::fmax(reduced.v_max, v_prev + 1e-3 * reduced.a_min) + 1e-12) << k;
    } else {
      ASSERT_LE(f.v(), reduced.v_max + 1e-12) << k;
    }
    v_prev = f.v();
  }
  EXPECT_EQ(k, predicted);
  EXPECT_NEAR(f.x(), 3.0, 1e-9);
}

// Invalid bounds: one fault per series of invalid scans, error TRUE, no
// prediction, and a controlled stop with the last valid acceleration bounds.
TEST(NonlinearFilterBlock, InvalidBoundsFaultOnceAndStop) {
  Filter f;
  f.bounds(kBounds);
  f.ref(0);
  f.h.scan();
  f.ref(5.0);
  for (int k = 0; k < 1000; ++k) f.h.scan();
  ASSERT_NEAR(f.v(), kBounds.v_max, 1e-12);
  FilterBounds bad = kBounds;
  bad.a_max = 0;
  f.bounds(bad);
  double v_prev = f.v(), x_prev = f.x();
  for (int k = 0; k < 1000; ++k) {
    f.h.scan();
    ASSERT_TRUE(f.error());
    ASSERT_FALSE(f.tracking());
    ASSERT_EQ(f.steps(), kNever);
    if (k > 0) {
      ASSERT_NEAR(f.v(), std::fmax(0.0, v_prev + 1e-3 * kBounds.a_min), 1e-12) << k;  // braking at the last a_min
    }
    ASSERT_GE(f.a(), kBounds.a_min);
    ASSERT_LE(f.a(), 0);
    v_prev = f.v();
    x_prev = f.x();
  }
  EXPECT_EQ(f.v(), 0);
  EXPECT_EQ(f.a(), 0);
  f.h.scan();
  EXPECT_EQ(f.x(), x_prev);  // holds position
  EXPECT_EQ(f.faults(), 1);
  // Valid again: resumes and reaches r.
  f.bounds(kBounds);
  f.h.scan();
  EXPECT_FALSE(f.error());
  const std::int64_t predicted = f.steps();
  ASSERT_GT(predicted, 0);
  f.h.scans(static_cast<int>(predicted));
  EXPECT_TRUE(f.tracking());
  EXPECT_NEAR(f.x(), 5.0, 1e-9);
  // A NaN r is the finite-input rule's (finite_guard.hpp): the filter does
  // not execute, its outputs hold and ENO is FALSE (one event per scan here;
  // a task reports one per series).
  f.h.set<double>("r", std::numeric_limits<double>::quiet_NaN());
  f.h.scans(5);
  EXPECT_FALSE(f.h.get<bool>("ENO"));
  EXPECT_EQ(f.faults(), 6);
  EXPECT_NEAR(f.x(), 5.0, 1e-9);
  // v_min >= v_max is invalid too: the filter's own fault.
  f.ref(5.0);
  f.h.scan();
  EXPECT_FALSE(f.error());
  EXPECT_TRUE(f.h.get<bool>("ENO"));
  f.bounds({1, 1, -3, 5});
  f.h.scan();
  EXPECT_TRUE(f.error());
  EXPECT_EQ(f.faults(), 7);
}

TEST(NonlinearFilterBlock, NeverValidBoundsHoldAtTheStart) {
  Filter f(options(std::nullopt, kMs, {{"start_at_r", "FALSE"}}));
  f.h.set<double>("x0", 2.0);
  f.h.set<double>("v0", 0.0);
  f.ref(7.0);
  f.h.scans(10);  // bounds all zero
  EXPECT_TRUE(f.error());
  EXPECT_EQ(f.x(), 2.0);
  EXPECT_EQ(f.v(), 0.0);
  EXPECT_EQ(f.faults(), 1);
}

// start_at_r FALSE: the first scan starts at (x0, v0); reset holds the filter
// there with x_ddot 0 and a prediction from the held state.
TEST(NonlinearFilterBlock, ResetAndStartState) {
  Filter f(options(std::nullopt, kMs, {{"start_at_r", "FALSE"}}));
  ASSERT_TRUE(f.h.ok());
  f.bounds(kBounds);
  f.h.set<double>("x0", -0.5);
  f.h.set<double>("v0", 0.3);
  f.ref(1.0);
  f.h.scan();
  EXPECT_EQ(f.x(), -0.5);
  EXPECT_EQ(f.v(), 0.3);
  EXPECT_FALSE(f.tracking());
  const std::int64_t from_start = f.steps();
  EXPECT_EQ(from_start, transient_steps(FilterState{-0.5, 0.3}, Reference{1.0, 0}, kBounds, 1e-3));
  f.h.scans(50);
  EXPECT_GT(f.x(), -0.5);
  f.h.set<bool>("reset", true);
  for (int k = 0; k < 5; ++k) {
    f.h.scan();
    EXPECT_EQ(f.x(), -0.5);
    EXPECT_EQ(f.v(), 0.3);
    EXPECT_EQ(f.a(), 0);
    EXPECT_EQ(f.steps(), from_start);
  }
  f.h.set<bool>("reset", false);
  f.h.scans(static_cast<int>(from_start) + 1);
  EXPECT_TRUE(f.tracking());
  EXPECT_NEAR(f.x(), 1.0, 1e-9);
}

// T is the task period; after skipped releases the block catches up the
// missed samples, so x stays on the time grid.
TEST(NonlinearFilterBlock, SamplingTimeAndSkippedReleases) {
  const double T = 2e-3;
  Filter f(options(std::nullopt, 2 * kMs));
  f.bounds(kBounds);
  f.ref(0);
  f.h.scan();
  f.ref(0.4);
  FilterState s = filter_step({0, 0}, {0, 0}, kBounds, T).next;
  for (int k = 0; k < 30; ++k) {
    if (k == 10) f.h.set_now_ns(f.h.now_ns() + 4 * kMs);  // two releases skipped
    if (k == 10) {
      for (int j = 0; j < 2; ++j) s = filter_step(s, {0.4, 0}, kBounds, T).next;
    }
    f.h.scan();
    ASSERT_EQ(f.x(), s.x) << k;
    ASSERT_EQ(f.v(), s.v) << k;
    s = filter_step(s, {0.4, 0}, kBounds, T).next;
  }
  // A ramp reference over a skipped release: the catch-up sample sees r one
  // period earlier, so tracking continues undisturbed.
  Filter g(options(std::nullopt, 2 * kMs));
  g.bounds(kBounds);
  for (int k = 0; k < 20; ++k) {
    if (k == 10) g.h.set_now_ns(g.h.now_ns() + 2 * kMs);
    const double t = static_cast<double>(g.h.now_ns()) * 1e-9;
    g.ref(0.1 + 0.5 * t, 0.5);
    g.h.scan();
    ASSERT_TRUE(g.tracking()) << k;
    ASSERT_NEAR(g.x(), 0.1 + 0.5 * t, 1e-12) << k;
  }
}

}  // namespace
}  // namespace syncplc::motion::test
