// Built-in blocks instanced from ST with their parameters given in the
// declaration (`s : TRANSIENT_SYNC := (n := 3)`), array pins as
// ARRAY[1..n], run against the same block on its own (BlockHarness), and
// every mistake in such a declaration reported at its place.
#include <algorithm>
#include <cstring>

#include "runtime/core/block_harness.hpp"
#include "tests/st/vm_fixture.hpp"

namespace syncplc::st::testing {
namespace vm_builtins {

bool same_bits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

TEST(StVmBuiltins, TransientSyncWithNFromItsDeclarationMatchesTheBlockOnItsOwn) {
  auto r = run_program(
      "sync : TRANSIENT_SYNC := (n := 3);\n"
      "r : ARRAY[1..3] OF LREAL := [0.0, 0.0, 0.0];\n"
      "vmin : ARRAY[1..3] OF LREAL := [3(-1.0)]; vmax : ARRAY[1..3] OF LREAL := [3(1.0)];\n"
      "amin : ARRAY[1..3] OF LREAL := [3(-2.0)]; amax : ARRAY[1..3] OF LREAL := [3(2.0)];\n"
      "x2 : LREAL; all_there : BOOL; i : INT; arrived : ARRAY[1..3] OF BOOL;",
      "sync(r := r, v_min := vmin, v_max := vmax, a_min := amin, a_max := amax, synchronized => all_there);\n"
      "x2 := sync.x[2];\n"
      "FOR i := 1 TO 3 DO arrived[i] := sync.tracking[i]; END_FOR;");
  ASSERT_TRUE(r->ok()) << r->errors[0];

  BlockHarness::Options o;
  o.params = {{"n", "3"}};
  o.period_ns = 10'000'000;  // the fixture's scan
  BlockHarness h(::syncplc::builtin_blocks(), "TRANSIENT_SYNC", o);
  ASSERT_TRUE(h.ok()) << h.errors()[0];
  for (std::uint32_t k = 0; k < 3; ++k) {
    h.set<double>("v_min", k, -1.0);
    h.set<double>("v_max", k, 1.0);
    h.set<double>("a_min", k, -2.0);
    h.set<double>("a_max", k, 2.0);
  }
  const double targets[3] = {1.0, -0.5, 2.0};  // three distances: the nearer axes are slowed down
  int arrival_scan[3] = {-1, -1, -1};
  for (int scan = 0; scan < 400; ++scan) {
    if (scan == 5)
      for (std::uint32_t k = 0; k < 3; ++k) {
        r->set<double>("r[" + std::to_string(k + 1) + "]", targets[k]);
        h.set<double>("r", k, targets[k]);
      }
    r->scan();
    h.scan();
    for (std::uint32_t k = 0; k < 3; ++k) {
      const std::string i = "[" + std::to_string(k + 1) + "]";
      ASSERT_TRUE(same_bits(r->get<double>("sync.x" + i), h.get<double>("x", k))) << "scan " << scan << " axis " << k;
      ASSERT_TRUE(same_bits(r->get<double>("sync.x_dot" + i), h.get<double>("x_dot", k))) << "scan " << scan;
      ASSERT_TRUE(same_bits(r->get<double>("sync.x_ddot" + i), h.get<double>("x_ddot", k))) << "scan " << scan;
      ASSERT_EQ(r->get<bool>("arrived" + i), h.get<bool>("tracking", k)) << "scan " << scan;
      if (scan > 5 && arrival_scan[k] < 0 && r->get<bool>("arrived" + i)) arrival_scan[k] = scan;
    }
    ASSERT_EQ(r->get<std::int64_t>("sync.arrival"), h.get<std::int64_t>("arrival")) << "scan " << scan;
    ASSERT_TRUE(same_bits(r->get<double>("x2"), r->get<double>("sync.x[2]")));
  }
  // Its known behaviour: every axis arrives on the same scan.
  EXPECT_GT(arrival_scan[0], 6);
  EXPECT_EQ(arrival_scan[0], arrival_scan[1]);
  EXPECT_EQ(arrival_scan[0], arrival_scan[2]);
  EXPECT_TRUE(r->get<bool>("all_there"));
  EXPECT_EQ(r->get<std::int64_t>("sync.spread"), 0);
  EXPECT_EQ(r->get<std::int64_t>("sync.windows"), 1);
  EXPECT_EQ(r->get<double>("sync.x[3]"), 2.0);
}

TEST(StVmBuiltins, CircleWithItsTwoRequiredParametersMatchesTheBlockOnItsOwn) {
  auto r = run_program("c : CIRCLE := (radius := 0.32, feed := 0.04167); px, py : LREAL;",
                       "c(); px := c.x; py := c.y;");
  ASSERT_TRUE(r->ok()) << r->errors[0];
  BlockHarness::Options o;
  o.params = {{"radius", "0.32"}, {"feed", "0.04167"}};
  o.period_ns = 10'000'000;
  BlockHarness h(::syncplc::builtin_blocks(), "CIRCLE", o);
  ASSERT_TRUE(h.ok()) << h.errors()[0];
  for (int scan = 0; scan < 300; ++scan) {
    r->scan();
    h.scan();
    ASSERT_TRUE(same_bits(r->get<double>("px"), h.get<double>("x"))) << "scan " << scan;
    ASSERT_TRUE(same_bits(r->get<double>("py"), h.get<double>("y"))) << "scan " << scan;
    ASSERT_TRUE(same_bits(r->get<double>("c.s"), h.get<double>("s"))) << "scan " << scan;
  }
  EXPECT_GT(r->get<double>("c.s"), 0.1);  // it moved along the circle (0.04167 m/s for 3 s)
}

TEST(StVmBuiltins, ArrayPinsAreArraysOfTheirLengthForArgumentsAndIndexes) {
  auto r = run_program(
      "sync : TRANSIENT_SYNC := (n := 4, rule := 2);\n"
      "refs : ARRAY[1..4] OF LREAL := [1.0, 2.0, 3.0, 4.0]; lim : ARRAY[1..4] OF LREAL := [4(1.0)];\n"
      "acc : ARRAY[1..4] OF LREAL := [4(1.0)]; nacc : ARRAY[1..4] OF LREAL := [4(-1.0)];\n"
      "out : ARRAY[1..4] OF LREAL; i : INT := 5; past : LREAL := 7.0;",
      "sync(r := refs, v_min := nacc, v_max := lim, a_min := nacc, a_max := acc, x => out);\n"
      "past := sync.x[i];");
  ASSERT_TRUE(r->ok()) << r->errors[0];
  r->scan();
  for (int k = 1; k <= 4; ++k) {
    EXPECT_EQ(r->get<double>("out[" + std::to_string(k) + "]"), k);  // started at r (start_at_r)
    EXPECT_EQ(r->get<double>("sync.r[" + std::to_string(k) + "]"), k);
  }
  // An index past n reads 0 and faults at its place, as any array's.
  EXPECT_EQ(r->get<double>("past"), 0.0);
  const auto f = r->fault_texts();
  ASSERT_EQ(f.size(), 1u);
  EXPECT_EQ(f[0], "array index out of bounds (1..4) at t0.st:9:16");
  // Paths reach the elements of the new layout.
  std::string why;
  EXPECT_FALSE(vm::resolve_path(*r->module, 0, "sync.x[5]", &why));
  EXPECT_EQ(why, "'sync.x[5]': index 5 is outside 1..4");
}

TEST(StVmBuiltins, TwoParameterizationsAreTwoTypesAndTheSameOneIsOne) {
  auto r = run_program(
      "a : TRANSIENT_SYNC := (n := 2); b : TRANSIENT_SYNC := (n := 2, rule := 0); c : TRANSIENT_SYNC := (n := 3);\n"
      "two : ARRAY[1..2] OF LREAL := [5.0, 6.0]; three : ARRAY[1..3] OF LREAL := [7.0, 8.0, 9.0];",
      "a(r := two); b(r := two); c(r := three);");
  ASSERT_TRUE(r->ok()) << r->errors[0];
  const vm::CompiledPou& p = r->instance->pou();
  const Type* ta = nullptr;
  const Type* tb = nullptr;
  const Type* tc = nullptr;
  for (const auto& v : p.vars) {
    if (v.name == "a") ta = v.type;
    if (v.name == "b") tb = v.type;
    if (v.name == "c") tc = v.type;
  }
  ASSERT_TRUE(ta && tb && tc);
  EXPECT_EQ(ta, tb);  // rule := 0 is the default
  EXPECT_NE(ta, tc);
  EXPECT_EQ(ta->name, "TRANSIENT_SYNC (n := 2)");
  r->scan();
  EXPECT_EQ(r->get<double>("a.x[2]"), 6.0);
  EXPECT_EQ(r->get<double>("c.x[3]"), 9.0);
}

TEST(StVmBuiltins, ParameterMistakesAreErrorsAtTheirPlace) {
  auto r = std::make_unique<StRun>(std::vector<std::string>{
                                       "PROGRAM Main\n"
                                       "VAR\n"
                                       "  k : DINT := 2;\n"
                                       "  a : TRANSIENT_SYNC;\n"
                                       "  b : CIRCLE := (radius := 0.5, fed := 1.0);\n"
                                       "  c : TRANSIENT_SYNC := (n := 0);\n"
                                       "  d : TRANSIENT_SYNC := (n := k);\n"
                                       "  e : PID := (Kp := TRUE, anti_windup := 3);\n"
                                       "  f : TRANSIENT_SYNC := (n := 2);\n"
                                       "  g : ARRAY[1..2] OF CIRCLE;\n"
                                       "END_VAR\n"
                                       "IF f.tracking[3] THEN k := 1; END_IF;\n"
                                       "END_PROGRAM\n"},
                                   "Main");
  EXPECT_EQ(r->errors,
            (std::vector<std::string>{
                "t0.st:4:3: a: TRANSIENT_SYNC needs its parameter 'n' (it has no default value): give it in the "
                "declaration, a : TRANSIENT_SYNC := (n := ...)",
                "t0.st:5:3: b: CIRCLE needs its parameter 'feed' (it has no default value): give it in the "
                "declaration, b : CIRCLE := (feed := ...)",
                "t0.st:5:33: 'CIRCLE' has no input, parameter or variable 'fed' to initialise (did you mean feed?)",
                "t0.st:6:31: c.n = 0 is outside its range 1 .. 1024",
                "t0.st:7:31: d.n: a parameter's value must be a constant expression",
                "t0.st:8:21: e.Kp: expected LREAL, found BOOL (use BOOL_TO_LREAL(...))",
                "t0.st:8:42: e.anti_windup = 3 is outside its range 0 .. 2",
                "t0.st:10:7: an array of CIRCLE: its parameter 'radius' has no default value, and only an instance "
                "declared on its own can be given one (CIRCLE := (...))",
                "t0.st:12:15: index 3 is outside 1..2",
            }));
}

TEST(StVmBuiltins, AnInputsInitialValueInTheDeclarationIsApplied) {
  auto r = run_program("t : TON := (PT := T#30ms); done : BOOL;", "t(IN := TRUE, Q => done);");
  ASSERT_TRUE(r->ok()) << r->errors[0];
  r->scan(3);  // 0, 10, 20 ms
  EXPECT_FALSE(r->get<bool>("done"));
  EXPECT_EQ(r->get<std::int64_t>("t.PT"), 30'000'000);
  r->scan();
  EXPECT_TRUE(r->get<bool>("done"));
}

TEST(StVmBuiltins, ATunableParameterAtItsDefaultIsNotTunedToZeroByItsUnwrittenInput) {
  auto r = run_program("p : PID; y : LREAL; ok : BOOL;", "p(setpoint := 1.0, actual := 0.25, y => y, ENO => ok);");
  ASSERT_TRUE(r->ok()) << r->errors[0];
  r->scan(2);
  EXPECT_EQ(r->get<double>("y"), 0.75);  // Kp 1 (its default)
  EXPECT_TRUE(r->get<bool>("ok"));
  EXPECT_TRUE(r->fault_texts().empty()) << r->fault_texts()[0];
}

TEST(StVmBuiltins, ATunableParameterHoldsUntilTheProgramWritesItsTuningInput) {
  auto r = run_program("p : PID := (Kp := 2.0); y : LREAL; ok : BOOL; tune : BOOL;",
                       "IF tune THEN p.Kp_in := 4.0; END_IF;\n"
                       "p(setpoint := 1.0, actual := 0.25, y => y, ENO => ok);");
  ASSERT_TRUE(r->ok()) << r->errors[0];
  r->scan(2);
  EXPECT_EQ(r->get<double>("y"), 1.5);  // Kp (e = 0.75), not its tuning input's zero
  EXPECT_TRUE(r->get<bool>("ok"));
  r->set<bool>("tune", true);
  r->scan();
  EXPECT_EQ(r->get<double>("y"), 3.0);
  EXPECT_TRUE(r->get<bool>("ok"));
  EXPECT_TRUE(r->fault_texts().empty());
}

TEST(StVmBuiltins, EveryBlockWithArrayPinsIsATypeAndEveryDefaultAValue) {
  const auto sigs = vm::block_signatures(::syncplc::builtin_blocks());
  auto find = [&](const std::string& n) {
    return std::find_if(sigs.begin(), sigs.end(), [&](const BlockSignature& b) { return b.name == n; });
  };
  for (const char* n : {"TRANSIENT_SYNC", "SYNC_CONTROLLER", "CIRCLE", "COSINE_TRAJECTORY"})
    EXPECT_NE(find(n), sigs.end()) << n;
  for (const BlockSignature& b : sigs) {
    IecType datatype{};
    const BlockTypeInfo* t = vm::builtin_block(::syncplc::builtin_blocks(), b.name, &datatype);
    ASSERT_TRUE(t) << b.name;
    ASSERT_EQ(b.params.size(), t->params.size()) << b.name;
    for (std::size_t k = 0; k < b.params.size(); ++k)
      EXPECT_EQ(b.params[k].value.has_value(), !t->params[k].default_value.empty()) << b.name << "." << b.params[k].name;
  }
}

// Issue 23: "every built-in block can be instanced and called from ST as an
// FB". Each one (but the operators AND, OR, XOR, NOT, MOD), its parameters without a default at the lower end of their
// range (1 where that is open), declared, called and run for a few scans.
TEST(StVmBuiltins, EveryBuiltInBlockIsInstancedAndCalledFromSt) {
  int blocks = 0;
  for (const BlockSignature& b : vm::block_signatures(::syncplc::builtin_blocks())) {
    // ST's operators (keywords): a graph block, not an FB name in ST.
    if (b.name == "AND" || b.name == "OR" || b.name == "XOR" || b.name == "NOT" || b.name == "MOD") continue;
    std::string params;
    for (const auto& p : b.params) {
      if (p.value) continue;
      std::string v = p.type == "BOOL" ? "FALSE" : p.type == "TIME" ? "T#1s" : "1";
      if (p.min && *p.min > 1) v = std::to_string(static_cast<long long>(*p.min));
      params += (params.empty() ? "" : ", ") + p.name + " := " + v;
    }
    std::string decl = "b : " + b.name + (params.empty() ? "" : " := (" + params + ")") + ";";
    // A link (an MC block's Axis) is a VAR_IN_OUT every call gives: an
    // AXIS_REF here names no axis (the call faults, the block has none).
    std::string args;
    for (const auto& p : b.pins)
      if (!p.ref_target.empty()) {
        decl += "\nref_" + p.name + " : " + (p.length_param.empty() ? "" : "ARRAY[1..1] OF ") + p.type + ";";
        args += (args.empty() ? "" : ", ") + p.name + " := ref_" + p.name;
      }
    auto r = std::make_unique<StRun>(
        std::vector<std::string>{"PROGRAM Main\nVAR\n" + decl + "\nEND_VAR\nb(" + args + ");\nEND_PROGRAM\n"}, "Main");
    EXPECT_TRUE(r->ok()) << decl << ": " << (r->errors.empty() ? "not instanced" : r->errors[0]);
    if (r->ok()) r->scan(3);
    ++blocks;
  }
  EXPECT_GT(blocks, 30);
}

// IEC 61131-3's typed counters (table 45): CTU_DINT counts past INT's
// range, CTD_LINT below it, CTUD_UDINT stops at 0 and CTU_ULINT at ULINT's
// largest value, each as the generic block at that type does; the plain
// CTU stays at INT and saturates at 32767.
TEST(StVmBuiltins, TypedCountersAreTheGenericCounterAtTheirType) {
  auto r = run_program(
      "up : CTU_DINT; down : CTD_LINT; both : CTUD_UDINT; big : CTUD_ULINT; small : CTU;\n"
      "pulse : BOOL; first : BOOL := TRUE; load : BOOL;",
      "pulse := NOT pulse;\n"
      "up(CU := pulse, PV := 40000);\n"
      "down(CD := pulse, LD := load, PV := LINT#-9000000000);\n"
      "both(CD := pulse, PV := UDINT#7);\n"
      "big(CU := pulse, LD := first, PV := ULINT#18446744073709551613);\n"
      "small(CU := pulse, PV := 100);\n"
      "first := FALSE;");
  ASSERT_TRUE(r->ok()) << r->errors[0];
  r->scan(2 * 40000);  // 40,000 rising edges
  EXPECT_EQ(r->get<std::int32_t>("up.CV"), 40000);
  EXPECT_TRUE(r->get<bool>("up.Q"));
  EXPECT_EQ(r->get<std::int64_t>("down.CV"), -40000);
  EXPECT_EQ(r->get<std::uint32_t>("both.CV"), 0u) << "an unsigned count stops at 0";
  EXPECT_TRUE(r->get<bool>("both.QD"));
  EXPECT_EQ(r->get<std::uint64_t>("big.CV"), 18446744073709551615ull) << "no wrap past the type's largest";
  EXPECT_TRUE(r->get<bool>("big.QU"));
  EXPECT_EQ(r->get<std::int16_t>("small.CV"), 32767) << "CTU is at INT";
  r->set<bool>("load", true);
  r->scan();
  EXPECT_EQ(r->get<std::int64_t>("down.CV"), -9000000000);
  StRun sint({"PROGRAM Main\nVAR c : CTU_SINT; END_VAR\nc();\nEND_PROGRAM\n"}, "Main");
  ASSERT_FALSE(sint.errors.empty()) << "table 45 has no CTU_SINT";
  EXPECT_EQ(sint.errors[0], "t0.st:2:9: unknown type 'CTU_SINT' (did you mean CTU_DINT?)");
}

// An element of an array of FBs by an index out of bounds is the zeroed
// scratch area: a call of it does nothing (the index's fault is raised), on
// both engines, whatever the FB holds (a built-in block's pointer there is
// null; before, the call crashed the runtime).
TEST(StVmBuiltins, CallingAnFbArrayElementOutOfBoundsDoesNothingButFault) {
  const std::string src = R"(
FUNCTION_BLOCK Cell
VAR_INPUT go : BOOL; END_VAR
VAR_OUTPUT done : BOOL; END_VAR
VAR t : TON; n : DINT; END_VAR
t(IN := go, PT := T#20ms);
done := t.Q;
n := n + 1;
END_FUNCTION_BLOCK

PROGRAM Main
VAR
  ts : ARRAY[1..3] OF TON;
  cells : ARRAY[1..2] OF Cell;
  k : INT := 5;
  q, d : BOOL;
END_VAR
ts[k](IN := TRUE, PT := T#10ms);
q := ts[k].Q;
cells[k](go := TRUE);
d := cells[k].done;
cells[1](go := TRUE);
END_PROGRAM
)";
  for (vm::Engine engine : {vm::Engine::Native, vm::Engine::Interpreter}) {
    StRun r({src}, "Main", 10'000'000, engine);
    ASSERT_TRUE(r.ok()) << r.errors[0];
    r.scan(4);
    EXPECT_FALSE(r.get<bool>("q"));
    EXPECT_FALSE(r.get<bool>("d"));
    EXPECT_EQ(r.get<std::int32_t>("cells[1].n"), 4) << "the element in bounds runs";
    EXPECT_TRUE(r.get<bool>("cells[1].done"));
    const auto faults = r.fault_texts();
    ASSERT_FALSE(faults.empty());
    EXPECT_NE(faults[0].find("out of bounds"), std::string::npos) << faults[0];
  }
}

}  // namespace vm_builtins
}  // namespace syncplc::st::testing
