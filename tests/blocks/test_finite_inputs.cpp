// The finite-input rule (IEC 61131-3 ENO, runtime/core/finite_guard.hpp) for
// every registered block type: random NaN/inf bursts on the floating inputs.
// During a burst the block does not execute: outputs hold, ENO is FALSE, a
// fault event is raised. After it the block runs as if the burst scans had
// not existed: outputs equal, bit for bit, those of a twin instance fed the
// same finite inputs that skipped the burst scans, and ENO is TRUE.
#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "fblocks/library.hpp"
#include "runtime/core/block_harness.hpp"
#include "runtime/core/finite_guard.hpp"

namespace syncplc {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();

// cells_finite (the branch-free check of an array input) against std::isfinite
// for every special value of LREAL and REAL at every position of arrays of 0
// to 6 elements, and on random bit patterns.
TEST(FiniteGuard, CellsFiniteIsIsfiniteOfEveryElement) {
  const double dspecial[] = {0.0, -0.0, 1.0, -2.5, std::numeric_limits<double>::max(),
                             -std::numeric_limits<double>::max(), std::numeric_limits<double>::min(),
                             std::numeric_limits<double>::denorm_min(), kInf, -kInf, kNaN, -kNaN,
                             std::numeric_limits<double>::signaling_NaN()};
  const float fspecial[] = {0.0f, -0.0f, 1.0f, std::numeric_limits<float>::max(), std::numeric_limits<float>::min(),
                            std::numeric_limits<float>::denorm_min(), std::numeric_limits<float>::infinity(),
                            -std::numeric_limits<float>::infinity(), std::numeric_limits<float>::quiet_NaN(),
                            std::numeric_limits<float>::signaling_NaN()};
  for (std::uint32_t n = 0; n <= 6; ++n)
    for (std::uint32_t at = 0; at < std::max<std::uint32_t>(n, 1); ++at) {
      for (double v : dspecial) {
        std::vector<Cell> c(n);
        for (auto& x : c) x.set<double>(1.5);
        if (n > 0) c[at].set<double>(v);
        EXPECT_EQ(cells_finite(c.data(), n, false), n == 0 || std::isfinite(v)) << n << " " << at << " " << v;
      }
      for (float v : fspecial) {
        std::vector<Cell> c(n);
        for (auto& x : c) x.set<float>(1.5f);
        if (n > 0) c[at].set<float>(v);
        EXPECT_EQ(cells_finite(c.data(), n, true), n == 0 || std::isfinite(v)) << n << " " << at << " " << v;
      }
    }
  std::mt19937_64 g(61131);
  for (int k = 0; k < 100000; ++k) {
    Cell c[3];
    for (auto& x : c) x.raw = g();
    const bool d = std::isfinite(c[0].get<double>()) && std::isfinite(c[1].get<double>()) &&
                   std::isfinite(c[2].get<double>());
    EXPECT_EQ(cells_finite(c, 3, false), d);
    for (auto& x : c) x.set<float>(std::bit_cast<float>(static_cast<std::uint32_t>(g())));
    const bool f = std::isfinite(c[0].get<float>()) && std::isfinite(c[1].get<float>()) &&
                   std::isfinite(c[2].get<float>());
    EXPECT_EQ(cells_finite(c, 3, true), f);
  }
}

// Mandatory parameters get 1 (within their range): a value every block accepts.
BlockHarness::Options options_for(const BlockTypeInfo& t, std::optional<IecType> dt) {
  BlockHarness::Options o;
  o.datatype = dt;
  for (const auto& p : t.params)
    if (p.default_value.empty()) o.params[p.name] = "1";
  return o;
}

IecType pin_type(const PinDecl& p, IecType dt) { return p.cls == TypeClass::Exact ? p.type : dt; }

// The instance data types to try: REAL and LREAL where the type is generic
// over them, else its default.
std::vector<std::optional<IecType>> datatypes(const BlockTypeInfo& t) {
  if (!t.is_generic()) return {std::nullopt};
  std::vector<std::optional<IecType>> v;
  for (IecType r : {IecType::REAL, IecType::LREAL}) {
    bool all = true;
    for (const auto& p : t.pins)
      if (p.cls != TypeClass::Exact && !in_class(r, p.cls)) all = false;
    if (all) v.push_back(r);
  }
  if (v.empty()) v.push_back(std::nullopt);
  return v;
}

void set_real(BlockHarness& h, const std::string& pin, std::uint32_t k, IecType t, double v) {
  if (t == IecType::REAL) h.set<float>(pin, k, static_cast<float>(v));
  else h.set<double>(pin, k, v);
}

std::vector<std::uint64_t> outputs(BlockHarness& h, const BlockTypeInfo& t) {
  std::vector<std::uint64_t> v;
  for (const auto& p : t.pins)
    if (p.dir == PinDir::Out && p.name != kEnoPin)
      for (std::uint32_t k = 0; k < h.length(p.name); ++k) v.push_back(h.cell(p.name, k).raw);
  return v;
}

struct Case {
  const BlockTypeInfo* type;
  std::optional<IecType> dt;
};

void run_bursts(const Case& c, std::uint32_t seed) {
  const BlockTypeInfo& t = *c.type;
  const auto o = options_for(t, c.dt);
  BlockHarness h(builtin_blocks(), t.name, o), twin(builtin_blocks(), t.name, o);
  ASSERT_TRUE(h.ok()) << t.name;
  ASSERT_TRUE(twin.ok());
  const IecType dt = o.datatype.value_or(t.default_datatype.value_or(IecType::LREAL));
  std::vector<std::pair<std::string, std::uint32_t>> reals;  // floating input elements
  for (const auto& p : t.pins)
    if (p.dir == PinDir::In && p.tunes.empty() && is_real(pin_type(p, dt)))
      for (std::uint32_t k = 0; k < h.length(p.name); ++k) reals.emplace_back(p.name, k);

  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> value(-2.0, 2.0);
  std::uniform_int_distribution<int> gap(3, 30), len(1, 8);
  const double bad[] = {kNaN, kInf, -kInf};
  int until_burst = gap(rng), burst_left = 0;
  std::vector<std::uint64_t> held;
  for (int scan = 0; scan < 400; ++scan) {
    // The same finite inputs to both, a smooth random walk (a reference, a
    // measurement), except that bounds-like pins keep their order.
    for (const auto& [pin, k] : reals) {
      const double v = value(rng);
      set_real(h, pin, k, pin_type(t.pins[static_cast<std::size_t>(t.pin_index(pin))], dt), v);
      twin.cell(pin, k) = h.cell(pin, k);
    }
    const bool in_burst = burst_left > 0 && !reals.empty();
    if (in_burst) {
      const auto& [pin, k] = reals[static_cast<std::size_t>(rng() % reals.size())];
      set_real(h, pin, k, pin_type(t.pins[static_cast<std::size_t>(t.pin_index(pin))], dt), bad[rng() % 3]);
      if (held.empty()) held = outputs(h, t);
      const std::size_t events = h.events().size();
      h.scan();
      twin.skip_scan();
      EXPECT_FALSE(h.get<bool>(kEnoPin)) << t.name << " scan " << scan;
      EXPECT_EQ(outputs(h, t), held) << t.name << ": outputs moved during a burst, scan " << scan;
      EXPECT_GT(h.events().size(), events) << t.name << ": no fault event";
      if (--burst_left == 0) until_burst = gap(rng);
    } else {
      held.clear();
      h.scan();
      twin.scan();
      EXPECT_TRUE(h.get<bool>(kEnoPin)) << t.name << " scan " << scan;
      EXPECT_EQ(outputs(h, t), outputs(twin, t)) << t.name << ": state poisoned, scan " << scan;
      for (const auto& p : t.pins)
        if (p.dir == PinDir::Out && is_real(pin_type(p, dt)))
          for (std::uint32_t k = 0; k < h.length(p.name); ++k) {
            const double v = pin_type(p, dt) == IecType::REAL ? h.get<float>(p.name, k) : h.get<double>(p.name, k);
            EXPECT_TRUE(std::isfinite(v)) << t.name << "." << p.name << " scan " << scan;
          }
      if (--until_burst <= 0) burst_left = len(rng);
    }
    if (::testing::Test::HasFailure()) return;
  }
}

TEST(FiniteInputs, EveryBlockTypeHasEno) {
  for (const auto* t : builtin_blocks().all()) {
    const int i = t->pin_index(kEnoPin);
    ASSERT_GE(i, 0) << t->name;
    EXPECT_EQ(t->pins[static_cast<std::size_t>(i)].dir, PinDir::Out) << t->name;
    EXPECT_EQ(t->pins[static_cast<std::size_t>(i)].type, IecType::BOOL) << t->name;
  }
}

TEST(FiniteInputs, EveryBlockTypeHoldsThroughBurstsAndRecovers) {
  int with_reals = 0;
  for (const auto* t : builtin_blocks().all()) {
    // BURN burns wall-clock time and has no floating input; UNIT_DELAY checks
    // at end_of_scan (its own test below).
    if (t->name == "BURN" || t->unit_delay) continue;
    for (auto dt : datatypes(*t)) {
      SCOPED_TRACE(t->name + (dt ? " " + std::string(type_name(*dt)) : ""));
      for (std::uint32_t seed = 1; seed <= 3; ++seed) run_bursts({t, dt}, seed);
      if (::testing::Test::HasFailure()) return;
      BlockHarness probe(builtin_blocks(), t->name, options_for(*t, dt));
      if (!probe.block().guard().reals.empty()) ++with_reals;
    }
  }
  EXPECT_GT(with_reals, 20);  // the property was exercised, not vacuous
}

// The reviewer's case: one NaN sample made a pure P controller output NaN
// forever.
TEST(FiniteInputs, PidRecoversFromOneNaNSample) {
  BlockHarness::Options o;
  o.params = {{"Kp", "2"}};
  BlockHarness pid(builtin_blocks(), "PID", o);
  ASSERT_TRUE(pid.ok());
  pid.set<double>("setpoint", 1.0);
  pid.set<double>("actual", 0.25);
  pid.scan();
  EXPECT_DOUBLE_EQ(pid.get<double>("y"), 1.5);
  EXPECT_TRUE(pid.get<bool>("ENO"));
  pid.set<double>("actual", kNaN);
  pid.scan();
  EXPECT_DOUBLE_EQ(pid.get<double>("y"), 1.5);  // held
  EXPECT_FALSE(pid.get<bool>("ENO"));
  ASSERT_EQ(pid.events().size(), 1u);
  EXPECT_EQ(pid.events()[0].kind, EventKind::BlockFault);
  EXPECT_STREQ(pid.events()[0].message, "input not finite");
  pid.set<double>("actual", 0.5);
  pid.scan();
  EXPECT_DOUBLE_EQ(pid.get<double>("y"), 1.0);
  EXPECT_TRUE(pid.get<bool>("ENO"));
}

// A unit delay samples its input at the end of the scan: a NaN there is not
// stored, and ENO reports it on the next scan.
TEST(FiniteInputs, UnitDelayKeepsItsLastFiniteSample) {
  BlockHarness d(builtin_blocks(), "UNIT_DELAY");
  ASSERT_TRUE(d.ok());
  d.set<double>("IN", 3.0);
  d.scan();
  d.set<double>("IN", kInf);
  d.scan();
  EXPECT_DOUBLE_EQ(d.get<double>("OUT"), 3.0);
  d.set<double>("IN", 4.0);
  d.scan();
  EXPECT_DOUBLE_EQ(d.get<double>("OUT"), 3.0);
  EXPECT_FALSE(d.get<bool>("ENO"));  // this scan's OUT is the held value
  d.scan();
  EXPECT_DOUBLE_EQ(d.get<double>("OUT"), 4.0);
  EXPECT_TRUE(d.get<bool>("ENO"));
}

}  // namespace
}  // namespace syncplc
