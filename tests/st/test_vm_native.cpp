// Native code (runtime/st/vm/native_x64.cpp) against the interpreter: the
// same program, compiled twice, run on both engines from the same inputs;
// after every scan the frames must agree bit for bit, and so must the
// faults (their text and order) and whether the loop budget stopped the scan.
// Programs: one per numeric type exercising every instruction native code
// has a template of (and the ones it hands to the interpreter), with edge
// inputs (each type's limits, NaN, infinities, -0.0, indices out of bounds,
// loops that exhaust the budget); and every program of the valid corpus.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "tests/st/corpus_files.hpp"
#include "runtime/st/vm/same_cell.hpp"
#include "tests/st/vm_fixture.hpp"

namespace syncplc::st::testing {
namespace {

using vm::same_cell;

// The program for one type: `T` in it is replaced by the type's name.
// `widen` adds the implicit widening to LREAL (not for 64-bit integers).
std::string typed_program(const std::string& type, bool widen) {
  std::string src = R"(
PROGRAM P
VAR
  x, y, z, s, p, q : T;
  r : ARRAY[0..9] OF T;
  lt, le, gt, ge, eq, ne, b1, b2 : BOOL;
  k, n, hit, stop_at : INT;
  w : LREAL;
END_VAR
s := x + y; p := x - y; q := x * y;
lt := x < y; le := x <= y; gt := x > y; ge := x >= y; eq := x = y; ne := x <> y;
b1 := (lt AND NOT gt) OR (eq XOR ne);
b2 := b1 XOR le;
IF x < y THEN hit := hit + 1; END_IF;
IF x <= y THEN hit := hit + 2; END_IF;
IF x > y THEN hit := hit + 4; END_IF;
IF x >= y THEN hit := hit + 8; END_IF;
IF x = y THEN hit := hit + 16; END_IF;
IF x <> y THEN hit := hit + 32; END_IF;
IF NOT b1 THEN hit := hit - 1; END_IF;
z := x * y + z;
z := z + x * y;
z := x * y - z;
z := z - x * y;
IF z > y THEN z := y; ELSIF z < x THEN z := x; END_IF;
q := q / y;
MODULO
IF s < x THEN s := x; ELSIF s > y THEN s := y; END_IF;
WIDEN
FOR k := 0 TO 9 DO
  r[k] := r[k] + x;
  s := s + r[k];
  IF r[k] > s THEN s := r[k] * y; END_IF;
END_FOR;
FOR k := n TO n + 3 DO
  r[k] := y;
END_FOR;
FOR k := 9 TO 0 BY -1 DO
  IF r[k] > x THEN EXIT; END_IF;
  p := p + r[k];
END_FOR;
FOR k := 0 TO 2 DO
  FOR n := 0 TO 3 DO
    q := q + r[k + n];
  END_FOR;
END_FOR;
n := stop_at MOD 13;
k := 0;
WHILE k < stop_at DO
  k := k + 1;
  IF k = 7 AND x = y THEN RETURN; END_IF;
END_WHILE;
END_PROGRAM
)";
  auto replace_all = [&](const std::string& from, const std::string& to) {
    for (std::size_t at = 0; (at = src.find(from, at)) != std::string::npos; at += to.size()) src.replace(at, from.size(), to);
  };
  replace_all("WIDEN", widen ? "w := x + w * 0.5;" : "");
  replace_all("MODULO", type == "REAL" || type == "LREAL" ? "" : "p := p MOD y;");
  replace_all(": T;", ": " + type + ";");
  replace_all("OF T;", "OF " + type + ";");
  return src;
}

template <class C>
std::vector<C> edge_values() {
  using L = std::numeric_limits<C>;
  std::vector<C> v = {C(0), C(1), C(2), C(3), L::max(), L::lowest(), C(L::max() - C(1))};
  if constexpr (std::is_signed_v<C>) v.push_back(C(-1)), v.push_back(C(-3));
  if constexpr (std::is_floating_point_v<C>) {
    v.push_back(L::quiet_NaN());
    v.push_back(L::infinity());
    v.push_back(-L::infinity());
    v.push_back(C(-0.0));
    v.push_back(L::denorm_min());
    v.push_back(C(0.1));
    v.push_back(C(-2.5e10));
  }
  return v;
}

// One source compiled twice, for each engine.
struct Engines {
  StRun native, interp;
  explicit Engines(const std::string& src, const std::string& pou = "P")
      : native({src}, pou, 10'000'000, vm::Engine::Native), interp({src}, pou, 10'000'000, vm::Engine::Interpreter) {}
  bool ok() const { return native.ok() && interp.ok(); }
  std::string error() const { return native.errors.empty() ? (interp.errors.empty() ? "" : interp.errors[0]) : native.errors[0]; }
};

// Everything an observer can see of a run after a scan.
struct Seen {
  bool ran = true;
  std::vector<std::uint64_t> frame;
  std::vector<std::string> faults;
};

Seen seen(StRun& r, bool ran) {
  Seen s;
  s.ran = ran;
  const Cell* f = r.instance->frame();
  for (std::uint32_t k = 0; k < r.instance->frame_cells(); ++k) s.frame.push_back(f[k].raw);
  s.faults = r.fault_texts();
  return s;
}

void expect_same(const Seen& a, const Seen& b, const std::string& where) {
  EXPECT_EQ(a.ran, b.ran) << where;
  ASSERT_EQ(a.frame.size(), b.frame.size()) << where;
  for (std::size_t k = 0; k < a.frame.size(); ++k)
    ASSERT_TRUE(same_cell(a.frame[k], b.frame[k])) << where << ": cell " << k << " differs: " << a.frame[k] << " "
                                                   << b.frame[k];
  EXPECT_EQ(a.faults, b.faults) << where;
}

template <class C>
void run_typed(const std::string& type, bool widen) {
  const std::string src = typed_program(type, widen);
  StRun native({src}, "P", 10'000'000, vm::Engine::Native);
  StRun interp({src}, "P", 10'000'000, vm::Engine::Interpreter);
  ASSERT_TRUE(native.ok()) << (native.errors.empty() ? "" : native.errors[0]);
  ASSERT_TRUE(interp.ok());
#if defined(__x86_64__)
  EXPECT_GT(vm::native_pous(*native.module), 0u) << "x86-64 runs compiled ST as native code";
#endif
  EXPECT_EQ(vm::native_pous(*interp.module), 0u);
  native.budget = interp.budget = 400;  // the WHILE of stop_at >= ~300 exhausts it
  const std::vector<C> values = edge_values<C>();
  std::mt19937_64 rng(20261129);
  const std::int16_t stops[] = {0, 5, 7, 40, 399, 1000};
  const std::int16_t starts[] = {0, 3, 6, 7, 9, -1, 12, -32768};
  for (int scan = 0; scan < 400; ++scan) {
    const C x = values[rng() % values.size()], y = values[rng() % values.size()];
    const std::int16_t stop_at = stops[rng() % 6], n = starts[rng() % 8];
    for (StRun* r : {&native, &interp}) {
      r->set<C>("x", x);
      r->set<C>("y", y);
      r->set<std::int16_t>("stop_at", stop_at);
      r->set<std::int16_t>("n", n);
    }
    const bool a = native.scan(), b = interp.scan();
    expect_same(seen(native, a), seen(interp, b), type + " scan " + std::to_string(scan));
    if (::testing::Test::HasFatalFailure()) return;
  }
  EXPECT_FALSE(native.fault_texts().empty()) << "the inputs reach the faults (bounds, division by zero)";
}

TEST(StVmNative, EveryTypesArithmeticComparisonsLoopsAndFaultsGiveTheInterpretersBits) {
  run_typed<std::int8_t>("SINT", true);
  run_typed<std::int16_t>("INT", true);
  run_typed<std::int32_t>("DINT", true);
  run_typed<std::int64_t>("LINT", false);
  run_typed<std::uint8_t>("USINT", true);
  run_typed<std::uint16_t>("UINT", true);
  run_typed<std::uint32_t>("UDINT", true);
  run_typed<std::uint64_t>("ULINT", false);
  run_typed<float>("REAL", true);
  run_typed<double>("LREAL", false);
}

// Loops whose cells native code keeps in registers, left every way there
// is: to their end, by EXIT, by RETURN, by the budget running out inside
// them, and through the interpreter's rare path in the middle of one (an
// index out of bounds, which writes the element's cell while it is in a
// register).
TEST(StVmNative, LoopsInRegistersWriteTheirCellsBackOnEveryWayOut) {
  const std::string src = R"(
PROGRAM P
VAR
  x, y, acc, best, v : LREAL;
  buf : ARRAY[0..15] OF LREAL;
  i, j, n, mode, count : DINT;
  flag : BOOL;
END_VAR
FOR i := 0 TO 15 DO
  buf[i] := buf[i] * 0.5 + x;
END_FOR;
acc := 0.0;
best := buf[0];
FOR i := 0 TO n DO
  v := buf[i] * y + acc;
  acc := acc + v * 0.25;
  IF v > best THEN best := v; j := i; END_IF;
  IF mode = 1 AND i = 5 THEN EXIT; END_IF;
  IF mode = 2 AND i = 7 THEN RETURN; END_IF;
  count := count + 1;
  flag := flag XOR (v < acc);
END_FOR;
i := 0;
WHILE i < n DO
  i := i + 1;
  IF mode = 3 THEN CONTINUE; END_IF;
  acc := acc - x * y;
  IF acc < -1.0E6 THEN acc := -1.0E6; ELSIF acc > 1.0E6 THEN acc := 1.0E6; END_IF;
END_WHILE;
END_PROGRAM
)";
  Engines both(src);
  ASSERT_TRUE(both.ok()) << both.error();
  StRun& native = both.native;
  StRun& interp = both.interp;
#if defined(__x86_64__)
  EXPECT_GE(vm::native_register_loops(*native.module), 3u) << "the three loops keep their cells in registers";
#endif
  std::mt19937_64 rng(7);
  const double xs[] = {0.0, 1.5, -2.25, 1e300, std::numeric_limits<double>::quiet_NaN(), -0.0};
  const std::int32_t ns[] = {0, 3, 15, 16, 40, 5000, -1};
  for (int scan = 0; scan < 300; ++scan) {
    const double x = xs[rng() % 6], y = xs[rng() % 6];
    const std::int32_t n = ns[rng() % 7], mode = static_cast<std::int32_t>(rng() % 4);
    const std::int64_t budget = scan % 5 == 0 ? static_cast<std::int64_t>(rng() % 200) : 1'000'000;
    for (StRun* r : {&native, &interp}) {
      r->set<double>("x", x);
      r->set<double>("y", y);
      r->set<std::int32_t>("n", n);
      r->set<std::int32_t>("mode", mode);
      r->budget = budget;
    }
    const bool a = native.scan(), b = interp.scan();
    expect_same(seen(native, a), seen(interp, b), "scan " + std::to_string(scan));
    if (::testing::Test::HasFatalFailure()) return;
  }
  EXPECT_FALSE(native.fault_texts().empty()) << "n = 16 and 40 index past buf's end inside the loop";
}

// The templates that call the runtime (string functions, REAL functions,
// FB calls) and the ones with a rare path into the interpreter (integer
// division by 0 and by -1, CASE selectors outside every label).
TEST(StVmNative, CallsCaseAndDivisionGiveTheInterpretersBits) {
  const std::string src = R"(
FUNCTION_BLOCK Spin
VAR_INPUT
  n : DINT;
END_VAR
VAR_OUTPUT
  turns : DINT;
END_VAR
VAR
  k : DINT;
END_VAR
FOR k := 1 TO n DO
  turns := turns + 1;
END_FOR;
END_FUNCTION_BLOCK

FUNCTION Half : LREAL
VAR_INPUT
  v : LREAL;
END_VAR
Half := v / 2.0;
END_FUNCTION

PROGRAM P
VAR
  sel, a, b, q, r : DINT;
  s8 : SINT;
  u : UDINT;
  x, y, z : LREAL;
  f : REAL;
  text, part : STRING[20];
  pos : INT;
  spin : Spin;
  state : (Idle, Run, Stop) := Idle;
END_VAR
CASE sel OF
  -3..-1: a := a + 1;
  0, 2: a := a + 2; state := Run;
  5: a := a - 7; state := Stop;
  7..9: a := a * 3;
ELSE
  a := a + 100;
END_CASE;
CASE state OF
  Idle: b := b + 1;
  Run: b := b * 2;
  Stop: b := 0;
END_CASE;
q := a / sel;
r := a MOD sel;
s8 := DINT_TO_SINT(sel) / SINT#-1;
u := DINT_TO_UDINT(a) / DINT_TO_UDINT(sel);
z := x / y + SQRT(x) + LN(y) + EXPT(x, y) + Half(x) + ATAN2(y, x);
f := LREAL_TO_REAL(z) / LREAL_TO_REAL(y);
text := CONCAT('n=', DINT_TO_STRING(a));
pos := FIND(text, '1');
part := MID(text, 3, pos);
spin(n := sel);
END_PROGRAM
)";
  Engines both(src);
  ASSERT_TRUE(both.ok()) << both.error();
  StRun& native = both.native;
  StRun& interp = both.interp;
  std::mt19937_64 rng(11);
  const std::int32_t sels[] = {-4, -3, -1, 0, 1, 2, 5, 7, 9, 10, -2147483647 - 1, 2147483647, 300};
  const double xs[] = {0.0, 2.0, -1.0, 1e308, std::numeric_limits<double>::infinity(), 0.5};
  for (int scan = 0; scan < 300; ++scan) {
    const std::int32_t sel = sels[rng() % 13];
    const double x = xs[rng() % 6], y = xs[rng() % 6];
    const std::int64_t budget = scan % 7 == 0 ? static_cast<std::int64_t>(rng() % 50) : 1'000'000;
    for (StRun* r : {&native, &interp}) {
      r->set<std::int32_t>("sel", sel);
      r->set<double>("x", x);
      r->set<double>("y", y);
      r->budget = budget;
    }
    const bool a = native.scan(), b = interp.scan();
    expect_same(seen(native, a), seen(interp, b), "scan " + std::to_string(scan));
    if (::testing::Test::HasFatalFailure()) return;
  }
}

// A CASE whose jump table is far larger than its code (4,001 targets for
// a handful of instructions) still gets native code: the table is in the
// code's memory, and its size counts (before, the estimate left it out and
// the POU fell back to the interpreter).
TEST(StVmNative, APouWithAWideCaseTableIsNativeCode) {
  const std::string src =
      "PROGRAM P\nVAR k, a : INT; END_VAR\n"
      "CASE k OF\n  0..3999: a := a + 1;\n  4000: a := 0;\nEND_CASE;\nk := (k + 997) MOD 4003;\nEND_PROGRAM\n";
  Engines both(src);
  ASSERT_TRUE(both.ok()) << both.error();
#if defined(__x86_64__)
  EXPECT_EQ(vm::native_pous(*both.native.module), 1u);
#endif
  for (int scan = 0; scan < 50; ++scan) {
    const bool a = both.native.scan(), b = both.interp.scan();
    expect_same(seen(both.native, a), seen(both.interp, b), "scan " + std::to_string(scan));
  }
}

TEST(StVmNative, ARunawayLoopStopsAtTheSameSiteWithTheSameBudgetLeft) {
  const std::string src =
      "PROGRAM P\nVAR\n  k : DINT;\n  a : ARRAY[1..4] OF LREAL;\n  s : LREAL;\nEND_VAR\n"
      "WHILE TRUE DO\n  k := k + 1;\n  FOR k := 1 TO 4 DO s := s + a[k]; END_FOR;\nEND_WHILE;\nEND_PROGRAM\n";
  Engines both(src);
  ASSERT_TRUE(both.ok()) << both.error();
  StRun& native = both.native;
  StRun& interp = both.interp;
  for (std::int64_t budget : {0, 1, 2, 3, 4, 5, 99, 1000}) {
    native.budget = interp.budget = budget;
    const bool a = native.scan(), b = interp.scan();
    EXPECT_FALSE(a);
    expect_same(seen(native, a), seen(interp, b), "budget " + std::to_string(budget));
    ASSERT_NE(native.instance->stopped(), nullptr);
    ASSERT_NE(interp.instance->stopped(), nullptr);
    EXPECT_STREQ(native.instance->stopped(), interp.instance->stopped());
    EXPECT_EQ(native.instance->frame()[0].raw, interp.instance->frame()[0].raw);
  }
}

// A PROGRAM (or FB) instanced by the project has no caller to bind its
// VAR_IN_OUTs: a call of an FB through one gets a null frame, which the
// interpreter's run() takes as nothing to run. Native code must not load
// cells from address 0 there (it crashed the process).
TEST(StVmNative, AnFbCalledThroughAnUnboundVarInOutRunsAsInTheInterpreter) {
  const std::string src = R"(
FUNCTION_BLOCK Inner
VAR x : LREAL; k : DINT; END_VAR
FOR k := 1 TO 3 DO x := x + 1.0; END_FOR;
END_FUNCTION_BLOCK
PROGRAM P
VAR_IN_OUT inner : Inner; END_VAR
VAR n, m : DINT; END_VAR
n := n + 1;
inner();
m := m + 2;
END_PROGRAM
)";
  Engines both(src);
  ASSERT_TRUE(both.ok()) << both.error();
  StRun& native = both.native;
  StRun& interp = both.interp;
  for (int scan = 0; scan < 3; ++scan) {
    const bool b = interp.scan(), a = native.scan();
    expect_same(seen(native, a), seen(interp, b), "scan " + std::to_string(scan));
  }
  EXPECT_EQ(native.get<std::int32_t>("m"), 6);
}

// The edges of loops in registers: FOR_INC up to each integer type's
// largest value (a + 1 must not wrap past it), indices of arrays whose
// bounds are beyond 32 bits or at INT32_MIN, an array of 400,001 cells (the
// displacements of the cells after it), more cells than registers, and
// loops entered at their head by a CASE's table and by the code before
// them, one of them by a jump the generator threads into its body.
TEST(StVmNative, RegisterLoopsAtTheLimitsOfTypesIndicesAndRegisters) {
  const std::string src = R"(
PROGRAM P
VAR
  s, hs : SINT; i, hi : INT; d, hd : DINT; l, hl : LINT;
  us, hus : USINT; ui, hui : UINT; ud, hud : UDINT; ul, hul : ULINT;
  ns : SINT; ni : INT; nd : DINT; nl : LINT; nus : USINT; nui : UINT; nud : UDINT; nul : ULINT;
  far : ARRAY[3000000000..3000000009] OF LINT;
  neg : ARRAY[-2147483648..-2147483639] OF DINT;
  big : ARRAY[-200000..200000] OF LREAL;
  x0, x1, x2, x3, x4, x5, x6, x7, x8, x9, x10, x11, x12, x13 : LREAL;
  j0, j1, j2, j3, j4, j5, j6, j7, n, k : DINT;
  ix : LINT; iu : UDINT; sel : INT; mode : DINT;
  acc : LREAL;
END_VAR
FOR s := hs - 3 TO hs DO ns := ns + s; END_FOR;
FOR i := hi - 3 TO hi DO ni := ni + i; END_FOR;
FOR d := hd - 3 TO hd DO nd := nd + d; END_FOR;
FOR l := hl - 3 TO hl DO nl := nl + l; END_FOR;
FOR us := hus - 3 TO hus DO nus := nus + us; END_FOR;
FOR ui := hui - 3 TO hui DO nui := nui + ui; END_FOR;
FOR ud := hud - 3 TO hud DO nud := nud + ud; END_FOR;
FOR ul := hul - 3 TO hul DO nul := nul + 1; END_FOR;
FOR d := -2147483647 - 1 + k TO -2147483638 + k DO neg[d] := neg[d] + d; END_FOR;
FOR ix := 2999999999 + nl MOD 3 TO 3000000010 DO far[ix] := far[ix] + ix; acc := acc + 0.5; END_FOR;
FOR iu := 2999999999 TO 3000000010 + ud DO far[iu] := far[iu] - 1; END_FOR;
FOR d := k - 1 TO k + 201 DO big[d * 1000] := big[d * 1000] + x0; x1 := x1 + big[d]; END_FOR;
FOR j0 := 0 TO n DO
  x0 := x0 * x1 + x2; x3 := x3 * x4 + x5; x6 := x6 * x7 + x8; x9 := x9 * x10 + x11; x12 := x12 + x13 * x0;
  j1 := j1 + j0; j2 := j2 + j1; j3 := j3 - j2; j4 := j4 + j3; j5 := j5 + j4; j6 := j6 + j5; j7 := j7 + j6;
  IF j7 > 100000 THEN EXIT; END_IF;
  IF x12 > 1.0E6 THEN x12 := 1.0E6; ELSIF x12 < -1.0E6 THEN x12 := -1.0E6; END_IF;
END_FOR;
IF mode = 1 THEN acc := acc + 1.0; END_IF;
REPEAT
  CONTINUE;
  acc := acc * 2.0;
UNTIL j1 > mode END_REPEAT;
CASE sel OF
  0: WHILE j2 < 100 DO j2 := j2 + 7; acc := acc + 0.25; END_WHILE;
  1: FOR i := 1 TO 5 DO acc := acc * 1.5; END_FOR;
  2, 3: REPEAT j3 := j3 - 1; UNTIL j3 < 0 END_REPEAT;
END_CASE;
WHILE acc > 100.0 DO acc := acc - 99.0; END_WHILE;
END_PROGRAM
)";
  Engines both(src);
  ASSERT_TRUE(both.ok()) << both.error();
  StRun& native = both.native;
  StRun& interp = both.interp;
#if defined(__x86_64__)
  EXPECT_GE(vm::native_register_loops(*native.module), 14u);
#endif
  std::mt19937_64 rng(11);
  auto limit = [&](auto max) {
    using C = decltype(max);
    const C v[] = {max, C(max - 1), C(max - 3), C(0), C(3), std::numeric_limits<C>::lowest()};
    return v[rng() % 6];
  };
  for (int scan = 0; scan < 120; ++scan) {
    const auto hs = limit(std::numeric_limits<std::int8_t>::max());
    const auto hi = limit(std::numeric_limits<std::int16_t>::max());
    const auto hd = limit(std::numeric_limits<std::int32_t>::max());
    const auto hl = limit(std::numeric_limits<std::int64_t>::max());
    const auto hus = limit(std::numeric_limits<std::uint8_t>::max());
    const auto hui = limit(std::numeric_limits<std::uint16_t>::max());
    const auto hud = limit(std::numeric_limits<std::uint32_t>::max());
    const auto hul = limit(std::numeric_limits<std::uint64_t>::max());
    const std::int32_t ks[] = {0, 1, -1, 3, -200, 200, 2147483647};
    const std::int32_t k = ks[rng() % 7], n = static_cast<std::int32_t>(rng() % 40) - 2;
    const double xs[] = {0.5, -1.25, 2.0, std::numeric_limits<double>::quiet_NaN(), 1e300, -0.0};
    const std::int64_t budget = scan % 4 == 0 ? static_cast<std::int64_t>(rng() % 300) : 1'000'000;
    for (StRun* r : {&native, &interp}) {
      r->set("hs", hs), r->set("hi", hi), r->set("hd", hd), r->set("hl", hl);
      r->set("hus", hus), r->set("hui", hui), r->set("hud", hud), r->set("hul", hul);
      r->set<std::int32_t>("k", k);
      r->set<std::int32_t>("n", n);
      r->set<std::int16_t>("sel", static_cast<std::int16_t>(scan % 5));
      r->set<std::int32_t>("mode", scan % 7 - 1);
      r->set<double>("x0", xs[scan % 6]);
      r->set<double>("x13", xs[(scan / 6) % 6]);
      r->budget = budget;
    }
    const bool a = native.scan(), b = interp.scan();
    expect_same(seen(native, a), seen(interp, b), "scan " + std::to_string(scan));
    if (::testing::Test::HasFatalFailure()) return;
    ASSERT_EQ(native.instance->stopped() == nullptr, interp.instance->stopped() == nullptr);
    if (native.instance->stopped()) {
      EXPECT_STREQ(native.instance->stopped(), interp.instance->stopped());
    }
  }
  EXPECT_FALSE(native.fault_texts().empty()) << "the indices past the arrays' ends fault";
}

// Every PROGRAM and FUNCTION_BLOCK of the valid corpus, 50 scans each from
// their initial values. Only the cells that are values are compared: a
// reference or an embedded built-in block holds an address, which differs
// between the two instances.
TEST(StVmNative, EveryProgramOfTheValidCorpusRunsAsTheInterpreterRunsIt) {
  int compared = 0;
  for (const auto& file : corpus::sources("valid")) {
    const std::string src = corpus::read(file);
    StRun probe({src}, "", 10'000'000, vm::Engine::Interpreter);
    if (!probe.module) continue;  // a file of declarations only, or a FUNCTION's
    for (const vm::CompiledPou& pou : probe.module->pous) {
      if (pou.kind == PouKind::Function) continue;
      // A VAR_IN_OUT or VAR_EXTERNAL is a reference its user binds: alone,
      // the POU has nothing to point it at.
      bool bound_elsewhere = false;
      for (const vm::VarSlot& v : pou.vars) {
        const auto scope = static_cast<VarScope>(v.scope);
        bound_elsewhere = bound_elsewhere || scope == VarScope::InOut || scope == VarScope::External;
      }
      if (bound_elsewhere) continue;
      StRun native({src}, pou.name, 10'000'000, vm::Engine::Native);
      StRun interp({src}, pou.name, 10'000'000, vm::Engine::Interpreter);
      ASSERT_TRUE(native.ok() && interp.ok()) << file;
      std::vector<std::pair<std::uint32_t, std::uint32_t>> values;  // (at, cells)
      for (const vm::VarSlot& v : pou.vars) {
        if (!v.type) continue;
        const VarScope scope = static_cast<VarScope>(v.scope);
        if (scope == VarScope::InOut || scope == VarScope::External) continue;
        const Type* t = v.type;
        while (t->kind == Type::Kind::Array && t->element) t = t->element;
        if (t->kind == Type::Kind::FunctionBlock || t->kind == Type::Kind::Struct) continue;
        values.emplace_back(v.at, v.cells);
      }
      for (int scan = 0; scan < 50; ++scan) {
        const bool a = native.scan(), b = interp.scan();
        ASSERT_EQ(a, b) << file << " " << pou.name;
        for (const auto& [at, cells] : values)
          for (std::uint32_t k = 0; k < cells; ++k)
            ASSERT_TRUE(same_cell(native.instance->frame()[at + k].raw, interp.instance->frame()[at + k].raw))
                << file << " " << pou.name << " scan " << scan << " cell " << at + k;
        ASSERT_EQ(native.fault_texts(), interp.fault_texts()) << file << " " << pou.name;
      }
      ++compared;
    }
  }
  EXPECT_GE(compared, 12);
}

}  // namespace
}  // namespace syncplc::st::testing
