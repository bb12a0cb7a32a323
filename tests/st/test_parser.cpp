// The Structured Text parser: IEC precedence, every statement and
// declaration kind, locations, error messages and recovery, the nesting limit.
#include <gtest/gtest.h>

#include "runtime/st/ast_dump.hpp"
#include "runtime/st/parser.hpp"

namespace syncplc::st {
namespace {

std::vector<std::string> messages(const ParseResult& r) {
  std::vector<std::string> out;
  for (const auto& d : r.diagnostics.sorted()) out.push_back(d.text());
  return out;
}

ParseResult parse_ok(const std::string& src) {
  ParseResult r = parse(src, SourceFile("p.st"));
  EXPECT_TRUE(r.ok()) << src << "\n" << (messages(r).empty() ? "" : messages(r)[0]);
  return r;
}

// The expression `text` as the value of an assignment, dumped.
std::string expr(const std::string& text) {
  ParseResult r = parse_ok("PROGRAM p\nx := " + text + ";\nEND_PROGRAM\n");
  if (r.unit.pous.empty() || r.unit.pous[0].body.empty()) return "<none>";
  return dump(r.unit.pous[0].body[0].value);
}

// The body of a program whose statements are `text`, dumped.
std::string body(const std::string& text) {
  ParseResult r = parse_ok("PROGRAM p\n" + text + "\nEND_PROGRAM\n");
  if (r.unit.pous.empty()) return "<none>";
  return dump(r.unit.pous[0].body);
}

std::vector<std::string> errors_of(const std::string& src) { return messages(parse(src, SourceFile("e.st"))); }

TEST(StParser, Precedence) {
  EXPECT_EQ(expr("a OR b AND c"), "(OR a (AND b c))");
  EXPECT_EQ(expr("a XOR b OR c AND d"), "(OR (XOR a b) (AND c d))");
  EXPECT_EQ(expr("a & b XOR c"), "(XOR (AND a b) c)");
  // Unary minus binds tighter than ** (3rd edition, table 71).
  EXPECT_EQ(expr("-2 ** 2"), "(** (neg 2) 2)");
  EXPECT_EQ(expr("2 ** -1"), "(** 2 (neg 1))");
  EXPECT_EQ(expr("NOT a = b"), "(= (NOT a) b)");
  EXPECT_EQ(expr("a < b < c"), "(< (< a b) c)");
  EXPECT_EQ(expr("a = b <> c"), "(<> (= a b) c)");
  EXPECT_EQ(expr("a < b = c > d"), "(= (< a b) (> c d))");
  EXPECT_EQ(expr("a + b * c ** d"), "(+ a (* b (** c d)))");
  EXPECT_EQ(expr("a ** b ** c"), "(** (** a b) c)");
  EXPECT_EQ(expr("a - b - c"), "(- (- a b) c)");
  EXPECT_EQ(expr("a / b MOD c * d"), "(* (MOD (/ a b) c) d)");
  EXPECT_EQ(expr("(a + b) * c"), "(* (+ a b) c)");
  EXPECT_EQ(expr("a AND b = c"), "(AND a (= b c))");
  EXPECT_EQ(expr("NOT NOT a"), "(NOT (NOT a))");
  EXPECT_EQ(expr("+a - -b"), "(- (plus a) (neg b))");
  EXPECT_EQ(expr("MAX(a, b) + 1"), "(+ (call MAX a b) 1)");
}

TEST(StParser, PrimariesAndVariableAccess) {
  EXPECT_EQ(expr("a.b[i, j + 1].c"), "(. ([] (. a b) i (+ j 1)) c)");
  EXPECT_EQ(expr("w.3"), "(.bit w 3)");
  EXPECT_EQ(expr("fb.q.0"), "(.bit (. fb q) 0)");
  EXPECT_EQ(expr("Colour#Red"), "Colour#Red");
  EXPECT_EQ(expr("INT#-5 + 16#FF"), "(+ INT#-5 255)");
  EXPECT_EQ(expr("T#1s200ms"), "TIME#1200000000ns");
  EXPECT_EQ(expr("LREAL#1.5"), "LREAL#1.5");
  EXPECT_EQ(expr("1.5E3"), "1500.0");
  EXPECT_EQ(expr("TRUE AND FALSE"), "(AND TRUE FALSE)");
  EXPECT_EQ(expr("'it$'s'"), "'it$'s'");
  EXPECT_EQ(expr("\"wide\""), "\"wide\"");
  EXPECT_EQ(expr("D#2024-01-31"), "DATE#2024-01-31");
  EXPECT_EQ(expr("TOD#12:30:00.5"), "TOD#12:30:00.5");
  EXPECT_EQ(expr("DT#2024-01-31-12:30:00"), "DT#2024-01-31-12:30:00");
  EXPECT_EQ(expr("LIMIT(MN := 0, IN := x, MX := 10)"), "(call LIMIT (:= MN 0) (:= IN x) (:= MX 10))");
  EXPECT_EQ(expr("f()"), "(call f)");
}

TEST(StParser, EveryStatementKind) {
  EXPECT_EQ(body("x := 1;"), "@2:1 (:= x 1)\n");
  EXPECT_EQ(body(";"), "@2:1 (empty)\n");
  EXPECT_EQ(body("a[i].b := c.d;"), "@2:1 (:= (. ([] a i) b) (. c d))\n");
  EXPECT_EQ(body("IF a THEN x := 1; ELSIF b THEN x := 2; ELSE x := 3; END_IF;"),
            "@2:1 (if\n"
            "  @2:1 (branch a\n    @2:11 (:= x 1)\n  )\n"
            "  @2:19 (branch b\n    @2:32 (:= x 2)\n  )\n"
            "  (else\n    @2:45 (:= x 3)\n  )\n"
            ")\n");
  EXPECT_EQ(body("CASE s OF\n1, 2: x := 1;\n3..5, 7: x := 2; y := 3;\nRed: ;\nColour#Blue: x := 4;\n-1: x := 5;\n"
                 "ELSE x := 0;\nEND_CASE;"),
            "@2:1 (case s\n"
            "  @3:1 (labels 1 2\n    @3:7 (:= x 1)\n  )\n"
            "  @4:1 (labels 3..5 7\n    @4:10 (:= x 2)\n    @4:18 (:= y 3)\n  )\n"
            "  @5:1 (labels Red\n    @5:6 (empty)\n  )\n"
            "  @6:1 (labels Colour#Blue\n    @6:14 (:= x 4)\n  )\n"
            "  @7:1 (labels (neg 1)\n    @7:5 (:= x 5)\n  )\n"
            "  (else\n    @8:6 (:= x 0)\n  )\n"
            ")\n");
  EXPECT_EQ(body("FOR i := 10 TO 1 BY -1 DO s := s + i; END_FOR;"),
            "@2:1 (for i 10 1 (neg 1)\n  @2:27 (:= s (+ s i))\n)\n");
  EXPECT_EQ(body("FOR i := 1 TO n DO EXIT; END_FOR;"), "@2:1 (for i 1 n _\n  @2:20 (exit)\n)\n");
  EXPECT_EQ(body("WHILE x < 10 DO x := x + 1; CONTINUE; END_WHILE;"),
            "@2:1 (while (< x 10)\n  @2:17 (:= x (+ x 1))\n  @2:29 (continue)\n)\n");
  EXPECT_EQ(body("REPEAT x := x - 1; UNTIL x <= 0 END_REPEAT;"),
            "@2:1 (repeat (<= x 0)\n  @2:8 (:= x (- x 1))\n)\n");
  EXPECT_EQ(body("RETURN;"), "@2:1 (return)\n");
  EXPECT_EQ(body("timer(IN := start, PT := T#5s, Q => done, ET => );"),
            "@2:1 (call timer (:= IN start) (:= PT TIME#5000000000ns) (=> Q done) (=> ET))\n");
  EXPECT_EQ(body("timer(start, T#5s);"), "@2:1 (call timer start TIME#5000000000ns)\n");
  EXPECT_EQ(body("edge(CLK := x, NOT Q => nq);"), "@2:1 (call edge (:= CLK x) (=> NOT Q nq))\n");
  EXPECT_EQ(body("axes[2](enable := TRUE);"), "@2:1 (call ([] axes 2) (:= enable TRUE))\n");
  EXPECT_EQ(body("IF a THEN IF b THEN ; END_IF; END_IF;"),
            "@2:1 (if\n  @2:1 (branch a\n    @2:11 (if\n      @2:11 (branch b\n        @2:21 (empty)\n"
            "      )\n    )\n  )\n)\n");
}

TEST(StParser, EveryDeclarationKind) {
  ParseResult r = parse_ok(
      "TYPE\n"
      "  Colour : (Red, Green, Blue);\n"
      "  Mode : INT (Off := 0, Auto := 10, Manual := 20) := Auto;\n"
      "  Percent : INT (0..100);\n"
      "  Grid : ARRAY[1..10, 0..3] OF LREAL;\n"
      "  Name : STRING[80];\n"
      "  Speed : LREAL := 1.5;\n"
      "  Point : STRUCT x : LREAL; y : LREAL := 2.0; tag : STRING[16]; END_STRUCT;\n"
      "END_TYPE\n"
      "VAR_GLOBAL RETAIN g_count : DINT; END_VAR\n"
      "FUNCTION_BLOCK fb\n"
      "VAR_INPUT a, b : BOOL := TRUE; END_VAR\n"
      "VAR_OUTPUT q : INT; END_VAR\n"
      "VAR_IN_OUT io : Point; END_VAR\n"
      "VAR_TEMP t : ARRAY[0..2] OF ARRAY[0..1] OF INT; END_VAR\n"
      "VAR_EXTERNAL CONSTANT limit : REAL; END_VAR\n"
      "VAR RETAIN PERSISTENT\n"
      "  sensor AT %IX0.0 : BOOL;\n"
      "  any_in AT %I* : WORD;\n"
      "  p : Point := (x := 1.0, y := 2.0);\n"
      "  arr : ARRAY[1..5] OF INT := [1, 2, 3(0)];\n"
      "  pts : ARRAY[0..1] OF Point := [(x := 1.0), 2((y := 3.0))];\n"
      "  msg : STRING[80] := 'hi';\n"
      "  wmsg : WSTRING(20);\n"
      "  cfg : STRING;\n"
      "  r : INT (-5..5);\n"
      "END_VAR\n"
      "VAR_GLOBAL g2 : INT; END_VAR\n"
      "END_FUNCTION_BLOCK\n"
      "FUNCTION f : LREAL\n"
      "VAR_INPUT x : LREAL; END_VAR\n"
      "f := x * 2.0;\n"
      "END_FUNCTION\n");
  EXPECT_EQ(dump(r.unit),
            "(unit\n"
            "  @2:3 (type Colour (enum (Red) (Green) (Blue)))\n"
            "  @3:3 (type Mode (enum INT (Off 0) (Auto 10) (Manual 20)) (init Auto))\n"
            "  @4:3 (type Percent (subrange INT 0..100))\n"
            "  @5:3 (type Grid (array [1..10, 0..3] LREAL))\n"
            "  @6:3 (type Name STRING[80])\n"
            "  @7:3 (type Speed LREAL (init 1.5))\n"
            "  @8:3 (type Point (struct @8:18 (decl (x) LREAL) @8:29 (decl (y) LREAL (init 2.0)) @8:47 (decl (tag) STRING[16])))\n"
            "  @10:1 (VAR_GLOBAL RETAIN\n"
            "    @10:19 (decl (g_count) DINT)\n"
            "  )\n"
            "  @11:1 (FUNCTION_BLOCK fb\n"
            "    @12:1 (VAR_INPUT\n"
            "      @12:11 (decl (a b) BOOL (init TRUE))\n"
            "    )\n"
            "    @13:1 (VAR_OUTPUT\n"
            "      @13:12 (decl (q) INT)\n"
            "    )\n"
            "    @14:1 (VAR_IN_OUT\n"
            "      @14:12 (decl (io) Point)\n"
            "    )\n"
            "    @15:1 (VAR_TEMP\n"
            "      @15:10 (decl (t) (array [0..2] (array [0..1] INT)))\n"
            "    )\n"
            "    @16:1 (VAR_EXTERNAL CONSTANT\n"
            "      @16:23 (decl (limit) REAL)\n"
            "    )\n"
            "    @17:1 (VAR RETAIN PERSISTENT\n"
            "      @18:3 (decl (sensor) (at %IX0.0) BOOL)\n"
            "      @19:3 (decl (any_in) (at %I*) WORD)\n"
            "      @20:3 (decl (p) Point (init (struct-init (x 1.0) (y 2.0))))\n"
            "      @21:3 (decl (arr) (array [1..5] INT) (init (array-init 1 2 (repeat 3 0))))\n"
            "      @22:3 (decl (pts) (array [0..1] Point) (init (array-init (struct-init (x 1.0)) (repeat 2 (struct-init (y 3.0))))))\n"
            "      @23:3 (decl (msg) STRING[80] (init 'hi'))\n"
            "      @24:3 (decl (wmsg) WSTRING[20])\n"
            "      @25:3 (decl (cfg) STRING)\n"
            "      @26:3 (decl (r) (subrange INT (neg 5)..5))\n"
            "    )\n"
            "    @28:1 (VAR_GLOBAL\n"
            "      @28:12 (decl (g2) INT)\n"
            "    )\n"
            "    (body\n"
            "    )\n"
            "  )\n"
            "  @30:1 (FUNCTION f : LREAL\n"
            "    @31:1 (VAR_INPUT\n"
            "      @31:11 (decl (x) LREAL)\n"
            "    )\n"
            "    (body\n"
            "      @32:1 (:= f (* x 2.0))\n"
            "    )\n"
            "  )\n"
            ")\n");
}

TEST(StParser, RepeatedDefaultsAndSemicolonsAfterPous) {
  ParseResult r = parse_ok("PROGRAM p\nVAR a : ARRAY[1..4] OF INT := [1, 3()]; END_VAR\nEND_PROGRAM;\n"
                           "FUNCTION_BLOCK f\nEND_FUNCTION_BLOCK;\n");
  ASSERT_EQ(r.unit.pous.size(), 2u);
  EXPECT_EQ(dump(r.unit.pous[0].sections.at(0).decls.at(0).type), "(array [1..4] INT)");
  const Initializer& init = r.unit.pous[0].sections[0].decls[0].init;
  ASSERT_EQ(init.elements.size(), 2u);
  EXPECT_EQ(dump(init.elements[1].repeat), "3");
  EXPECT_EQ(init.elements[1].value.kind, InitKind::None);
}

TEST(StParser, ExpressionNodesKeepTheirLocations) {
  ParseResult r = parse_ok("PROGRAM p\n  x := a +\n    f(b);\nEND_PROGRAM\n");
  const Statement& s = r.unit.pous.at(0).body.at(0);
  EXPECT_EQ(s.loc.text(), "p.st:2:3");
  EXPECT_EQ(s.target.loc.text(), "p.st:2:3");
  EXPECT_EQ(s.value.loc.text(), "p.st:2:10");  // the operator
  EXPECT_EQ(s.value.operands.at(0).loc.text(), "p.st:2:8");
  EXPECT_EQ(s.value.operands.at(1).loc.text(), "p.st:3:5");
  EXPECT_EQ(s.value.operands.at(1).args.at(0).loc.text(), "p.st:3:7");
}

TEST(StParser, PouDocumentationIsTheCommentBeforeItOrElseItsFirstInside) {
  ParseResult r = parse_ok(
      "(* Moves boxes from the infeed to the outfeed. *)\n"
      "FUNCTION_BLOCK Conveyor\nEND_FUNCTION_BLOCK\n"
      "FUNCTION_BLOCK Lift // raises a box\nVAR_INPUT up : BOOL; END_VAR\nEND_FUNCTION_BLOCK\n"
      "PROGRAM Main\nEND_PROGRAM\n");
  ASSERT_EQ(r.unit.pous.size(), 3u);
  EXPECT_EQ(r.unit.pous[0].doc, "Moves boxes from the infeed to the outfeed.");
  EXPECT_EQ(r.unit.pous[1].doc, "raises a box");
  EXPECT_EQ(r.unit.pous[2].doc, "");
  // A file's header separated by a blank line, and a comment trailing the
  // previous POU's last line, are not documentation.
  ParseResult h = parse_ok(
      "(* Copyright 2026, licence: MIT *)\n\n"
      "// Counts boxes.\n// Resets on R.\n"
      "FUNCTION_BLOCK Counter\nEND_FUNCTION_BLOCK // end of Counter\n"
      "FUNCTION_BLOCK Plain\nEND_FUNCTION_BLOCK\n"
      "(* Licence *)\n\nFUNCTION_BLOCK Later\nEND_FUNCTION_BLOCK\n"
      "(* Before a pragma *)\n{attribute 'x'}\nFUNCTION_BLOCK Pragma\nEND_FUNCTION_BLOCK\n");
  ASSERT_EQ(h.unit.pous.size(), 4u);
  EXPECT_EQ(h.unit.pous[0].doc, "Counts boxes.\nResets on R.");
  EXPECT_EQ(h.unit.pous[1].doc, "");
  EXPECT_EQ(h.unit.pous[2].doc, "");
  EXPECT_EQ(h.unit.pous[3].doc, "Before a pragma");
}

TEST(StParser, PragmasAreSkippedWithANote) {
  ParseResult r = parse("{attribute 'hide'}\nPROGRAM p\nx := 1;\nEND_PROGRAM\n", SourceFile("p.st"));
  EXPECT_TRUE(r.ok());
  EXPECT_EQ(messages(r), (std::vector<std::string>{"p.st:1:1: note: pragma '{attribute 'hide'}' ignored"}));
  ASSERT_EQ(r.unit.pous.size(), 1u);
  EXPECT_EQ(r.unit.pous[0].body.size(), 1u);
}

TEST(StParser, AllSyntaxErrorsOfAFileInOneRun) {
  EXPECT_EQ(errors_of("PROGRAM p\n"
                      "VAR x : INT; y INT; z : ; END_VAR\n"
                      "x := 1\n"
                      "y := (2 + ;\n"
                      "IF x THEN\n"
                      "  x := 3;\n"
                      "END_FI;\n"
                      "WHILE x DO x := 1; END_IF;\n"
                      "FOR i = 1 TO 3 DO x := i; END_FOR;\n"
                      "CASE x 1: x := 2; END_CASE;\n"
                      "x := 5;\n"
                      "END_PROGRAM\n"),
            (std::vector<std::string>{
                "e.st:2:16: expected ':' and a type, found name 'INT'",
                "e.st:2:25: expected a type, found ';'",
                "e.st:4:1: expected ';', found name 'y'",
                "e.st:4:11: expected an expression, found ';'",
                "e.st:7:7: expected ':=' or a call after 'END_FI', found ';' (did you mean END_IF?)",
                // The WHILE is inside the IF (END_FI did not close it); its END_IF is taken as END_WHILE.
                "e.st:8:20: expected END_WHILE, found END_IF",
                "e.st:9:7: expected ':=', found '='",
                "e.st:10:8: expected OF, found an integer literal 1",
                "e.st:12:1: expected END_IF, found END_PROGRAM",
            }));
}

TEST(StParser, MisspeltKeywordsGetASuggestion) {
  EXPECT_EQ(errors_of("FUNCTION_BLOK fb\nEND_FUNCTION_BLOCK\n"),
            (std::vector<std::string>{"e.st:1:1: expected FUNCTION, FUNCTION_BLOCK, PROGRAM, TYPE or VAR_GLOBAL, "
                                      "found name 'FUNCTION_BLOK' (did you mean FUNCTION_BLOCK?)"}));
  // A misspelt section is reported once and read as the section it most likely is.
  ParseResult r = parse("PROGRAM p\nVAR_INPT x : INT; END_VAR\nVAR_OUTPT RETAIN\n  y : INT;\n  z : INT;\n"
                        "END_VAR\nx := 1;\nEND_PROGRAM\n", SourceFile("e.st"));
  EXPECT_EQ(messages(r), (std::vector<std::string>{
                             "e.st:2:1: expected a VAR section or a statement, found name 'VAR_INPT' "
                             "(did you mean VAR_INPUT?)",
                             "e.st:3:1: expected a VAR section or a statement, found name 'VAR_OUTPT' "
                             "(did you mean VAR_OUTPUT?)"}));
  ASSERT_EQ(r.unit.pous.size(), 1u);
  ASSERT_EQ(r.unit.pous[0].sections.size(), 2u);
  EXPECT_EQ(r.unit.pous[0].sections[0].kind, VarSectionKind::Input);
  EXPECT_EQ(r.unit.pous[0].sections[1].kind, VarSectionKind::Output);
  EXPECT_TRUE(r.unit.pous[0].sections[1].retain);
  EXPECT_EQ(r.unit.pous[0].sections[1].decls.size(), 2u);
  EXPECT_EQ(r.unit.pous[0].body.size(), 1u);
}

TEST(StParser, MissingEndsAndUnsupportedConstructs) {
  EXPECT_EQ(errors_of("FUNCTION_BLOCK a\nx := 1;\nPROGRAM b\nEND_PROGRAM\n"),
            (std::vector<std::string>{"e.st:3:1: expected END_FUNCTION_BLOCK, found PROGRAM"}));
  EXPECT_EQ(errors_of("PROGRAM p\nIF a THEN\n"),
            (std::vector<std::string>{"e.st:3:1: expected END_IF, found end of file",
                                      "e.st:3:1: expected END_PROGRAM, found end of file"}));
  EXPECT_EQ(errors_of("PROGRAM p\nx := p^;\nEND_PROGRAM\n"),
            (std::vector<std::string>{"e.st:2:7: pointer dereference '^' is not supported (no pointers in syncplc's ST)"}));
  EXPECT_EQ(errors_of("FUNCTION f\nEND_FUNCTION\n"),
            (std::vector<std::string>{"e.st:2:1: expected ':' and the function's return type, found END_FUNCTION"}));
}

TEST(StParser, NestingBeyondTheLimitIsOneClearError) {
  const std::string deep_parens = "PROGRAM p\nx := " + std::string(100000, '(') + "1;\nEND_PROGRAM\n";
  std::vector<std::string> e = errors_of(deep_parens);
  ASSERT_EQ(e.size(), 1u);
  EXPECT_NE(e[0].find("nesting deeper than 256 levels"), std::string::npos) << e[0];
  std::string ifs = "PROGRAM p\n";
  for (int i = 0; i < 5000; ++i) ifs += "IF a THEN\n";
  e = errors_of(ifs);
  ASSERT_EQ(e.size(), 1u);
  EXPECT_NE(e[0].find("nesting deeper than 256 levels"), std::string::npos) << e[0];
  std::string chain = "PROGRAM p\nx := a";
  for (int i = 0; i < 100000; ++i) chain += " + a";
  e = errors_of(chain + ";\nEND_PROGRAM\n");
  ASSERT_EQ(e.size(), 1u);
  std::string unary = "PROGRAM p\nx := ";
  for (int i = 0; i < 100000; ++i) unary += "NOT ";
  e = errors_of(unary + "a;\nEND_PROGRAM\n");
  ASSERT_EQ(e.size(), 1u);
  // Every other recursive construct: postfix chains, calls, initial values, types, CASE.
  auto repeated = [](const std::string& head, const std::string& unit, int n, const std::string& tail) {
    std::string out = head;
    for (int i = 0; i < n; ++i) out += unit;
    return out + tail;
  };
  for (const std::string& src : {
           repeated("PROGRAM p\nx := a", "[1]", 100000, ";\nEND_PROGRAM\n"),
           repeated("PROGRAM p\nx := a", ".b", 100000, ";\nEND_PROGRAM\n"),
           repeated("PROGRAM p\nx := ", "f(", 100000, ";\nEND_PROGRAM\n"),
           repeated("PROGRAM p\nVAR x : INT := ", "[", 100000, ";\nEND_VAR END_PROGRAM\n"),
           repeated("PROGRAM p\nVAR x : INT := ", "(a := ", 100000, ";\nEND_VAR END_PROGRAM\n"),
           repeated("TYPE t : ", "ARRAY[1..2] OF ", 100000, "INT; END_TYPE\n"),
           repeated("TYPE t : ", "STRUCT a : ", 100000, "INT; END_TYPE\n"),
           repeated("PROGRAM p\n", "CASE x OF 1: ", 5000, "\nEND_PROGRAM\n"),
       }) {
    e = errors_of(src);
    ASSERT_EQ(e.size(), 1u) << src.substr(0, 40);
    EXPECT_NE(e[0].find("nesting deeper than 256 levels"), std::string::npos) << e[0];
  }
  // Within the limit: 200 levels parse.
  EXPECT_TRUE(parse("PROGRAM p\nx := " + std::string(200, '(') + "1" + std::string(200, ')') + ";\nEND_PROGRAM\n",
                    SourceFile("ok.st")).ok());
}

}  // namespace
}  // namespace syncplc::st
