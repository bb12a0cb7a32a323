// The type checker's declaration, call and statement rules: names and
// suggestions, initial values, CONSTANT, FB instance calls, VAR_IN_OUT,
// CASE labels, FOR control variables, EXIT, and one error per mistake.
#include "tests/st/checker_fixture.hpp"

namespace syncplc::st {
namespace {

using testing::check_program;
using testing::check_source;
using testing::check_sources;

TEST(StCheckRules, DuplicateNamesAreFoundCaseInsensitively) {
  auto c = check_source(R"(TYPE Mode : (Auto, Manual); END_TYPE
FUNCTION_BLOCK MODE
END_FUNCTION_BLOCK
PROGRAM P
VAR speed : INT; SPEED : REAL; END_VAR
VAR_TEMP Speed : BOOL; END_VAR
END_PROGRAM)");
  EXPECT_EQ(c->errors(), (std::vector<std::string>{
                             "2:1: duplicate name 'MODE' (first declared at t0.st:1:6)",
                             "5:18: duplicate name 'SPEED' (first declared at t0.st:5:5)",
                             "6:10: duplicate name 'Speed' (first declared at t0.st:5:5)",
                         }));
}

TEST(StCheckRules, MisspeltNamesGetSuggestions) {
  auto c = check_program("motor_speed : INT; t : TON;", "motor_sped := 1;\nmotor_speed := motorspeed + 1;\nt(IN := TRUE, PTT := T#1s);",
                         "TYPE Recipe : STRUCT a : INT; END_STRUCT; END_TYPE\nPROGRAM Q VAR r : Recipie; x : LRAL; END_VAR END_PROGRAM");
  EXPECT_TRUE(c->has("2:19: unknown type 'Recipie' (did you mean Recipe?)")) << c->errors()[0];
  EXPECT_TRUE(c->has("2:32: unknown type 'LRAL' (did you mean LREAL?)")) << ::testing::PrintToString(c->errors());
  EXPECT_TRUE(c->has("7:1: unknown variable 'motor_sped' (did you mean motor_speed?)"));
  EXPECT_TRUE(c->has("8:16: unknown name 'motorspeed' (did you mean motor_speed?)"));
  EXPECT_TRUE(c->has("t (TON) has no input 'PTT' (did you mean PT?)"));
  EXPECT_EQ(c->errors().size(), 5u);
}

TEST(StCheckRules, OneMistakeGivesOneError) {
  // The unknown name poisons the expressions above it: no "expected LREAL, found <error>" follows.
  auto c = check_program("x : LREAL; i : INT; a : ARRAY[1..3] OF INT;",
                         "x := (nope + 1.5) * x / 2.0;\ni := a[nope] + LREAL_TO_INT(nope * 2.0);\nIF nope THEN x := nope.y; END_IF;");
  EXPECT_EQ(c->errors().size(), 5u);
  for (const auto& e : c->errors()) EXPECT_NE(e.find("unknown name 'nope'"), std::string::npos) << e;
}

TEST(StCheckRules, InitialValues) {
  auto ok = check_source(R"(TYPE Pt : STRUCT x, y : INT; END_STRUCT; END_TYPE
PROGRAM P
VAR
  p : Pt := (x := 1, y := 2);
  a : ARRAY[1..5] OF INT := [1, 2, 3(0)];
  ps : ARRAY[0..1] OF Pt := [(x := 1), (y := 2)];
  t : TON := (PT := T#1s);
  r : INT (0..10) := 5;
END_VAR
END_PROGRAM)");
  EXPECT_TRUE(ok->errors().empty()) << ok->errors()[0];
  auto bad = check_source(R"(TYPE Pt : STRUCT x, y : INT; END_STRUCT; END_TYPE
PROGRAM P
VAR
  p : Pt := (x := 1, z := 2);
  a : ARRAY[1..5] OF INT := [1, 2, 4(0)];
  i : INT := 1.5;
  r : INT (0..10) := 11;
  q : INT := i;
END_VAR
END_PROGRAM)");
  EXPECT_EQ(bad->errors(), (std::vector<std::string>{
                               "4:22: 'Pt' has no field 'z'",
                               "5:29: 6 initial values for an array of 5 elements",
                               "6:14: initial value: expected INT, found a real literal",
                               "7:22: initial value: value 11 is outside INT (0..10)",
                               "8:14: an initial value must be a constant expression",
                           }));
}

TEST(StCheckRules, ConstantsAreNotAssignable) {
  auto c = check_source(R"(PROGRAM P
VAR CONSTANT limit : INT := 10; END_VAR
VAR i : INT; END_VAR
limit := 5;
i := limit;
END_PROGRAM)");
  EXPECT_EQ(c->errors(), (std::vector<std::string>{"4:1: 'limit' is a CONSTANT and cannot be assigned"}));
}

const char* kMotor = R"(FUNCTION_BLOCK Motor
VAR_INPUT run : BOOL; speed : INT; END_VAR
VAR_OUTPUT running : BOOL; actual : INT; END_VAR
VAR internal : INT; END_VAR
running := run;
END_FUNCTION_BLOCK)";

TEST(StCheckRules, FbInstanceCallsAndOutputs) {
  auto ok = check_program("m : Motor; on : BOOL; v : DINT; t : TON;",
                          "m(run := TRUE, speed := 5, running => on);\nm(FALSE, 3);\nv := m.actual;\nm.speed := 7;\n"
                          "t(IN := m.running, PT := T#2s, Q => on);\nm(actual => v, NOT running => on);",
                          kMotor);
  EXPECT_TRUE(ok->errors().empty()) << ok->errors()[0];
  auto bad = check_program("m : Motor; on : BOOL; i : INT;",
                           "m.running := TRUE;\ni := m.internal;\nm(run := 1.5);\nm(running := on);\nm(speed => i);\n"
                           "on := m(run := TRUE);\nm(TRUE, 1, 2);\nm(actual => on);",
                           kMotor);
  EXPECT_EQ(bad->errors(), (std::vector<std::string>{
                               "11:2: 'running' is an output of Motor: only the block writes it",
                               "12:7: 'internal' is internal to Motor: only its inputs and outputs are seen from outside",
                               "13:10: input 'run' of m (Motor): expected BOOL, found a real literal",
                               "14:3: 'running' is an output of m (Motor): connect it with '=>'",
                               "15:3: 'speed' is a VAR_INPUT of m (Motor): '=>' takes an output",
                               "16:7: calling the instance 'm' is a statement, not a value: call it, then read its "
                               "outputs (m.output)",
                               "17:12: m (Motor) takes 2 input(s); this argument is one too many",
                               "18:13: output 'actual' => : expected BOOL, found INT (use a variable of type INT)",
                           }));
}

TEST(StCheckRules, VarInOutNeedsAVariableOfItsType) {
  const char* fb = R"(FUNCTION_BLOCK Acc
VAR_IN_OUT total : DINT; END_VAR
total := total + 1;
END_FUNCTION_BLOCK)";
  auto c = check_program("a : Acc; d : DINT; i : INT;", "a(total := d);\na(total := d + 1);\na(total := i);\na();", fb);
  EXPECT_EQ(c->errors(), (std::vector<std::string>{
                             "10:14: VAR_IN_OUT 'total' of a (Acc) needs a variable, not a value",
                             "11:12: VAR_IN_OUT 'total' of a (Acc): expected a variable of type DINT, found INT",
                             "12:1: VAR_IN_OUT 'total' of a (Acc) must be given a variable",
                         }));
}

TEST(StCheckRules, UserFunctions) {
  const char* f = R"(FUNCTION Scale : LREAL
VAR_INPUT x : LREAL; k : LREAL := 1.0; END_VAR
Scale := x * k;
END_FUNCTION)";
  auto c = check_program("r : LREAL; i : INT;", "r := Scale(2.0, 3.0);\nr := Scale(x := r);\ni := Scale(r);\nr := Scale(y := r);", f);
  EXPECT_EQ(c->errors(), (std::vector<std::string>{
                             "11:6: assignment to 'i': expected INT, found LREAL (use LREAL_TO_INT(...))",
                             "12:12: Scale has no input 'y'",
                         }));
}

TEST(StCheckRules, CaseSelectorAndLabels) {
  auto c = check_program("i : INT; r : REAL; c : Colour;",
                         "CASE i OF 1, 2: ; 3..5: ; 5: ; 10..12: ; 0..1: ; END_CASE;\nCASE r OF 1: ; END_CASE;\n"
                         "CASE c OF Red: ; Colour#Green: ; Red: ; END_CASE;\nCASE i OF 6..2: ; i: ; END_CASE;",
                         "TYPE Colour : (Red, Green); END_TYPE");
  EXPECT_EQ(c->errors(), (std::vector<std::string>{
                             "6:27: CASE label overlaps the label at t0.st:6:19",
                             "6:42: CASE label overlaps the label at t0.st:6:11",
                             "7:6: a CASE selector must be an integer (ANY_INT) or an enumeration, found REAL",
                             "8:34: CASE label overlaps the label at t0.st:8:11",
                             "9:11: a CASE range's lower bound is above its upper bound",
                             "9:19: a CASE label must be a constant",
                         }));
}

TEST(StCheckRules, ForControlVariable) {
  auto c = check_source(R"(FUNCTION_BLOCK F
VAR_INPUT n : INT; END_VAR
VAR i, j : INT; r : REAL; END_VAR
FOR i := 1 TO 10 BY 2 DO j := i; END_FOR;
FOR i := 10 TO 1 BY -1 DO i := 3; END_FOR;
FOR n := 1 TO 2 DO ; END_FOR;
FOR r := 1 TO 2 DO ; END_FOR;
FOR i := 1 TO 2 BY 0 DO ; END_FOR;
FOR i := 1 TO 2.5 DO ; END_FOR;
END_FUNCTION_BLOCK)");
  EXPECT_EQ(c->errors(), (std::vector<std::string>{
                             "5:27: 'i' is the control variable of a FOR loop and cannot be assigned in its body",
                             "6:5: a FOR control variable must be local (VAR or VAR_TEMP), 'n' is VAR_INPUT",
                             "7:5: a FOR control variable must be an integer (ANY_INT), 'r' is REAL",
                             "8:20: FOR step (BY) 0 never ends the loop",
                             "9:15: FOR end: expected INT, found a real literal",
                         }));
}

TEST(StCheckRules, ExitAndContinueOnlyInsideLoops) {
  auto c = check_program("i : INT;", "EXIT;\nWHILE TRUE DO IF i > 2 THEN EXIT; END_IF; CONTINUE; END_WHILE;\nCONTINUE;\n"
                                     "REPEAT EXIT; UNTIL i = 1 END_REPEAT;\nIF i = 1 THEN RETURN; END_IF;");
  EXPECT_EQ(c->errors(), (std::vector<std::string>{
                             "5:1: EXIT outside a loop (FOR, WHILE or REPEAT)",
                             "7:1: CONTINUE outside a loop (FOR, WHILE or REPEAT)",
                         }));
}

TEST(StCheckRules, ConditionsAreBool) {
  auto c = check_program("i : INT;", "IF i THEN ; ELSIF i = 1 THEN ; END_IF;\nWHILE 1 DO ; END_WHILE;\nREPEAT ; UNTIL i END_REPEAT;");
  EXPECT_EQ(c->errors(), (std::vector<std::string>{
                             "5:4: IF condition: expected BOOL, found INT (use INT_TO_BOOL(...))",
                             "6:7: WHILE condition: expected BOOL, found an integer literal (write TRUE or FALSE)",
                             "7:16: UNTIL condition: expected BOOL, found INT (use INT_TO_BOOL(...))",
                         }));
}

TEST(StCheckRules, ExternalsAreListedForTheLoader) {
  auto c = check_sources({"VAR_GLOBAL g : INT; k : INT := 3; END_VAR VAR_GLOBAL CONSTANT lim : INT := 3; END_VAR",
                          R"(PROGRAM P
VAR_EXTERNAL g : DINT; tag1 : LREAL; lim : INT; END_VAR
tag1 := 1.0;
END_PROGRAM)"});
  EXPECT_EQ(c->errors(), (std::vector<std::string>{
                             "2:14: VAR_EXTERNAL 'g' is DINT here but INT in its VAR_GLOBAL at t0.st:1:12",
                             "2:38: 'lim' is a global CONSTANT: declare it in VAR_EXTERNAL CONSTANT",
                         }));
  ASSERT_EQ(c->program.externals.size(), 3u);
  EXPECT_EQ(c->program.externals[1].name, "tag1");
  EXPECT_EQ(c->program.externals[1].type->name, "LREAL");
  EXPECT_EQ(c->program.externals[1].pou, "P");
}

TEST(StCheckRules, TypesAndPousOfSeveralFilesSeeEachOther) {
  auto c = check_sources({"FUNCTION_BLOCK A VAR_INPUT p : Shape; END_VAR END_FUNCTION_BLOCK",
                          "TYPE Shape : (Round, Square); END_TYPE PROGRAM P VAR a : A; END_VAR a(p := Square); END_PROGRAM"});
  EXPECT_TRUE(c->errors().empty()) << c->errors()[0];
}

// Named types resolve one through another (recursively): a generated chain
// of thousands of them exhausted the stack (a segmentation fault at 10,000
// structures). Types are limited to kMaxNesting levels, as the parser's
// nesting is (here two a link: the structure and its member's type): an
// error at each type where a chain passes the limit.
TEST(StCheckRules, ALongChainOfNamedTypesIsRefusedWithoutExhaustingTheStack) {
  constexpr int kCount = 20000;
  std::string source = "TYPE\n";
  for (int i = 0; i < kCount; ++i)
    source += "T" + std::to_string(100000 + i) + " : STRUCT a : T" + std::to_string(100000 + i + 1) +
              "; END_STRUCT;\n";
  source += "T" + std::to_string(100000 + kCount) + " : INT;\nEND_TYPE\n";
  auto c = check_source(source);
  ASSERT_FALSE(c->errors().empty());
  EXPECT_EQ(c->errors()[0], "129:22: type 'T100128' is nested deeper than 256 levels");
  EXPECT_LE(c->errors().size(), static_cast<std::size_t>(kCount / 128 + 1));
  auto ok = check_source("TYPE\n" + source.substr(5, source.find("T100120 :") - 5) + "T100120 : INT;\nEND_TYPE\n");
  EXPECT_TRUE(ok->errors().empty()) << ok->errors()[0];
}

TEST(StCheckRules, TypeDeclarations) {
  auto c = check_source(R"(TYPE
  Distance : LREAL;
  Small : INT (-5..5);
  Loop : Loop2;
  Loop2 : Loop;
  Bad : REAL (0..1);
  Empty : ARRAY[3..1] OF INT;
  Lvl : USINT (Low := 1, High := 300);
  Col : (A, B, A);
END_TYPE
FUNCTION F : INT
VAR t : TON; END_VAR
VAR_EXTERNAL g : INT; END_VAR
F := 1;
END_FUNCTION
PROGRAM P
VAR d : Distance; r : LREAL; s : Small; day : DATE; clock : TOD; stamp : DT; name : WSTRING[8]; END_VAR
r := d;
d := r * 2.0;
s := 6;
s := s + 1;
day := D#2024-02-29;
stamp := DT#2024-02-29-10:00:00 + T#1h;
clock := TOD#12:00:00 - T#30m;
name := "caf$00E9";
END_PROGRAM)");
  EXPECT_EQ(c->errors(), (std::vector<std::string>{
                             "5:11: type 'Loop' is defined in terms of itself",
                             "6:9: a subrange's base type must be an integer type, found 'REAL'",
                             "7:17: array bounds 3..1: the lower bound is above the upper",
                             "8:26: value 300 of 'High' does not fit USINT",
                             "9:16: duplicate enumeration value 'A' (first at t0.st:9:10)",
                             "12:9: a FUNCTION keeps no state, so it cannot hold an instance of TON",
                             "13:1: a FUNCTION cannot use VAR_EXTERNAL (IEC 61131-3 gives functions no access to globals)",
                             "20:6: assignment to 's': value 6 is outside Small (-5..5)",
                         }))
      << ::testing::PrintToString(c->errors());
}


// IEC 61131-3 forbids recursion; the code generator gives every FUNCTION one
// static frame and every FB instance a fixed layout, so none may pass.
TEST(StCheckRules, CallsWithoutACycleAreAllowed) {
  // A diamond (F calls G and H, G calls H), an FB calling a FUNCTION and an
  // instance of another FB through VAR_IN_OUT, a FUNCTION's name as its result.
  auto c = check_source(R"(FUNCTION H : INT
VAR_INPUT x : INT; END_VAR
H := x + 1;
END_FUNCTION
FUNCTION G : INT
VAR_INPUT x : INT; END_VAR
G := H(x) * 2;
END_FUNCTION
FUNCTION F : INT
VAR_INPUT x : INT; END_VAR
F := G(x) + H(x);
F := F + 1;
END_FUNCTION
FUNCTION_BLOCK Leaf
VAR_OUTPUT n : INT; END_VAR
n := F(n);
END_FUNCTION_BLOCK
FUNCTION_BLOCK Node
VAR_IN_OUT other : Leaf; END_VAR
VAR leaves : ARRAY[1..3] OF Leaf; END_VAR
leaves[1]();
other();
END_FUNCTION_BLOCK
PROGRAM P
VAR l : Leaf; n : Node; END_VAR
n(other := l);
END_PROGRAM)");
  EXPECT_TRUE(c->errors().empty()) << ::testing::PrintToString(c->errors());
}

TEST(StCheckRules, RecursionIsOneErrorPerGroupOfPousCallingEachOther) {
  auto c = check_source(R"(FUNCTION A : INT
VAR_INPUT x : INT; END_VAR
A := B(x) + B(x + 1) + C(x);
END_FUNCTION
FUNCTION B : INT
VAR_INPUT x : INT; END_VAR
B := C(x);
END_FUNCTION
FUNCTION C : INT
VAR_INPUT x : INT; END_VAR
C := A(x := x) + C(x);
END_FUNCTION
FUNCTION_BLOCK Ping
VAR_EXTERNAL pong : Pong; END_VAR
pong();
END_FUNCTION_BLOCK
FUNCTION_BLOCK Pong
VAR_EXTERNAL ping : Ping; END_VAR
ping();
END_FUNCTION_BLOCK
FUNCTION D : INT
D := A(1) + D();
END_FUNCTION)");
  // A, B and C call one another: one error, at A (the first), with the
  // shortest cycle through it (A -> C -> A; the calls of B come first in the
  // source but make a longer one). Ping and Pong, through VAR_EXTERNAL
  // instances, another; D's call of itself a third.
  EXPECT_EQ(c->errors(), (std::vector<std::string>{
                             "3:24: FUNCTION A calls itself: A -> C -> A",
                             "15:1: FUNCTION_BLOCK Ping calls itself: Ping -> Pong -> Ping",
                             "22:13: FUNCTION D calls itself: D -> D",
                         }));
}

TEST(StCheckRules, AnFbHoldingAnInstanceOfItselfIsRefused) {
  auto c = check_source(R"(TYPE Pair : STRUCT a, b : Inner; END_STRUCT; END_TYPE
TYPE Nest : STRUCT p : ARRAY[0..1] OF Pair; END_STRUCT; END_TYPE
FUNCTION_BLOCK Outer
VAR_INPUT cfg : INT; END_VAR
VAR_OUTPUT nest : Nest; END_VAR
nest.p[0].a();
END_FUNCTION_BLOCK
FUNCTION_BLOCK Inner
VAR_TEMP o : Outer; END_VAR
o();
END_FUNCTION_BLOCK
FUNCTION_BLOCK Self
VAR_INPUT copy : Self; END_VAR
END_FUNCTION_BLOCK)");
  // One error per cycle: Outer's and Inner's calls of the instances are the same mistake.
  EXPECT_EQ(c->errors(), (std::vector<std::string>{
                             "5:12: FUNCTION_BLOCK Outer holds an instance of itself, so its size would be infinite: "
                             "Outer -> Inner -> Outer",
                             "13:11: FUNCTION_BLOCK Self holds an instance of itself, so its size would be infinite: "
                             "Self -> Self",
                         }));
}

// A long chain of POUs (a generated program) is searched without recursion:
// no stack overflow, one error.
TEST(StCheckRules, ALongCycleIsFoundWithoutExhaustingTheStack) {
  constexpr int kCount = 3000;
  std::string functions, blocks;
  for (int i = 0; i < kCount; ++i) {
    const int next = (i + 1) % kCount;
    functions += "FUNCTION F" + std::to_string(i) + " : INT\nF" + std::to_string(i) + " := F" +
                 std::to_string(next) + "();\nEND_FUNCTION\n";
    blocks += "FUNCTION_BLOCK B" + std::to_string(i) + "\nVAR b : B" + std::to_string(next) +
              "; END_VAR\nEND_FUNCTION_BLOCK\n";
  }
  auto c = check_source(functions + blocks);
  ASSERT_EQ(c->errors().size(), 2u) << ::testing::PrintToString(c->errors());
  EXPECT_EQ(c->errors()[0].rfind("2:7: FUNCTION F0 calls itself: F0 -> F1 -> F2 -> ", 0), 0u) << c->errors()[0];
  EXPECT_NE(c->errors()[0].find(" -> F2999 -> F0"), std::string::npos);
  EXPECT_NE(c->errors()[1].find("FUNCTION_BLOCK B0 holds an instance of itself"), std::string::npos);
}

}  // namespace
}  // namespace syncplc::st
