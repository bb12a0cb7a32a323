// The type checker's typing rules: implicit widening (3rd edition) and the
// refused narrowing with its conversion, literal fitting, operator classes,
// TIME arithmetic, enumerations, structs, arrays and bits.
#include "tests/st/checker_fixture.hpp"

namespace syncplc::st {
namespace {

using testing::check_program;
using testing::check_source;

TEST(StCheckTypes, ImplicitWideningIsAllowed) {
  auto c = check_program(
      "i : INT; si : SINT; d : DINT; l : LINT; ui : UINT; ud : UDINT; r : REAL; lr : LREAL; b : BYTE; w : WORD; "
      "dw : DWORD; t : TIME; lt : LTIME;",
      "d := i; l := d; d := si; d := ui; l := ud; r := i; lr := d; lr := r; w := b; dw := w; lt := t;"
      "lr := r + lr; d := i + ui;");
  EXPECT_TRUE(c->errors().empty()) << c->errors()[0];
}

TEST(StCheckTypes, NarrowingIsRefusedWithTheConversionToWrite) {
  auto c = check_program("i : INT; d : DINT; lr : LREAL; r : REAL; ui : UINT; w : WORD; b : BYTE;",
                         "i := lr;\nr := d;\nui := i;\nb := w;\ni := w;");
  EXPECT_EQ(c->errors(), (std::vector<std::string>{
                             "5:6: assignment to 'i': expected INT, found LREAL (use LREAL_TO_INT(...))",
                             "6:6: assignment to 'r': expected REAL, found DINT (use DINT_TO_REAL(...))",
                             "7:7: assignment to 'ui': expected UINT, found INT (use INT_TO_UINT(...))",
                             "8:6: assignment to 'b': expected BYTE, found WORD (use WORD_TO_BYTE(...))",
                             "9:6: assignment to 'i': expected INT, found WORD (use WORD_TO_INT(...))",
                         }));
}

TEST(StCheckTypes, UntypedLiteralsTakeTheTypeTheContextWantsIfTheyFit) {
  auto ok = check_program("s : SINT; b : BYTE; r : REAL; u : ULINT; w : WORD;",
                          "s := -128; b := 255; r := 1; u := 16#FFFF_FFFF_FFFF_FFFF; w := w AND 16#FF00; s := s + 1;");
  EXPECT_TRUE(ok->errors().empty()) << ok->errors()[0];
  auto bad = check_program("s : SINT; b : BYTE; i : INT; u : UINT;",
                           "s := 200;\nb := -1;\ni := 1.5;\nu := u + 70000;\ni := INT#40000;");
  EXPECT_EQ(bad->errors(), (std::vector<std::string>{
                               "5:6: assignment to 's': value 200 does not fit SINT (-128..127)",
                               "6:6: assignment to 'b': value -1 does not fit BYTE (0..255)",
                               "7:6: assignment to 'i': expected INT, found a real literal",
                               "8:10: operand of '+': value 70000 does not fit UINT (0..65535)",
                               "9:6: INT#40000 does not fit INT (-32768..32767)",
                           }));
}

TEST(StCheckTypes, ModNeedsIntegersAndPowerARealBase) {
  auto c = check_program("i : INT; r : LREAL;", "i := i MOD 3;\nr := r MOD 2.0;\nr := r ** 2;\nr := i ** 2.0;");
  EXPECT_EQ(c->errors(), (std::vector<std::string>{
                             "6:8: MOD needs integers (ANY_INT), found LREAL",
                             "8:6: '**' needs a real base (ANY_REAL), found INT (use INT_TO_LREAL(...))",
                         }));
}

TEST(StCheckTypes, TimeArithmetic) {
  auto ok = check_program("t : TIME; d : DINT; r : LREAL; b : BOOL; dt1, dt2 : DT;",
                          "t := t + T#1s; t := t - T#5ms; t := t * 2; t := t * d; t := t / 2.5; t := 3 * t;"
                          "b := t > T#1s; t := dt1 - dt2; dt1 := dt1 + T#1h;");
  EXPECT_TRUE(ok->errors().empty()) << ok->errors()[0];
  auto bad = check_program("t : TIME; d : DINT;", "t := t + 1;\nt := d / t;\nd := t;\nt := t / 0;");
  EXPECT_TRUE(bad->has("5:8: '+' is not defined for TIME and an integer literal")) << bad->errors()[0];
  EXPECT_TRUE(bad->has("6:8: '/' is not defined for DINT and TIME")) << ::testing::PrintToString(bad->errors());
  EXPECT_TRUE(bad->has("7:6: assignment to 'd': expected DINT, found TIME (use TIME_TO_DINT(...))"));
  EXPECT_TRUE(bad->has("8:10: division by zero"));
  EXPECT_EQ(bad->errors().size(), 4u);
}

// DATE and DT are nanoseconds since 1970-01-01 in 64 bits: a literal the
// lexer takes (years 1 to 9999) may lie outside; it is an error, not a
// wrapped value (the checker multiplied past INT64_MAX: fuzz_st_parse).
TEST(StCheckTypes, DatesOutsideTheNanosecondRangeAreRefused) {
  auto ok = check_program("d : DATE; t : DT;",
                          "d := D#1677-09-22; d := D#2262-04-11; d := D#1970-01-01;"
                          "t := DT#1677-09-21-00:12:44; t := DT#2262-04-11-23:47:16.854775807;");
  EXPECT_TRUE(ok->errors().empty()) << ok->errors()[0];
  auto bad = check_program("d : DATE; t : DT;",
                           "d := D#4048-01-31;\nd := D#1677-09-21;\nt := DT#2262-04-11-23:47:17;\n"
                           "t := DT#0001-01-01-00:00:00;");
  EXPECT_EQ(bad->errors(), (std::vector<std::string>{
                               "5:6: DATE#4048-01-31 is outside the range of DATE (1677-09-22 to 2262-04-11)",
                               "6:6: DATE#1677-09-21 is outside the range of DATE (1677-09-22 to 2262-04-11)",
                               "7:6: DT#2262-04-11-23:47:17 is outside the range of DT (1677-09-21-00:12:44 to "
                               "2262-04-11-23:47:16.854775807)",
                               "8:6: DT#0001-01-01-00:00:00 is outside the range of DT (1677-09-21-00:12:44 to "
                               "2262-04-11-23:47:16.854775807)",
                           }));
}

TEST(StCheckTypes, Comparisons) {
  auto c = check_program("a : INT; b : LREAL; x : BOOL; s : STRING;",
                         "x := a < b;\nx := a = s;\nx := (a < 1) < 2;");
  EXPECT_EQ(c->errors(), (std::vector<std::string>{
                             "6:8: operands of '=' have types INT and STRING[80], with no implicit conversion between "
                             "them (use STRING_TO_INT(...) or the reverse)",
                             "7:16: operand of '<': expected BOOL, found an integer literal (write TRUE or FALSE)",
                         }));
}

TEST(StCheckTypes, LogicOnBoolAndBitStrings) {
  auto c = check_program("x : BOOL; w : WORD; i : INT;", "x := x AND NOT x;\nw := w OR 16#F;\ni := i AND i;\nx := NOT i;");
  EXPECT_EQ(c->errors(), (std::vector<std::string>{
                             "7:8: AND needs BOOL or a bit string (ANY_BIT), found INT",
                             "8:6: NOT needs BOOL or a bit string (ANY_BIT), found INT",
                         }));
}

const char* kEnums = R"(TYPE
  Colour : (Red, Green, Blue);
  Light : (Off, Red2, Amber);
  Signal : (Stop, Go, Red);
END_TYPE)";

TEST(StCheckTypes, EnumerationValuesQualifiedAndUnqualified) {
  auto c = check_program("c : Colour; s : Signal; l : Light;",
                         "c := Colour#Blue;\nc := Green;\nc := Red;\nl := Amber;\nc := Colour#Yellow;\nc := l;\n"
                         "IF c = Red THEN s := Signal#Red; END_IF;",
                         kEnums);
  EXPECT_EQ(c->errors(), (std::vector<std::string>{
                             "14:6: Colour has no value 'Yellow'",
                             "15:6: assignment to 'c': expected Colour, found Light",
                         }));
  // Red with Colour wanted is Colour's; where nothing says which, the qualification is needed.
  auto amb = check_program("x : BOOL;", "x := Red = Red;", kEnums);
  EXPECT_TRUE(amb->has("'Red' is a value of Colour and of Signal: write Colour#Red")) << amb->errors()[0];
}

TEST(StCheckTypes, StructArrayMemberAndBitAccess) {
  const char* types = R"(TYPE
  Point : STRUCT x, y : LREAL; END_STRUCT;
  Path : ARRAY[1..10] OF Point;
END_TYPE)";
  auto ok = check_program("p : Path; m : ARRAY[0..2, 0..3] OF INT; i : INT; w : WORD; b : BOOL;",
                          "p[i].x := p[2].y;\nm[2, 3] := m[i, i + 1];\nb := w.15;\nw.0 := TRUE;", types);
  EXPECT_TRUE(ok->errors().empty()) << ok->errors()[0];
  auto bad = check_program("p : Path; m : ARRAY[0..2, 0..3] OF INT; w : WORD; b : BOOL; r : REAL;",
                           "p[11].x := 0.0;\np[1].z := 0.0;\nm[1] := 0;\nb := w.16;\nb := b.0;\np[r].x := 1.0;\n"
                           "r := r.x;",
                           types);
  EXPECT_EQ(bad->errors(), (std::vector<std::string>{
                               "9:3: index 11 is outside 1..10",
                               "10:5: 'Point' has no field 'z'",
                               "11:2: ARRAY[0..2,0..3] OF INT has 2 dimension(s), indexed with 1",
                               "12:7: bit 16 is outside WORD (0..15)",
                               "13:7: bit access '.0' needs a bit string (BYTE, WORD, DWORD, LWORD), found BOOL",
                               "14:3: an array index must be an integer (ANY_INT), found REAL",
                               "15:7: '.x' on a value of type REAL, which has no fields",
                           }));
}

TEST(StCheckTypes, StandardFunctionsAndConversions) {
  auto ok = check_program(
      "i : INT; d : DINT; r : LREAL; w : WORD; s : STRING[20]; n : INT; b : BOOL;",
      "d := MAX(i, d, 3); r := LIMIT(0.0, r, 10.0); i := SEL(b, i, 5); d := MUX(1, d, i, 7);"
      "w := SHL(w, 2); r := SQRT(r) + EXPT(r, 2) + ATAN2(r, 1.0); n := LEN(s); s := CONCAT(s, 'x', s);"
      "s := MID(s, 2, 1); n := FIND(s, 'a'); i := LREAL_TO_INT(r); d := TRUNC(r); i := LREAL_TRUNC_INT(r);"
      "r := TO_LREAL(i); s := INT_TO_STRING(i); r := ABS(-2.5); i := ABS(i);");
  EXPECT_TRUE(ok->errors().empty()) << ok->errors()[0];
  auto bad = check_program("i : INT; r : LREAL; b : BOOL; w : WORD; s : STRING;",
                           "r := SQRT(i);\nw := SHL(b, 1);\ni := LEN(i);\nr := MAX(r, s);\ni := SINE(r);\n"
                           "i := LIMIT(1, 2);\ni := REAL_TO_INT(r);");
  EXPECT_EQ(bad->errors(), (std::vector<std::string>{
                               "5:6: SQRT needs ANY_REAL inputs, found INT",
                               "6:6: SHL needs ANY_BIT (not BOOL) inputs, found BOOL",
                               "7:6: LEN needs ANY_STRING inputs, found INT",
                               "8:13: IN of MAX: LREAL and STRING[80] have no common type (the inputs of MAX take one "
                               "type)",
                               "9:6: unknown function or FB instance 'SINE' (did you mean SIN?)",
                               "10:6: LIMIT takes 3 argument(s), found 2",
                               "11:18: input of REAL_TO_INT: expected REAL, found LREAL (use LREAL_TO_REAL(...))",
                           }));
}

TEST(StCheckTypes, CheckedProgramRecordsTypesSymbolsAndConstants) {
  auto c = check_source(R"(PROGRAM P
VAR CONSTANT N : INT := 4; END_VAR
VAR a : ARRAY[1..N * 2] OF REAL; x : REAL; END_VAR
x := a[N + 1] + 1;
END_PROGRAM)");
  ASSERT_TRUE(c->errors().empty()) << c->errors()[0];
  const PouInfo* p = c->program.pou("P");
  ASSERT_NE(p, nullptr);
  const Variable* a = p->find("A");
  ASSERT_NE(a, nullptr);
  ASSERT_EQ(a->type->kind, Type::Kind::Array);
  EXPECT_EQ(a->type->dims[0].high, 8);
  EXPECT_EQ(a->type->element_count(), 8);
  const Statement& s = c->parsed[0]->unit.pous[0].body[0];
  const ExprInfo* sum = c->program.info(s.value);
  ASSERT_NE(sum, nullptr);
  EXPECT_EQ(sum->type->name, "REAL");
  const Expr& one = s.value.operands[1];
  EXPECT_EQ(c->program.info(one)->type->name, "REAL");  // the literal took REAL
  const Expr& index = s.value.operands[0].operands[1];
  ASSERT_TRUE(c->program.info(index)->constant.has_value());
  EXPECT_EQ(static_cast<int>(c->program.info(index)->constant->i), 5);
  EXPECT_EQ(c->program.info(index)->type->name, "INT");
  EXPECT_EQ(c->program.info(s.target)->variable, p->find("x"));
}

}  // namespace
}  // namespace syncplc::st
