// The instructions and code shapes added for speed (docs/benchmarks.md
// section 17) keep the semantics of what they replace: FOR_INC (a FOR with
// the step 1), LDX/STX typed by the index, MULADD/ADDMUL/MULSUB/SUBMUL (a
// product and a sum or difference, each rounded), conditions compiled to
// jumps, jumps to jumps threaded, and string results written straight into
// the assigned variable. Each test also checks that the code generator used
// the new form, so it tests that form.
#include <cmath>
#include <limits>

#include "runtime/st/vm/listing.hpp"
#include "runtime/st/vm/st_string.hpp"
#include "tests/st/vm_fixture.hpp"

namespace syncplc::st::testing {
namespace vm_fused {

using vm::Op;

int count_op(const StRun& r, Op op, const std::string& pou = "Main") {
  int n = 0;
  for (const vm::Insn& i : r.module->pous[static_cast<std::size_t>(r.module->find(pou))].code) n += i.op == op;
  return n;
}

TEST(StVmFused, ForWithStepOneRunsToTheTypesLastValueWithoutWrapping) {
  auto r = run_program("b : SINT; u : USINT; q : ULINT; i : INT; nb, nu, nq, ne, n2 : DINT;",
                       "FOR b := 125 TO 127 DO nb := nb + 1; END_FOR;"
                       "FOR u := 253 TO 255 BY 1 DO nu := nu + 1; END_FOR;"
                       "FOR q := 16#FFFFFFFFFFFFFFFD TO 16#FFFFFFFFFFFFFFFF DO nq := nq + 1; END_FOR;"
                       "FOR i := 5 TO 4 DO ne := ne + 1; END_FOR;"
                       "FOR i := 0 TO 10 BY 2 DO n2 := n2 + 1; END_FOR;");
  ASSERT_TRUE(r->ok());
  EXPECT_EQ(count_op(*r, Op::FOR_INC_I8), 1);
  EXPECT_EQ(count_op(*r, Op::FOR_INC_U8), 1);  // BY 1 written
  EXPECT_EQ(count_op(*r, Op::FOR_INC_U64), 1);
  EXPECT_EQ(count_op(*r, Op::FOR_INC_I16), 1);
  EXPECT_EQ(count_op(*r, Op::FOR_NEXT_I16), 1);  // BY 2
  ASSERT_TRUE(r->scan());
  EXPECT_EQ(r->get<std::int32_t>("nb"), 3);
  EXPECT_EQ(r->get<std::int8_t>("b"), 127);
  EXPECT_EQ(r->get<std::int32_t>("nu"), 3);
  EXPECT_EQ(r->get<std::uint8_t>("u"), 255);
  EXPECT_EQ(r->get<std::int32_t>("nq"), 3);
  EXPECT_EQ(r->get<std::uint64_t>("q"), std::numeric_limits<std::uint64_t>::max());
  EXPECT_EQ(r->get<std::int32_t>("ne"), 0);
  EXPECT_EQ(r->get<std::int32_t>("n2"), 6);
}

TEST(StVmFused, ForWithStepOneCountsEveryBackwardJumpAgainstTheBudget) {
  // 11 iterations, 10 backward jumps.
  const std::string body = "n := 0;\nFOR i := 0 TO 10 DO\n  n := n + 1;\nEND_FOR;\nafter := TRUE;";
  auto ok = run_program("i : INT; n : DINT; after : BOOL;", body);
  ASSERT_TRUE(ok->ok());
  ok->budget = 10;
  EXPECT_TRUE(ok->scan());
  EXPECT_EQ(ok->get<std::int32_t>("n"), 11);
  auto stopped = run_program("i : INT; n : DINT; after : BOOL;", body);
  stopped->budget = 9;
  EXPECT_FALSE(stopped->scan());
  EXPECT_STREQ(stopped->instance->stopped(), "loop stopped: the scan's loop budget is spent at t0.st:6:1");
  EXPECT_EQ(stopped->get<std::int32_t>("n"), 10);
  EXPECT_FALSE(stopped->get<bool>("after"));
}

TEST(StVmFused, TheBudgetCountsOnThroughCallsOfBlocksAndFunctions) {
  // Main: 2 backward jumps of its own; three calls of Inner (9 each) and
  // three of Count (4 each): 2 + 27 + 12 = 41 in all.
  const std::string before =
      "FUNCTION_BLOCK Inner\nVAR i : INT; n : DINT; END_VAR\nFOR i := 0 TO 9 DO n := n + 1; END_FOR;\n"
      "END_FUNCTION_BLOCK\nFUNCTION Count : DINT\nVAR j : INT; END_VAR\nFOR j := 1 TO 5 DO Count := Count + j; "
      "END_FOR;\nEND_FUNCTION";
  for (const std::int64_t budget : {41, 40}) {
    auto r = run_program("k : INT; b : Inner; s : DINT; after : BOOL;",
                         "FOR k := 1 TO 3 DO b(); s := s + Count(); END_FOR; after := TRUE;", before);
    ASSERT_TRUE(r->ok());
    r->budget = budget;
    EXPECT_EQ(r->scan(), budget == 41);
    EXPECT_EQ(r->get<bool>("after"), budget == 41);
    if (budget == 41) {
      EXPECT_EQ(r->get<std::int32_t>("s"), 45);
    }
  }
}

TEST(StVmFused, IndexesOfEveryIntegerTypeAreCheckedAndFaultAtTheirSite) {
  auto r = run_program("a : ARRAY[-2..2] OF INT := [1, 2, 3, 4, 5]; s : SINT; us : USINT; ud : UDINT; l : LINT;"
                       "ul : ULINT; x1, x2, x3, x4, x5, x6 : INT := 77;",
                       "s := -2; x1 := a[s]; s := 3; x2 := a[s];\n"
                       "us := 255; x3 := a[us]; ud := 2; a[ud] := 50;\n"
                       "l := -3; a[l] := 60; x4 := a[l];\n"
                       "ul := 16#FFFFFFFFFFFFFFFF; x5 := a[ul]; a[ul] := 70; ul := 1; x6 := a[ul];");
  ASSERT_TRUE(r->ok());
  EXPECT_EQ(count_op(*r, Op::LDX_I8), 2);
  EXPECT_EQ(count_op(*r, Op::LDX_U8), 1);
  EXPECT_EQ(count_op(*r, Op::STX_U32), 1);
  EXPECT_EQ(count_op(*r, Op::STX_I64), 1);
  EXPECT_EQ(count_op(*r, Op::LDX_U64), 2);
  EXPECT_EQ(count_op(*r, Op::STX_U64), 1);
  r->scan();
  EXPECT_EQ(r->get<std::int16_t>("x1"), 1);
  EXPECT_EQ(r->get<std::int16_t>("x2"), 0);  // out of bounds: 0
  EXPECT_EQ(r->get<std::int16_t>("x3"), 0);
  EXPECT_EQ(r->get<std::int16_t>("a[2]"), 50);
  EXPECT_EQ(r->get<std::int16_t>("x4"), 0);
  EXPECT_EQ(r->get<std::int16_t>("x5"), 0);  // 2^64 - 1 is no -1
  EXPECT_EQ(r->get<std::int16_t>("x6"), 4);
  for (int k = -2; k <= 1; ++k) EXPECT_EQ(r->get<std::int16_t>("a[" + std::to_string(k) + "]"), k + 3);
  const auto f = r->fault_texts();
  ASSERT_EQ(f.size(), 6u);
  EXPECT_EQ(f[0], "array index out of bounds (-2..2) at t0.st:5:38");
  EXPECT_EQ(f[1], "array index out of bounds (-2..2) at t0.st:6:20");
  EXPECT_EQ(f[2], "array index out of bounds (-2..2) at t0.st:7:12");  // the write, dropped
  EXPECT_EQ(f[3], "array index out of bounds (-2..2) at t0.st:7:30");
  EXPECT_EQ(f[4], "array index out of bounds (-2..2) at t0.st:8:36");
  EXPECT_EQ(f[5], "array index out of bounds (-2..2) at t0.st:8:43");
}

TEST(StVmFused, MultiplyAddRoundsTheProductAsMulThenAddDo) {
  auto r = run_program(
      "a, b, c, x, y, v, s1, s2 : LREAL; fa, fb, fc, fx : REAL; i, j, k1, k2 : SINT; d, e : DINT;",
      "a := 1.0 + 2.0 ** -30; b := 1.0 - 2.0 ** -30; c := -1.0;"
      "x := a * b + c; y := c + a * b;"  // a * b is 1 - 2^-60, which rounds to 1: 0, where an FMA gives -2^-60
      "fa := REAL#1.0 + REAL#2.0 ** REAL#-13; fb := REAL#1.0 - REAL#2.0 ** REAL#-13; fc := REAL#-1.0;"
      "fx := fa * fb + fc;"  // rounded in REAL: 0 (in LREAL, 1 - 2^-26 is exact)
      "i := SINT#100; j := i * SINT#2 + SINT#100;"  // 200 wraps to -56, then 44
      "d := 65536; e := d * d + 5;"             // 2^32 wraps to 0
      "v := 3.0; v := v * 2.0 + v;"             // the destination is an operand
      "s1 := a * b - 1.0; s2 := 1.0 - a * b;"   // 0 both, where an FMA gives -+2^-60
      "i := SINT#-100; k1 := i * SINT#2 - SINT#100; k2 := SINT#100 - i * SINT#2;");  // -200 -> 56: -44; 44
  ASSERT_TRUE(r->ok());
  EXPECT_EQ(count_op(*r, Op::MULADD_F64), 2);
  EXPECT_EQ(count_op(*r, Op::ADDMUL_F64), 1);
  EXPECT_EQ(count_op(*r, Op::MULADD_F32), 1);
  EXPECT_EQ(count_op(*r, Op::MULADD_I8), 1);
  EXPECT_EQ(count_op(*r, Op::MULADD_I32), 1);
  EXPECT_EQ(count_op(*r, Op::MULSUB_F64), 1);
  EXPECT_EQ(count_op(*r, Op::SUBMUL_F64), 1);
  EXPECT_EQ(count_op(*r, Op::MULSUB_I8), 1);
  EXPECT_EQ(count_op(*r, Op::SUBMUL_I8), 1);
  r->scan();
  EXPECT_EQ(r->get<double>("x"), 0.0);
  EXPECT_FALSE(std::signbit(r->get<double>("x")));
  EXPECT_EQ(r->get<double>("y"), 0.0);
  EXPECT_EQ(r->get<float>("fx"), 0.0f);
  EXPECT_EQ(r->get<std::int8_t>("j"), 44);
  EXPECT_EQ(r->get<std::int32_t>("e"), 5);
  EXPECT_EQ(r->get<double>("v"), 9.0);
  EXPECT_EQ(r->get<double>("s1"), 0.0);
  EXPECT_EQ(r->get<double>("s2"), 0.0);
  EXPECT_EQ(r->get<std::int8_t>("k1"), -44);
  EXPECT_EQ(r->get<std::int8_t>("k2"), 44);
}

TEST(StVmFused, MultiplyAddEvaluatesItsOperandsInTheOrderWritten) {
  const std::string tick =
      "FUNCTION Tick : LREAL\nVAR_INPUT k : DINT; END_VAR\nVAR_IN_OUT log : DINT; END_VAR\n"
      "log := log * 10 + k; Tick := DINT_TO_LREAL(k);\nEND_FUNCTION";
  // w: l3 (a DINT, widened to LREAL) is read after the product's calls changed it, as ADD reads it.
  auto r = run_program("x, y, w : LREAL; l1, l2, l3 : DINT;",
                       "x := Tick(1, l1) * Tick(2, l1) + Tick(3, l1); y := Tick(1, l2) + Tick(2, l2) * Tick(3, l2);"
                       "l3 := 4; w := l3 + Tick(5, l3) * 2.0;",
                       tick);
  ASSERT_TRUE(r->ok());
  EXPECT_EQ(count_op(*r, Op::MULADD_F64), 1);
  EXPECT_EQ(count_op(*r, Op::ADDMUL_F64), 2);
  EXPECT_EQ(count_op(*r, Op::MULADD_I32, "Tick"), 1);
  r->scan();
  EXPECT_EQ(r->get<std::int32_t>("l1"), 123);
  EXPECT_EQ(r->get<std::int32_t>("l2"), 123);
  EXPECT_EQ(r->get<double>("x"), 5.0);
  EXPECT_EQ(r->get<double>("y"), 7.0);
  EXPECT_EQ(r->get<std::int32_t>("l3"), 45);
  EXPECT_EQ(r->get<double>("w"), 55.0);  // 45 + 5 * 2
}

TEST(StVmFused, ConditionsAsJumpsGiveTheValuesOfTheirExpressions) {
  // Each condition both ways: as IF (jumps) and as a BOOL value (AND/OR/NOT).
  const char* const conds[] = {"a AND b",         "a OR b",           "NOT a",
                               "a AND NOT b",     "NOT (a AND b)",    "a OR b AND c",
                               "(a OR b) AND c",  "NOT (a OR NOT c)", "a AND n > 2 OR NOT b AND n <> 5",
                               "NOT (n < 3) AND c"};
  std::string vars = "a, b, c : BOOL; n : INT; ";
  std::string body;
  for (std::size_t k = 0; k < std::size(conds); ++k) {
    const std::string i = std::to_string(k);
    vars += "j" + i + ", v" + i + ", w" + i + " : BOOL; r" + i + " : INT; ";
    body += "IF " + std::string(conds[k]) + " THEN j" + i + " := TRUE; ELSE j" + i + " := FALSE; END_IF;\n";
    body += "v" + i + " := " + conds[k] + ";\n";
    body += "w" + i + " := FALSE; WHILE (" + conds[k] + ") AND NOT w" + i + " DO w" + i + " := TRUE; END_WHILE;\n";
    body += "r" + i + " := 0; REPEAT r" + i + " := r" + i + " + 1; UNTIL (" + conds[k] + ") OR r" + i + " >= 2 END_REPEAT;\n";
  }
  auto r = run_program(vars, body);
  ASSERT_TRUE(r->ok());
  for (int bits = 0; bits < 16; ++bits) {
    r->set<bool>("a", bits & 1);
    r->set<bool>("b", bits & 2);
    r->set<bool>("c", bits & 4);
    r->set<std::int16_t>("n", (bits & 8) ? 5 : 2);
    ASSERT_TRUE(r->scan());
    for (std::size_t k = 0; k < std::size(conds); ++k) {
      const std::string i = std::to_string(k);
      const bool v = r->get<bool>("v" + i);
      EXPECT_EQ(r->get<bool>("j" + i), v) << conds[k] << " with " << bits;
      EXPECT_EQ(r->get<bool>("w" + i), v) << conds[k] << " with " << bits;
      EXPECT_EQ(r->get<std::int16_t>("r" + i), v ? 1 : 2) << conds[k] << " with " << bits;
      EXPECT_EQ(r->cell("j" + i)->raw, v ? 1u : 0u);
    }
  }
  EXPECT_EQ(r->fault_texts().size(), 0u);
}

TEST(StVmFused, ARightOperandThatCanFaultOrWriteIsStillEvaluated) {
  const std::string tick =
      "FUNCTION Tick : BOOL\nVAR_INPUT k : DINT; END_VAR\nVAR_IN_OUT log : DINT; END_VAR\n"
      "log := log * 10 + k; Tick := TRUE;\nEND_FUNCTION";
  auto r = run_program("off : BOOL; on : BOOL := TRUE; zero, k, log : DINT; arr : ARRAY[0..3] OF DINT; hit : DINT; "
                       "nan, z : LREAL; ok : BOOL;",
                       "k := 9;\n"
                       "IF off AND 10 / zero > 1 THEN hit := hit + 1; END_IF;\n"
                       "IF on OR arr[k] > 0 THEN hit := hit + 10; END_IF;\n"
                       "IF off AND Tick(7, log) THEN hit := hit + 100; END_IF;\n"
                       "nan := z / z; IF NOT (nan < 1.0) THEN ok := TRUE; END_IF;",
                       tick);
  ASSERT_TRUE(r->ok());
  r->scan();
  EXPECT_EQ(r->get<std::int32_t>("hit"), 10);
  EXPECT_EQ(r->get<std::int32_t>("log"), 7);  // Tick ran
  EXPECT_TRUE(r->get<bool>("ok"));            // NOT (NaN < 1.0) is TRUE
  const auto f = r->fault_texts();
  ASSERT_EQ(f.size(), 2u);
  EXPECT_EQ(f[0], "division by zero at t0.st:11:15");
  EXPECT_EQ(f[1], "array index out of bounds (0..3) at t0.st:12:14");
}

TEST(StVmFused, SkippableRightOperandsCostNoLogicInstructions) {
  auto r = run_program("a, b, c, x : BOOL; n : INT;",
                       "IF a AND NOT b THEN x := TRUE; END_IF; IF NOT a OR n > 3 AND c THEN x := FALSE; END_IF;");
  ASSERT_TRUE(r->ok());
  EXPECT_EQ(count_op(*r, Op::AND), 0) << vm::listing(*r->module, 0);
  EXPECT_EQ(count_op(*r, Op::OR), 0);
  EXPECT_EQ(count_op(*r, Op::NOT_BOOL), 0);
}

TEST(StVmFused, JumpsToJumpsGoStraightToTheirEnd) {
  auto r = run_program("k, n : INT; a, b : BOOL; x : DINT;",
                       "x := 0;\n"
                       "CASE k OF\n"
                       "  0: IF a THEN IF b THEN x := 1; ELSE x := 2; END_IF; ELSIF b THEN x := 3; ELSE x := 4; END_IF;\n"
                       "  1: WHILE n < 3 DO IF a THEN n := n + 1; ELSE n := n + 2; END_IF; END_WHILE; x := n;\n"
                       "ELSE\n"
                       "  IF a THEN x := 5; ELSIF b THEN x := 6; END_IF;\n"
                       "END_CASE;");
  ASSERT_TRUE(r->ok());
  const auto& code = r->instance->pou().code;
  for (std::size_t k = 0; k < code.size(); ++k)
    if (code[k].op == Op::JMP || code[k].op == Op::JZ || code[k].op == Op::JNZ) {
      EXPECT_NE(code[code[k].d].op, Op::JMP) << k << "\n" << vm::listing(*r->module, 0);
    }
  const int expected[3][4] = {{4, 2, 3, 1}, {4, 3, 4, 3}, {0, 5, 6, 5}};  // [k][a + 2b]
  for (int k = 0; k < 3; ++k)
    for (int ab = 0; ab < 4; ++ab) {
      r->set<std::int16_t>("k", static_cast<std::int16_t>(k));
      r->set<std::int16_t>("n", 0);
      r->set<bool>("a", ab & 1);
      r->set<bool>("b", ab & 2);
      ASSERT_TRUE(r->scan());
      EXPECT_EQ(r->get<std::int32_t>("x"), expected[k][ab]) << k << " " << ab;
    }
}

TEST(StVmFused, StringResultsGoStraightIntoTheVariableUnlessItIsAnOperand) {
  auto r = run_program("s : STRING[80] := 'abc'; t : STRING[80] := 'a longer text that was here before';"
                       "u : STRING[80]; w : STRING[80]; k : INT := -42; v : STRING[5]; p : STRING[80] := 'p';",
                       "s := CONCAT(s, '-', s); t := LEFT(t, 2); u := CONCAT('x', t); u := MID(u, 2, 2);"
                       "w := INT_TO_STRING(k); v := CONCAT(s, s); p := CONCAT(p, 'q');");
  ASSERT_TRUE(r->ok());
  r->scan();
  EXPECT_EQ(r->str("s"), "abc-abc");
  EXPECT_EQ(r->str("t"), "a ");
  EXPECT_EQ(r->str("u"), "a ");
  EXPECT_EQ(r->str("w"), "-42");
  EXPECT_EQ(r->str("p"), "pq");
  EXPECT_EQ(r->str("v"), "abc-a");  // cut, one fault
  // Zeros after the length (what was there before is gone).
  const Cell* t = r->cell("t");
  for (int c = 1; c < vm::string_cells(80, false); ++c) EXPECT_EQ(t[c].raw, c == 1 ? 0x2061u : 0u) << c;
  ASSERT_EQ(r->fault_texts().size(), 1u);
}

// The clamping IF is one CLAMP; the IFs that only look like it are not, and
// every one gives what the IF says, NaN and crossed bounds too.
TEST(StVmFused, TheClampingIfIsOneInstructionWithTheIfsResults) {
  const std::string decls =
      "x, y, z, w, v, lo, hi : LREAL; n, m : INT; flag : BOOL; px, py, pz, pw, pv : LREAL; pn : INT;";
  const std::string body =
      "IF x > hi THEN x := hi; ELSIF x < lo THEN x := lo; END_IF;\n"       // CLAMP, upper first
      "IF y < lo THEN y := lo; ELSIF y > hi THEN y := hi; END_IF;\n"       // CLAMP, lower first
      "IF n > 100 THEN n := 100; ELSIF n < -5 THEN n := -5; END_IF;\n"     // CLAMP_I16 on constants
      "IF z > hi THEN z := lo; ELSIF z < lo THEN z := hi; END_IF;\n"       // not: the bounds swapped
      "IF w > hi THEN w := hi; ELSIF w < lo THEN w := lo; ELSE flag := TRUE; END_IF;\n"  // not: an ELSE
      "IF v > hi THEN v := hi; ELSIF x < lo THEN v := lo; END_IF;\n"       // not: another variable tested
      "IF m > 100 THEN m := 99; ELSIF m < 0 THEN m := 0; END_IF;\n";       // not: another constant assigned
  auto r = run_program(decls, body);
  ASSERT_TRUE(r->ok());
  EXPECT_EQ(count_op(*r, Op::CLAMP_F64), 2);
  EXPECT_EQ(count_op(*r, Op::CLAMP_I16), 1);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  // The IF's result, for each order.
  auto upper_first = [](double x, double lo, double hi) { return x > hi ? hi : (x < lo ? lo : x); };
  auto lower_first = [](double x, double lo, double hi) { return x < lo ? lo : (x > hi ? hi : x); };
  for (const double lo : {-1.0, 0.0, 2.0, nan})
    for (const double hi : {-2.0, 1.0, 2.0, nan})
      for (const double x : {-3.0, -1.0, 0.5, 1.0, 1.5, 3.0, nan}) {
        r->set<double>("lo", lo);
        r->set<double>("hi", hi);
        for (const char* name : {"x", "y", "z", "w", "v"}) r->set<double>(name, x);
        r->set<bool>("flag", false);
        ASSERT_TRUE(r->scan());
        auto same = [](double a, double b) { return (std::isnan(a) && std::isnan(b)) || a == b; };
        const std::string at = " for x " + std::to_string(x) + ", lo " + std::to_string(lo) + ", hi " + std::to_string(hi);
        EXPECT_TRUE(same(r->get<double>("x"), upper_first(x, lo, hi))) << "x" << at;
        EXPECT_TRUE(same(r->get<double>("y"), lower_first(x, lo, hi))) << "y" << at;
        EXPECT_TRUE(same(r->get<double>("z"), x > hi ? lo : (x < lo ? hi : x))) << "z" << at;
        EXPECT_TRUE(same(r->get<double>("w"), upper_first(x, lo, hi))) << "w" << at;
        // v's second test reads x, as the first statement left it.
        const double x1 = upper_first(x, lo, hi);
        EXPECT_TRUE(same(r->get<double>("v"), x > hi ? hi : (x1 < lo ? lo : x))) << "v" << at;
        EXPECT_EQ(r->get<bool>("flag"), !(x > hi) && !(x < lo)) << at;
      }
  // In a FUNCTION's frame, on REAL and on an unsigned type, and with a bound that is x itself.
  auto f = run_program("a : REAL; u : UDINT; k : LREAL; lo2, hi2 : LREAL;",
                       "a := Clip(a); IF u > 10 THEN u := 10; ELSIF u < 3 THEN u := 3; END_IF;\n"
                       "IF k > k THEN k := k; ELSIF k < lo2 THEN k := lo2; END_IF;",
                       "FUNCTION Clip : REAL\nVAR_INPUT v : REAL; END_VAR\n"
                       "IF v > 1.5 THEN v := 1.5; ELSIF v < -1.5 THEN v := -1.5; END_IF;\nClip := v;\nEND_FUNCTION");
  ASSERT_TRUE(f->ok());
  EXPECT_EQ(count_op(*f, Op::CLAMP_F32, "Clip"), 1);
  EXPECT_EQ(count_op(*f, Op::CLAMP_U32), 1);
  EXPECT_EQ(count_op(*f, Op::CLAMP_F64), 1);
  for (const float a : {-3.0f, -1.5f, 0.25f, 1.5f, 7.0f}) {
    f->set<float>("a", a);
    f->set<std::uint32_t>("u", static_cast<std::uint32_t>(a + 4.0f));
    f->set<double>("k", a);
    f->set<double>("lo2", 0.0);
    ASSERT_TRUE(f->scan());
    EXPECT_EQ(f->get<float>("a"), a > 1.5f ? 1.5f : (a < -1.5f ? -1.5f : a));
    const std::uint32_t u = static_cast<std::uint32_t>(a + 4.0f);
    EXPECT_EQ(f->get<std::uint32_t>("u"), u > 10 ? 10u : (u < 3 ? 3u : u));
    EXPECT_EQ(f->get<double>("k"), a < 0 ? 0.0 : a);
  }
  for (const std::int16_t n : {-32768, -6, -5, 0, 100, 101, 32767}) {
    r->set<std::int16_t>("n", n);
    r->set<std::int16_t>("m", n);
    ASSERT_TRUE(r->scan());
    EXPECT_EQ(r->get<std::int16_t>("n"), n > 100 ? 100 : (n < -5 ? -5 : n));
    EXPECT_EQ(r->get<std::int16_t>("m"), n > 100 ? 99 : (n < 0 ? 0 : n));
  }
}

}  // namespace vm_fused
}  // namespace syncplc::st::testing
