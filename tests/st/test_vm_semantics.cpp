// The semantics of compiled ST, run by the VM: precedence, integer wrap,
// division and MOD signs, conversions, durations, CASE, FOR, loops, calls,
// FB state across scans, and the defined results of faults.
#include <cmath>

#include "tests/st/vm_fixture.hpp"

namespace syncplc::st::testing {
namespace vm_semantics {

TEST(StVm, PrecedenceAndIntegerArithmetic) {
  auto r = run_program("a, b, e, f : DINT; c, d : BOOL; x : LREAL;",
                       "a := 2 + 3 * 4; b := (2 + 3) * 4; c := 2 ** 3 > 7.0 AND TRUE; d := -2 ** 2 > 0.0;"
                       "e := 7 - 2 - 1; f := 100 / 10 / 5; x := 1.0 + 2.0 * 3.0 ** 2.0;");
  ASSERT_TRUE(r->ok());
  r->scan();
  EXPECT_EQ(r->get<std::int32_t>("a"), 14);
  EXPECT_EQ(r->get<std::int32_t>("b"), 20);
  EXPECT_TRUE(r->get<bool>("c"));
  EXPECT_TRUE(r->get<bool>("d"));  // unary minus binds tighter than '**' (IEC table 71): (-2)**2
  EXPECT_EQ(r->get<std::int32_t>("e"), 4);
  EXPECT_EQ(r->get<std::int32_t>("f"), 2);
  EXPECT_DOUBLE_EQ(r->get<double>("x"), 19.0);
}

TEST(StVm, IntegerOverflowWrapsInTheVariablesType) {
  auto r = run_program("i : INT := 32767; s : SINT := -128; u : USINT := 255; d : DINT := 2147483647;"
                       "w : UINT; l : LINT := 9223372036854775807; m : INT := -32768; n : INT;",
                       "i := i + 1; s := s - 1; u := u + 1; d := d * 2; w := w - 1; l := l + 1; n := -m;"
                       "m := m / -1;");
  ASSERT_TRUE(r->ok());
  r->scan();
  EXPECT_EQ(r->get<std::int16_t>("i"), -32768);
  EXPECT_EQ(r->get<std::int8_t>("s"), 127);
  EXPECT_EQ(r->get<std::uint8_t>("u"), 0);
  EXPECT_EQ(r->get<std::int32_t>("d"), -2);
  EXPECT_EQ(r->get<std::uint16_t>("w"), 65535);
  EXPECT_EQ(r->get<std::int64_t>("l"), INT64_MIN);
  EXPECT_EQ(r->get<std::int16_t>("n"), -32768);
  EXPECT_EQ(r->get<std::int16_t>("m"), -32768);
  // The cells keep their high bytes zero (the runtime's Cell layout).
  EXPECT_EQ(r->cell("i")->raw, 0x8000u);
  EXPECT_EQ(r->cell("s")->raw, 0x7Fu);
}

TEST(StVm, DivisionAndModTruncateTowardZero) {
  auto r = run_program("a, b, c, d, e, f, g, h : DINT;",
                       "a := 7 / 2; b := -7 / 2; c := 7 / -2; d := 7 MOD 3; e := -7 MOD 3; f := 7 MOD -3;"
                       "g := -7 MOD -3; h := 5;");
  ASSERT_TRUE(r->ok());
  r->scan();
  EXPECT_EQ(r->get<std::int32_t>("a"), 3);
  EXPECT_EQ(r->get<std::int32_t>("b"), -3);
  EXPECT_EQ(r->get<std::int32_t>("c"), -3);
  EXPECT_EQ(r->get<std::int32_t>("d"), 1);
  EXPECT_EQ(r->get<std::int32_t>("e"), -1);
  EXPECT_EQ(r->get<std::int32_t>("f"), 1);
  EXPECT_EQ(r->get<std::int32_t>("g"), -1);
}

TEST(StVm, DivisionByZeroGivesZeroAndAFaultAtItsLine) {
  auto r = run_program("a : DINT := 10; z : DINT; q, m : DINT := 99; x : LREAL := 1.0; y : LREAL;",
                       "q := a / z;\nm := a MOD z;\ny := x / 0.0;");
  ASSERT_TRUE(r->ok());
  r->scan();
  EXPECT_EQ(r->get<std::int32_t>("q"), 0);
  EXPECT_EQ(r->get<std::int32_t>("m"), 0);
  EXPECT_TRUE(std::isinf(r->get<double>("y")));  // IEC 60559
  const auto faults = r->fault_texts();
  ASSERT_EQ(faults.size(), 2u);
  EXPECT_EQ(faults[0], std::string("division by zero at t0.st:5:8"));
  EXPECT_EQ(faults[1], std::string("MOD by zero at t0.st:6:8"));
  r->scan();  // the scan goes on, scan after scan
  EXPECT_EQ(r->fault_texts().size(), 4u);
}

TEST(StVm, ImplicitWideningAndExplicitConversions) {
  auto r = run_program(
      "i : INT := -3; d : DINT; l : LINT; x : LREAL; re : REAL; u : UINT := 65535; ud : UDINT;"
      "a, b, c, e : INT; t : DINT; w : WORD; big : LREAL := 1.0E10; sat : INT;",
      "d := i; l := i; x := i; re := i; ud := u;"
      "a := LREAL_TO_INT(2.5); b := LREAL_TO_INT(-1.5); c := LREAL_TO_INT(3.5); e := LREAL_TRUNC_INT(-2.7);"
      "t := TRUNC(-2.7); w := INT_TO_WORD(i); sat := LREAL_TO_INT(big);");
  ASSERT_TRUE(r->ok()) << r->errors[0];
  r->scan();
  EXPECT_EQ(r->get<std::int32_t>("d"), -3);
  EXPECT_EQ(r->get<std::int64_t>("l"), -3);
  EXPECT_EQ(r->get<double>("x"), -3.0);
  EXPECT_EQ(r->get<float>("re"), -3.0f);
  EXPECT_EQ(r->get<std::uint32_t>("ud"), 65535u);
  EXPECT_EQ(r->get<std::int16_t>("a"), 2);   // ties to even
  EXPECT_EQ(r->get<std::int16_t>("b"), -2);
  EXPECT_EQ(r->get<std::int16_t>("c"), 4);
  EXPECT_EQ(r->get<std::int16_t>("e"), -2);  // toward zero
  EXPECT_EQ(r->get<std::int32_t>("t"), -2);
  EXPECT_EQ(r->get<std::uint16_t>("w"), 0xFFFDu);
  EXPECT_EQ(r->get<std::int16_t>("sat"), 32767);  // saturated, with a fault
  ASSERT_EQ(r->fault_texts().size(), 1u);
  EXPECT_NE(r->fault_texts()[0].find("LREAL_TO_INT: value out of range"), std::string::npos);
}

TEST(StVm, DurationArithmetic) {
  auto r = run_program("t : TIME := T#1s; a, b, c, d : TIME; n : DINT := 3; cmp : BOOL;",
                       "a := t + T#500ms; b := t * n; c := t / 4; d := t * 1.5; cmp := a > T#1s400ms;");
  ASSERT_TRUE(r->ok()) << r->errors[0];
  r->scan();
  EXPECT_EQ(r->get<std::int64_t>("a"), 1'500'000'000);
  EXPECT_EQ(r->get<std::int64_t>("b"), 3'000'000'000);
  EXPECT_EQ(r->get<std::int64_t>("c"), 250'000'000);
  EXPECT_EQ(r->get<std::int64_t>("d"), 1'500'000'000);
  EXPECT_TRUE(r->get<bool>("cmp"));
}

TEST(StVm, CaseWithListsRangesAndElse) {
  for (int sel : {1, 2, 3, 5, 7, 10, 42, -1}) {
    auto r = run_program("s : INT; out : INT;",
                         "CASE s OF 1: out := 10; 2, 3: out := 20; 5..7: out := 30; 10: out := 40; "
                         "ELSE out := -1; END_CASE;");
    ASSERT_TRUE(r->ok());
    r->set<std::int16_t>("s", static_cast<std::int16_t>(sel));
    r->scan();
    const int want = sel == 1 ? 10 : (sel == 2 || sel == 3) ? 20 : (sel >= 5 && sel <= 7) ? 30 : sel == 10 ? 40 : -1;
    EXPECT_EQ(r->get<std::int16_t>("out"), want) << sel;
  }
}

TEST(StVm, CaseOverEnumerationsAndSparseLabels) {
  auto r = run_program("c : Colour := Colour#Blue; k : DINT := 1000000; a, b : INT;",
                       "CASE c OF Red: a := 1; Green: a := 2; Blue: a := 3; END_CASE;"
                       "CASE k OF 1: b := 1; 1000000: b := 2; -5000000: b := 3; END_CASE;",
                       "TYPE Colour : (Red, Green, Blue); END_TYPE");
  ASSERT_TRUE(r->ok());
  r->scan();
  EXPECT_EQ(r->get<std::int16_t>("a"), 3);
  EXPECT_EQ(r->get<std::int16_t>("b"), 2);
}

TEST(StVm, ForLoopsCountUpDownAndNeverWrapPastTheEnd) {
  auto r = run_program("i : INT; s, n, m, k : DINT; b : SINT; c : INT;",
                       "FOR i := 1 TO 10 DO s := s + i; END_FOR;"
                       "FOR i := 10 TO 1 BY -3 DO n := n * 10 + i; END_FOR;"
                       "FOR i := 5 TO 1 DO m := m + 1; END_FOR;"
                       "FOR b := 120 TO 127 DO k := k + 1; END_FOR;"  // ends at 127 without wrapping
                       "FOR i := 1 TO 3 DO c := i; END_FOR;");
  ASSERT_TRUE(r->ok());
  ASSERT_TRUE(r->scan());
  EXPECT_EQ(r->get<std::int32_t>("s"), 55);
  EXPECT_EQ(r->get<std::int32_t>("n"), 10741);  // 10, 7, 4, 1
  EXPECT_EQ(r->get<std::int32_t>("m"), 0);
  EXPECT_EQ(r->get<std::int32_t>("k"), 8);
  EXPECT_EQ(r->get<std::int16_t>("c"), 3);
}

TEST(StVm, ExitAndContinueInNestedLoops) {
  auto r = run_program("i, j : INT; pairs, odd, w, rep : DINT;",
                       "FOR i := 1 TO 5 DO\n"
                       "  FOR j := 1 TO 5 DO IF j > i THEN EXIT; END_IF; pairs := pairs + 1; END_FOR;\n"
                       "END_FOR;\n"
                       "FOR i := 1 TO 10 DO IF i MOD 2 = 0 THEN CONTINUE; END_IF; odd := odd + 1; END_FOR;\n"
                       "WHILE TRUE DO w := w + 1; IF w >= 7 THEN EXIT; END_IF; END_WHILE;\n"
                       "REPEAT rep := rep + 2; UNTIL rep >= 9 END_REPEAT;");
  ASSERT_TRUE(r->ok());
  ASSERT_TRUE(r->scan());
  EXPECT_EQ(r->get<std::int32_t>("pairs"), 15);
  EXPECT_EQ(r->get<std::int32_t>("odd"), 5);
  EXPECT_EQ(r->get<std::int32_t>("w"), 7);
  EXPECT_EQ(r->get<std::int32_t>("rep"), 10);
}

TEST(StVm, ARunawayLoopIsStoppedByTheBudgetAtItsLine) {
  auto r = run_program("n : DINT; after : BOOL;", "n := n + 1;\nWHILE n > 0 DO\n  n := n + 1;\nEND_WHILE;\nafter := TRUE;");
  ASSERT_TRUE(r->ok());
  r->budget = 1000;
  EXPECT_FALSE(r->scan());
  EXPECT_STREQ(r->instance->stopped(), "loop stopped: the scan's loop budget is spent at t0.st:6:1");
  EXPECT_FALSE(r->get<bool>("after"));
  EXPECT_EQ(r->get<std::int32_t>("n"), 1002);  // deterministic: the same count on every run
}

TEST(StVm, ArrayIndexOutOfBoundsReadsZeroDropsTheWriteAndFaults) {
  auto r = run_program("a : ARRAY[1..5] OF DINT := [1, 2, 3, 4, 5]; m : ARRAY[0..2, 1..3] OF INT; i : INT := 6;"
                       "x, y : DINT := 77; j : INT := 2; k : INT := 3;",
                       "x := a[i];\na[i] := 9;\ny := a[j] + a[5];\nm[j, k] := 23;\nm[k, j] := 1;");
  ASSERT_TRUE(r->ok());
  r->scan();
  EXPECT_EQ(r->get<std::int32_t>("x"), 0);
  EXPECT_EQ(r->get<std::int32_t>("y"), 7);
  for (int k = 1; k <= 5; ++k) EXPECT_EQ(r->get<std::int32_t>("a[" + std::to_string(k) + "]"), k);
  EXPECT_EQ(r->get<std::int16_t>("m[2, 3]"), 23);
  const auto f = r->fault_texts();
  ASSERT_EQ(f.size(), 3u);
  EXPECT_EQ(f[0], "array index out of bounds (1..5) at t0.st:5:8");
  EXPECT_EQ(f[1], "array index out of bounds (1..5) at t0.st:6:3");
  EXPECT_EQ(f[2], "array index out of bounds (0..2) at t0.st:9:3");
}

TEST(StVm, SubrangeWritesAreClampedWithAFault) {
  auto r = run_program("p : Percent; v : INT := 150;", "p := v;", "TYPE Percent : INT (0..100); END_TYPE");
  ASSERT_TRUE(r->ok());
  r->scan();
  EXPECT_EQ(r->get<std::int16_t>("p"), 100);
  ASSERT_EQ(r->fault_texts().size(), 1u);
  EXPECT_EQ(r->fault_texts()[0], "value outside Percent at t0.st:6:1");
}

TEST(StVm, UserFunctionsWithInputsOutputsAndInOut) {
  const std::string src =
      "FUNCTION Scale : LREAL\nVAR_INPUT x : LREAL; k : LREAL := 2.0; END_VAR\nVAR_OUTPUT twice : LREAL; END_VAR\n"
      "Scale := x * k; twice := Scale * 2.0;\nEND_FUNCTION\n"
      "FUNCTION Bump : BOOL\nVAR_IN_OUT n : DINT; END_VAR\nn := n + 1; Bump := n > 2;\nEND_FUNCTION\n"
      "PROGRAM Main\nVAR a, b, c, d : LREAL; n : DINT; big : BOOL; END_VAR\n"
      "a := Scale(1.5); b := Scale(x := 1.0, k := 5.0, twice => c); d := Scale(Scale(1.0));\n"
      "big := Bump(n); big := Bump(n); big := Bump(n);\nEND_PROGRAM\n";
  StRun r({src}, "Main");
  ASSERT_TRUE(r.ok()) << r.errors[0];
  r.scan();
  EXPECT_EQ(r.get<double>("a"), 3.0);
  EXPECT_EQ(r.get<double>("b"), 5.0);
  EXPECT_EQ(r.get<double>("c"), 10.0);
  EXPECT_EQ(r.get<double>("d"), 4.0);
  EXPECT_EQ(r.get<std::int32_t>("n"), 3);
  EXPECT_TRUE(r.get<bool>("big"));
}

TEST(StVm, FunctionBlockInstancesKeepTheirStateAcrossScans) {
  const std::string src =
      "FUNCTION_BLOCK Counter\nVAR_INPUT up : BOOL; END_VAR\nVAR_OUTPUT count : DINT; END_VAR\n"
      "VAR last : BOOL; END_VAR\nVAR_TEMP edge : BOOL; END_VAR\n"
      "edge := up AND NOT last; last := up; IF edge THEN count := count + 1; END_IF;\nEND_FUNCTION_BLOCK\n"
      "FUNCTION_BLOCK Pair\nVAR_INPUT in : BOOL; END_VAR\nVAR a, b : Counter; END_VAR\n"
      "VAR_OUTPUT total : DINT; END_VAR\n a(up := in); b(up := NOT in); total := a.count * 100 + b.count;\n"
      "END_FUNCTION_BLOCK\n"
      "PROGRAM Main\nVAR p : Pair; many : ARRAY[1..3] OF Counter; t : DINT; k : INT; x : BOOL; END_VAR\n"
      "x := NOT x; p(in := x, total => t);\nFOR k := 1 TO 3 DO many[k](up := x AND k <> 2); END_FOR;\nEND_PROGRAM\n";
  StRun r({src}, "Main");
  ASSERT_TRUE(r.ok()) << r.errors[0];
  r.scan(6);
  EXPECT_EQ(r.get<std::int32_t>("p.a.count"), 3);
  EXPECT_EQ(r.get<std::int32_t>("p.b.count"), 3);  // the first scan's NOT x is FALSE: 3 edges of NOT x in 6 scans
  EXPECT_EQ(r.get<std::int32_t>("t"), 303);
  EXPECT_EQ(r.get<std::int32_t>("many[1].count"), 3);
  EXPECT_EQ(r.get<std::int32_t>("many[2].count"), 0);
  EXPECT_EQ(r.get<std::int32_t>("many[3].count"), 3);
}

TEST(StVm, BuiltInBlocksRunAsFunctionBlocksInVirtualTime) {
  auto r = run_program("t : TON; go : BOOL; done : BOOL; el : TIME; c : CTU; edge : R_TRIG; n : INT;",
                       "t(IN := go, PT := T#50ms, Q => done, ET => el);\n"
                       "edge(CLK := go); c(CU := edge.Q, R := FALSE, PV := 3); n := c.CV;");
  ASSERT_TRUE(r->ok()) << r->errors[0];
  r->scan(2);
  EXPECT_FALSE(r->get<bool>("done"));
  r->set<bool>("go", true);
  r->scan(5);  // 10 ms scans: 0, 10, 20, 30, 40 ms after the rising edge
  EXPECT_FALSE(r->get<bool>("done"));
  EXPECT_EQ(r->get<std::int64_t>("el"), 40'000'000);
  r->scan();
  EXPECT_TRUE(r->get<bool>("done"));
  EXPECT_EQ(r->get<std::int16_t>("n"), 1);
}

TEST(StVm, StringsAssignConcatCompareAndCut) {
  auto r = run_program("s : STRING[10]; t : STRING := 'abc'; l : INT; eq, lt : BOOL; p : INT; m : STRING[5];",
                       "s := CONCAT(t, '-', t, '-', t); l := LEN(s); eq := t = 'abc'; lt := 'abc' < 'abd';"
                       "p := FIND(s, 'c-a'); m := MID(s, 3, 2);");
  ASSERT_TRUE(r->ok()) << r->errors[0];
  r->scan();
  EXPECT_EQ(r->str("s"), "abc-abc-ab");  // cut to 10, with a fault
  EXPECT_EQ(r->get<std::int16_t>("l"), 10);
  EXPECT_TRUE(r->get<bool>("eq"));
  EXPECT_TRUE(r->get<bool>("lt"));
  EXPECT_EQ(r->get<std::int16_t>("p"), 3);
  EXPECT_EQ(r->str("m"), "bc-");  // MID(IN, L, P): L characters from position P
  EXPECT_FALSE(r->fault_texts().empty());
}

TEST(StVm, BitAccessShiftsAndLogic) {
  auto r = run_program("w : WORD := 16#00F0; b3, b4 : BOOL; s, ro : WORD; bt : BYTE := 16#81; nb : BYTE; x : BOOL;",
                       "b3 := w.3; b4 := w.4; w.0 := TRUE; w.4 := FALSE; s := SHL(w, 4); ro := ROL(WORD#16#8001, 1);"
                       "nb := NOT bt; x := b4 XOR b3 OR FALSE;");
  ASSERT_TRUE(r->ok()) << r->errors[0];
  r->scan();
  EXPECT_FALSE(r->get<bool>("b3"));
  EXPECT_TRUE(r->get<bool>("b4"));
  EXPECT_EQ(r->get<std::uint16_t>("w"), 0x00E1);
  EXPECT_EQ(r->get<std::uint16_t>("s"), 0x0E10);
  EXPECT_EQ(r->get<std::uint16_t>("ro"), 0x0003);
  EXPECT_EQ(r->get<std::uint8_t>("nb"), 0x7E);
  EXPECT_EQ(r->cell("nb")->raw, 0x7Eu);
  EXPECT_TRUE(r->get<bool>("x"));
}

TEST(StVm, StandardNumericFunctions) {
  auto r = run_program("a, b, c, d, e, f : LREAL; i, j, k, mx : INT; re : REAL; m : DINT;",
                       "a := ABS(-2.5); b := SQRT(16.0); c := EXPT(2.0, 10); d := LIMIT(0.0, 7.5, 5.0);"
                       "e := SEL(TRUE, 1.0, 2.0); f := MUX(2, 10.0, 20.0, 30.0); i := MIN(3, 1, 2); j := MAX(INT#3, 9);"
                       "k := ABS(INT#-32768); re := SQRT(REAL#2.0); m := MUX(5, 1, 2); mx := MAX(-1, -5);");
  ASSERT_TRUE(r->ok()) << r->errors[0];
  r->scan();
  EXPECT_EQ(r->get<double>("a"), 2.5);
  EXPECT_EQ(r->get<double>("b"), 4.0);
  EXPECT_EQ(r->get<double>("c"), 1024.0);
  EXPECT_EQ(r->get<double>("d"), 5.0);
  EXPECT_EQ(r->get<double>("e"), 2.0);
  EXPECT_EQ(r->get<double>("f"), 30.0);
  EXPECT_EQ(r->get<std::int16_t>("i"), 1);
  EXPECT_EQ(r->get<std::int16_t>("j"), 9);
  EXPECT_EQ(r->get<std::int16_t>("k"), -32768);  // wraps
  EXPECT_EQ(r->get<float>("re"), std::sqrt(2.0f));
  EXPECT_EQ(r->get<std::int32_t>("m"), 2);  // K outside 0..1: the nearest input, and a fault
  EXPECT_EQ(r->get<std::int16_t>("mx"), -1);
  ASSERT_EQ(r->fault_texts().size(), 1u);
}

TEST(StVm, StructsArraysAndInitialValues) {
  auto r = run_program("p : Point := (y := 2.5); ps : ARRAY[1..3] OF Point := [(x := 1.0), (x := 2.0)];"
                       "q : Point; arr : ARRAY[0..3] OF INT := [2(7), 9]; d : Distance; c : Colour; r : Percent;",
                       "q := p; q.x := q.x + ps[2].x;",
                       "TYPE Point : STRUCT x : LREAL := -1.0; y : LREAL; END_STRUCT; END_TYPE\n"
                       "TYPE Distance : LREAL := 1.5; END_TYPE\nTYPE Colour : (Red, Green) := Green; END_TYPE\n"
                       "TYPE Percent : INT (10..100); END_TYPE");
  ASSERT_TRUE(r->ok()) << r->errors[0];
  r->scan();
  EXPECT_EQ(r->get<double>("p.x"), -1.0);
  EXPECT_EQ(r->get<double>("p.y"), 2.5);
  EXPECT_EQ(r->get<double>("ps[3].x"), -1.0);
  EXPECT_EQ(r->get<double>("q.x"), 1.0);
  EXPECT_EQ(r->get<std::int16_t>("arr[1]"), 7);
  EXPECT_EQ(r->get<std::int16_t>("arr[2]"), 9);
  EXPECT_EQ(r->get<std::int16_t>("arr[3]"), 0);
  EXPECT_EQ(r->get<double>("d"), 1.5);
  EXPECT_EQ(r->get<std::int16_t>("c"), 1);
  EXPECT_EQ(r->get<std::int16_t>("r"), 10);
}

}  // namespace vm_semantics
}  // namespace syncplc::st::testing
