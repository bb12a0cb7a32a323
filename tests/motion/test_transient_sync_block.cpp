// TRANSIENT_SYNC as a block: declaration (array pins, parameters, documented
// equations), parameter checks, equivalence with NONLINEAR_FILTER where no
// synchronization happens (one axis; rule = off), invalid inputs, reset and
// start, and a reference velocity derived from r.
#include <cmath>
#include <limits>
#include <random>

#include "tests/motion/transient_sync_test_util.hpp"

namespace syncplc::motion::synctest {
namespace {

constexpr std::int64_t kPeriod10ms = 10'000'000;

BlockHarness::Options params(std::map<std::string, std::string> p, std::int64_t period = kPeriod10ms) {
  BlockHarness::Options o;
  o.params = std::move(p);
  o.period_ns = period;
  return o;
}

TEST(TransientSyncBlock, DeclaresArrayPinsAndDocumentsTheEquations) {
  const BlockTypeInfo* t = builtin_blocks().find("TRANSIENT_SYNC");
  ASSERT_NE(t, nullptr);
  EXPECT_EQ(t->category, "Motion");
  for (const char* eq : {"(33)", "(34)", "(24)", "t_M", "look-ahead", "a_min a_max tf"})
    EXPECT_NE(t->doc.find(eq), std::string::npos) << eq;
  EXPECT_NE(t->reference.find("Section III"), std::string::npos);
  EXPECT_NE(t->reference.find("(23)-(34)"), std::string::npos);
  for (const auto& p : t->pins) {
    EXPECT_FALSE(p.doc.empty()) << p.name;
    const bool scalar = p.name == "reset" || p.name == "arrival" || p.name == "synchronized" || p.name == "scaled" ||
                        p.name == "energy" || p.name == "energy_last" || p.name == "windows" ||
                        p.name == "window_scans" || p.name == "spread" || p.name == "ENO";
    EXPECT_EQ(p.is_array(), !scalar) << p.name;
    if (p.is_array()) {
      EXPECT_EQ(p.length_param, "n") << p.name;
    }
  }
  ASSERT_GE(t->param_index("n"), 0);
  EXPECT_TRUE(t->params[static_cast<std::size_t>(t->param_index("n"))].default_value.empty());  // required

  BlockHarness h(builtin_blocks(), "TRANSIENT_SYNC", params({{"n", "7"}}));
  ASSERT_TRUE(h.ok());
  EXPECT_EQ(h.length("r"), 7u);
  EXPECT_EQ(h.length("v_max_applied"), 7u);
  EXPECT_EQ(h.length("steps_to_go"), 7u);
  EXPECT_EQ(h.length("arrival"), 1u);
  EXPECT_EQ(h.length("energy"), 1u);
}

TEST(TransientSyncBlock, RejectsBadParameters) {
  for (auto p : std::vector<std::map<std::string, std::string>>{
           {{"n", "0"}}, {{"n", "1025"}}, {{"n", "3"}, {"rule", "3"}}, {{"n", "3"}, {"rule", "-1"}}}) {
    BlockHarness h(builtin_blocks(), "TRANSIENT_SYNC", params(p));
    EXPECT_FALSE(h.ok()) << p.begin()->second;
  }
  BlockHarness big(builtin_blocks(), "TRANSIENT_SYNC", params({{"n", "1024"}, {"rule", "2"}}));
  EXPECT_TRUE(big.ok());
}

// Random steps, ramps and bounds fed to TRANSIENT_SYNC and to n
// NONLINEAR_FILTER instances; every output must be identical.
void compare_with_filters(int n, int rule, std::uint64_t seed) {
  BlockHarness sync(builtin_blocks(), "TRANSIENT_SYNC", params({{"n", std::to_string(n)}, {"rule", std::to_string(rule)}}));
  ASSERT_TRUE(sync.ok());
  std::vector<std::unique_ptr<BlockHarness>> f;
  for (int i = 0; i < n; ++i) {
    f.push_back(std::make_unique<BlockHarness>(builtin_blocks(), "NONLINEAR_FILTER", params({})));
    ASSERT_TRUE(f.back()->ok());
  }
  std::mt19937_64 rng(seed);
  auto uni = [&](double a, double b) { return std::uniform_real_distribution<double>(a, b)(rng); };
  std::vector<double> r(static_cast<std::size_t>(n), 0), s(static_cast<std::size_t>(n), 0);
  std::vector<AxisBounds> b = table2_cycled(n);
  int moved = 0, skips = 0;
  for (int k = 0; k < 3000; ++k) {
    for (int i = 0; i < n; ++i) {
      const auto q = static_cast<std::size_t>(i);
      if (uni(0, 1) < 0.02) {  // a new segment, sometimes new bounds
        r[q] += uni(-2, 2);
        s[q] = uni(0, 1) < 0.4 ? 0 : uni(0.5 * b[q].v_min, 0.5 * b[q].v_max);
        if (uni(0, 1) < 0.3) {
          const double fv = uni(0.5, 1.5), fa = uni(0.5, 1.5);
          const AxisBounds& t2 = table2()[q % 3];
          b[q] = {t2.a_min * fa, t2.a_max * fa, t2.v_min * fv, t2.v_max * fv};
          s[q] = std::fmin(std::fmax(s[q], 0.5 * b[q].v_min), 0.5 * b[q].v_max);
        }
      }
      const std::uint32_t u = static_cast<std::uint32_t>(i);
      for (BlockHarness* h : {&sync, f[q].get()}) {
        const bool arr = h == &sync;
        auto set = [&](const char* pin, double v) {
          if (arr) h->set<double>(pin, u, v);
          else h->set<double>(pin, v);
        };
        set("r", r[q]);
        set("r_dot", s[q]);
        set("v_min", b[q].v_min);
        set("v_max", b[q].v_max);
        set("a_min", b[q].a_min);
        set("a_max", b[q].a_max);
      }
    }
    if (uni(0, 1) < 0.01) {  // skipped releases: 1 to 3 missed periods, caught up by the next scan
      const std::int64_t skip = kPeriod10ms * static_cast<std::int64_t>(uni(1, 4));
      sync.set_now_ns(sync.now_ns() + skip);
      for (auto& g : f) g->set_now_ns(g->now_ns() + skip);
      ++skips;
      for (int i = 0; i < n; ++i) r[static_cast<std::size_t>(i)] += 1e-9 * static_cast<double>(skip) * s[static_cast<std::size_t>(i)];
    }
    sync.scan();
    for (int i = 0; i < n; ++i) {
      const auto q = static_cast<std::size_t>(i);
      const std::uint32_t u = static_cast<std::uint32_t>(i);
      BlockHarness& g = *f[q];
      g.scan();
      ASSERT_EQ(sync.get<double>("x", u), g.get<double>("x")) << "scan " << k << " axis " << i;
      ASSERT_EQ(sync.get<double>("x_dot", u), g.get<double>("x_dot")) << "scan " << k << " axis " << i;
      ASSERT_EQ(sync.get<double>("x_ddot", u), g.get<double>("x_ddot")) << "scan " << k << " axis " << i;
      ASSERT_EQ(sync.get<bool>("tracking", u), g.get<bool>("tracking")) << "scan " << k << " axis " << i;
      ASSERT_EQ(sync.get<std::int64_t>("steps_to_go", u), g.get<std::int64_t>("steps_to_go")) << k << " " << i;
      ASSERT_EQ(sync.get<bool>("error", u), g.get<bool>("error"));
      ASSERT_EQ(sync.get<double>("v_max_applied", u), b[q].v_max);
      ASSERT_EQ(sync.get<double>("v_min_applied", u), b[q].v_min);
      if (!g.get<bool>("tracking")) ++moved;
      r[q] += 0.01 * s[q];
    }
    if (rule == kOff) {
      ASSERT_EQ(sync.get<std::int64_t>("scaled"), 0);
    }
  }
  EXPECT_GT(moved, 1000);
  EXPECT_GT(skips, 10);
}

TEST(TransientSyncBlock, SingleAxisIsTheNonlinearFilter) {
  for (int rule : {kUnified, kPaper, kOff}) {
    SCOPED_TRACE(rule);
    compare_with_filters(1, rule, 201);
  }
}

TEST(TransientSyncBlock, RuleOffIsIndependentFilters) { compare_with_filters(5, kOff, 202); }

TEST(TransientSyncBlock, InvalidBoundsOnOneAxis) {
  Instance in(3, kUnified, kPeriod10ms);
  ASSERT_TRUE(in.ok()) << in.errors();
  in.set_bounds(table2_cycled(3));
  for (int i = 0; i < 3; ++i) in.set_ref(i, 0, 0);
  in.scan();
  for (int i = 0; i < 3; ++i) in.set_ref(i, 1.0 + i, 0);
  for (int k = 0; k < 5; ++k) in.scan();
  ASSERT_GT(std::fabs(in.x_dot(1)), 0.5);
  EXPECT_TRUE(in.harness().events().empty());
  // Axis 1 gets a positive a_min: invalid.
  in.harness().set<double>("a_min", 1, 1.0);
  std::int64_t arrival = -1;
  for (int k = 0; k < 300; ++k) {
    in.scan();
    EXPECT_TRUE(in.error(1));
    EXPECT_FALSE(in.error(0));
    EXPECT_EQ(in.steps_to_go(1), -1);
    EXPECT_FALSE(in.tracking(1));
    EXPECT_FALSE(in.scalar<bool>("synchronized"));
    // Controlled stop with the last valid acceleration bounds.
    EXPECT_GE(in.x_ddot(1), table2()[1].a_min);
    EXPECT_LE(in.x_ddot(1), table2()[1].a_max);
    if (arrival < 0 && in.tracking(0) && in.tracking(2)) arrival = k;
  }
  EXPECT_NEAR(in.x_dot(1), 0, 1e-12);
  EXPECT_GT(arrival, 0);  // the valid axes still arrive
  ASSERT_EQ(in.harness().events().size(), 1u);  // one event for the series
  EXPECT_EQ(in.harness().events()[0].kind, EventKind::BlockFault);
  // Valid again: the axis recovers and the block synchronizes.
  in.harness().set<double>("a_min", 1, table2()[1].a_min);
  bool synced = false;
  for (int k = 0; k < 300 && !synced; ++k) {
    in.scan();
    EXPECT_FALSE(in.error(1));
    synced = in.scalar<bool>("synchronized");
  }
  EXPECT_TRUE(synced);
  EXPECT_NEAR(in.x(1), 2.0, 1e-9);
  // A non-finite reference is the finite-input rule's (finite_guard.hpp): the
  // block does not execute, every output holds, ENO is FALSE.
  const double x1 = in.x(1);
  in.harness().set<double>("r", 0, std::numeric_limits<double>::quiet_NaN());
  in.scan();
  in.scan();
  EXPECT_FALSE(in.error(0));
  EXPECT_EQ(in.x(1), x1);
  EXPECT_FALSE(in.harness().get<bool>("ENO"));
  EXPECT_EQ(in.harness().events().size(), 3u);
  EXPECT_STREQ(in.harness().events()[2].message, "input not finite");
}

TEST(TransientSyncBlock, ResetAndStart) {
  BlockHarness::Options o = params({{"n", "2"}, {"start_at_r", "FALSE"}});
  BlockHarness h(builtin_blocks(), "TRANSIENT_SYNC", o);
  ASSERT_TRUE(h.ok());
  for (std::uint32_t i = 0; i < 2; ++i) {
    h.set<double>("v_min", i, -5);
    h.set<double>("v_max", i, 5);
    h.set<double>("a_min", i, -20);
    h.set<double>("a_max", i, 20);
    h.set<double>("r", i, 1.0);
  }
  h.set<double>("x0", 0, 0.5);
  h.set<double>("v0", 0, 0.25);
  h.set<double>("x0", 1, -1.0);
  h.scan();  // starts at (x0, v0)
  EXPECT_EQ(h.get<double>("x", 0u), 0.5);
  EXPECT_EQ(h.get<double>("x_dot", 0u), 0.25);
  EXPECT_EQ(h.get<double>("x", 1u), -1.0);
  EXPECT_FALSE(h.get<bool>("synchronized"));
  for (int k = 0; k < 200; ++k) h.scan();
  EXPECT_TRUE(h.get<bool>("synchronized"));
  EXPECT_EQ(h.get<std::int64_t>("windows"), 1);
  EXPECT_EQ(h.get<std::int64_t>("spread"), 0);
  h.set<bool>("reset", true);
  for (int k = 0; k < 3; ++k) {
    h.scan();
    EXPECT_EQ(h.get<double>("x", 0u), 0.5);
    EXPECT_EQ(h.get<double>("x_dot", 0u), 0.25);
    EXPECT_EQ(h.get<double>("x_ddot", 0u), 0);
    EXPECT_EQ(h.get<double>("x", 1u), -1.0);
  }
  h.set<bool>("reset", false);
  for (int k = 0; k < 200; ++k) h.scan();
  EXPECT_TRUE(h.get<bool>("synchronized"));
  EXPECT_NEAR(h.get<double>("x", 1u), 1.0, 1e-9);
  EXPECT_EQ(h.get<std::int64_t>("spread"), 0);

  // start_at_r (default): tracking from the first scan, no window.
  BlockHarness g(builtin_blocks(), "TRANSIENT_SYNC", params({{"n", "1"}}));
  ASSERT_TRUE(g.ok());
  g.set<double>("v_min", 0u, -1);
  g.set<double>("v_max", 0u, 1);
  g.set<double>("a_min", 0u, -1);
  g.set<double>("a_max", 0u, 1);
  g.set<double>("r", 0u, 3);
  g.set<double>("r_dot", 0u, 0.5);
  g.scan();
  EXPECT_EQ(g.get<double>("x", 0u), 3);
  EXPECT_EQ(g.get<double>("x_dot", 0u), 0.5);
  EXPECT_TRUE(g.get<bool>("synchronized"));
  EXPECT_EQ(g.get<std::int64_t>("windows"), 0);
}

// r_dot not connected: the block differentiates r. A step then looks like a
// one-scan ramp far beyond the bounds (that axis "cannot track" for that
// scan), after which the ramps are seen exactly; the unified rule still
// brings all axes in together and E still drops.
TEST(TransientSyncBlock, DerivedReferenceVelocity) {
  const int n = 3;
  const double T = 0.01;
  Instance sync(n, kUnified, kPeriod10ms, false), off(n, kOff, kPeriod10ms, false);
  ASSERT_TRUE(sync.ok()) << sync.errors();
  ASSERT_TRUE(off.ok()) << off.errors();
  const auto b = table2_cycled(n);
  sync.set_bounds(b);
  off.set_bounds(b);
  std::mt19937_64 rng(203);
  auto uni = [&](double a, double c) { return std::uniform_real_distribution<double>(a, c)(rng); };
  std::vector<double> r(n, 0), s(n, 0);
  WindowMeter ms(n), mo(n);
  std::int64_t scan = 0;
  auto step = [&] {
    for (int i = 0; i < n; ++i) {
      sync.set_ref(i, r[static_cast<std::size_t>(i)], 0);
      off.set_ref(i, r[static_cast<std::size_t>(i)], 0);
    }
    sync.scan();
    off.scan();
    ms.observe(sync, scan, T);
    mo.observe(off, scan, T);
    ++scan;
    for (int i = 0; i < n; ++i) r[static_cast<std::size_t>(i)] += T * s[static_cast<std::size_t>(i)];
  };
  step();
  step();
  for (int e = 0; e < 60; ++e) {
    for (int i = 0; i < n; ++i) {
      r[static_cast<std::size_t>(i)] += uni(-3, 3);
      s[static_cast<std::size_t>(i)] = uni(0, 1) < 0.5 ? 0 : uni(0.3 * b[static_cast<std::size_t>(i)].v_min,
                                                                0.3 * b[static_cast<std::size_t>(i)].v_max);
    }
    step();
    for (int k = 0; k < 3000 && (ms.open() || mo.open()); ++k) step();
    ASSERT_FALSE(ms.open() || mo.open()) << "event " << e;
  }
  ASSERT_EQ(ms.windows.size(), mo.windows.size());
  double es = 0, eo = 0;
  for (std::size_t k = 0; k < ms.windows.size(); ++k) {
    EXPECT_EQ(ms.windows[k].spread, 0) << "window " << k;
    EXPECT_EQ(ms.windows[k].length, mo.windows[k].length) << "window " << k;
    es += ms.windows[k].energy;
    eo += mo.windows[k].energy;
  }
  EXPECT_LT(es, 0.97 * eo);
}

}  // namespace
}  // namespace syncplc::motion::synctest
