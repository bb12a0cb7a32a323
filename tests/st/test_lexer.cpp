// The Structured Text lexer: each literal kind, positions, comments,
// pragmas, direct addresses, and each lexical error at its line:col with
// lexing going on after it.
#include <gtest/gtest.h>

#include "runtime/st/lexer.hpp"

namespace syncplc::st {
namespace {

struct Lexed {
  std::vector<Token> tokens;
  StDiagnostics diags;
};

Lexed lex_text(std::string_view src) {
  Lexed l;
  l.tokens = lex(src, SourceFile("t.st"), l.diags);
  return l;
}

std::vector<std::string> errors(const Lexed& l) {
  std::vector<std::string> out;
  for (const auto& d : l.diags.list()) out.push_back(d.text());
  return out;
}

// The one token of `src` (besides End), lexed without error.
Token single(std::string_view src) {
  Lexed l = lex_text(src);
  EXPECT_TRUE(l.diags.list().empty()) << src << ": " << (l.diags.list().empty() ? "" : l.diags.list()[0].text());
  EXPECT_EQ(l.tokens.size(), 2u) << src;
  return l.tokens.empty() ? Token{} : l.tokens[0];
}

TEST(StLexer, IdentifiersAndKeywordsAreCaseInsensitiveAndKeepTheirSpelling) {
  Lexed l = lex_text("Motor_1 end_if End_Function_Block x");
  ASSERT_EQ(l.tokens.size(), 5u);
  EXPECT_EQ(l.tokens[0].kind, TokenKind::Identifier);
  EXPECT_EQ(l.tokens[0].text, "Motor_1");
  EXPECT_EQ(l.tokens[1].kind, TokenKind::KwEndIf);
  EXPECT_EQ(l.tokens[2].kind, TokenKind::KwEndFunctionBlock);
  EXPECT_EQ(l.tokens[3].kind, TokenKind::Identifier);
  EXPECT_EQ(l.tokens[4].kind, TokenKind::End);
}

TEST(StLexer, EveryKeywordOfTheLanguage) {
  const char* words[] = {"FUNCTION", "END_FUNCTION", "FUNCTION_BLOCK", "END_FUNCTION_BLOCK", "PROGRAM",
                         "END_PROGRAM", "TYPE", "END_TYPE", "STRUCT", "END_STRUCT", "ARRAY", "OF", "STRING",
                         "WSTRING", "VAR", "VAR_INPUT", "VAR_OUTPUT", "VAR_IN_OUT", "VAR_TEMP", "VAR_EXTERNAL",
                         "VAR_GLOBAL", "END_VAR", "CONSTANT", "RETAIN", "NON_RETAIN", "PERSISTENT", "AT", "IF",
                         "THEN", "ELSIF", "ELSE", "END_IF", "CASE", "END_CASE", "FOR", "TO", "BY", "DO", "END_FOR",
                         "WHILE", "END_WHILE", "REPEAT", "UNTIL", "END_REPEAT", "EXIT", "CONTINUE", "RETURN", "NOT",
                         "AND", "OR", "XOR", "MOD", "TRUE", "FALSE"};
  for (const char* w : words) {
    const Token t = single(w);
    EXPECT_TRUE(is_keyword(t.kind)) << w;
    EXPECT_EQ(describe(t.kind), w);
  }
}

TEST(StLexer, PositionsAreLineAndColumnFromOne) {
  Lexed l = lex_text("x :=\n  y + 1;\n\t(* c *) z");
  ASSERT_GE(l.tokens.size(), 7u);
  EXPECT_EQ(l.tokens[0].loc.text(), "t.st:1:1");
  EXPECT_EQ(l.tokens[1].loc.text(), "t.st:1:3");
  EXPECT_EQ(l.tokens[2].loc.text(), "t.st:2:3");
  EXPECT_EQ(l.tokens[3].loc.text(), "t.st:2:5");
  EXPECT_EQ(l.tokens[4].loc.text(), "t.st:2:7");
  EXPECT_EQ(l.tokens[5].loc.text(), "t.st:2:8");
  EXPECT_EQ(l.tokens[6].loc.text(), "t.st:3:10");
}

TEST(StLexer, IntegerLiterals) {
  EXPECT_EQ(single("1_000").int_value, 1000u);
  EXPECT_EQ(single("16#FF").int_value, 255u);
  EXPECT_EQ(single("16#ff").int_value, 255u);
  EXPECT_EQ(single("2#1010_1010").int_value, 0xAAu);
  EXPECT_EQ(single("8#17").int_value, 15u);
  EXPECT_EQ(single("18446744073709551615").int_value, 18446744073709551615u);
  const Token typed = single("INT#5");
  EXPECT_EQ(typed.kind, TokenKind::Integer);
  EXPECT_EQ(typed.type_prefix, "INT");
  EXPECT_EQ(typed.int_value, 5u);
  const Token neg = single("int#-5");
  EXPECT_EQ(neg.type_prefix, "INT");
  EXPECT_TRUE(neg.negative);
  const Token based = single("WORD#16#FFFF");
  EXPECT_EQ(based.type_prefix, "WORD");
  EXPECT_EQ(based.int_value, 0xFFFFu);
  const Token b = single("BOOL#TRUE");
  EXPECT_EQ(b.type_prefix, "BOOL");
  EXPECT_EQ(b.int_value, 1u);
}

TEST(StLexer, RealLiterals) {
  EXPECT_EQ(single("1.5").real_value, 1.5);
  EXPECT_EQ(single("1.5E3").real_value, 1500.0);
  EXPECT_EQ(single("1.5e-3").real_value, 0.0015);
  EXPECT_EQ(single("1_000.0").real_value, 1000.0);
  const Token t = single("LREAL#1.5");
  EXPECT_EQ(t.kind, TokenKind::Real);
  EXPECT_EQ(t.type_prefix, "LREAL");
  const Token i = single("REAL#2");
  EXPECT_EQ(i.kind, TokenKind::Integer);  // REAL#2: an integer written for a REAL, typed later
  EXPECT_EQ(i.type_prefix, "REAL");
}

TEST(StLexer, Durations) {
  const Token t = single("T#1s200ms");
  EXPECT_EQ(t.kind, TokenKind::Duration);
  EXPECT_EQ(t.type_prefix, "TIME");
  EXPECT_EQ(t.duration_ns, 1'200'000'000);
  EXPECT_EQ(single("TIME#-5ms").duration_ns, -5'000'000);
  const Token lt = single("LTIME#1d2h");
  EXPECT_EQ(lt.type_prefix, "LTIME");
  EXPECT_EQ(lt.duration_ns, (24 + 2) * 3600LL * 1'000'000'000LL);
  EXPECT_EQ(single("T#1.5s").duration_ns, 1'500'000'000);
  EXPECT_EQ(single("t#1h_30m").duration_ns, 90LL * 60 * 1'000'000'000LL);
  EXPECT_EQ(single("T#3m4s5ms6us7ns").duration_ns, 184'005'006'007LL);
  EXPECT_EQ(single("LT#1MS").duration_ns, 1'000'000);
}

TEST(StLexer, DatesAndTimesOfDay) {
  const Token d = single("D#2024-01-31");
  EXPECT_EQ(d.kind, TokenKind::Date);
  EXPECT_EQ(d.str_value, "2024-01-31");
  EXPECT_EQ(single("DATE#2024-02-29").type_prefix, "DATE");
  const Token tod = single("TOD#12:30:00.5");
  EXPECT_EQ(tod.kind, TokenKind::TimeOfDay);
  EXPECT_EQ(tod.str_value, "12:30:00.5");
  EXPECT_EQ(single("TIME_OF_DAY#23:59:59").type_prefix, "TOD");
  const Token dt = single("DT#2024-01-31-12:30:00");
  EXPECT_EQ(dt.kind, TokenKind::DateAndTime);
  EXPECT_EQ(dt.str_value, "2024-01-31-12:30:00");
  EXPECT_EQ(single("DATE_AND_TIME#2024-01-31-00:00:00.125").type_prefix, "DT");
}

TEST(StLexer, StringsWithEscapes) {
  EXPECT_EQ(single("'it$'s'").str_value, "it's");
  EXPECT_EQ(single("'$$5'").str_value, "$5");
  EXPECT_EQ(single("'a$Lb$Nc$Pd$Re$Tf'").str_value, "a\nb\nc\fd\re\tf");
  EXPECT_EQ(single("'$0A$41'").str_value, "\nA");
  EXPECT_EQ(single("'say \"hi\"'").str_value, "say \"hi\"");
  EXPECT_EQ(single("''").str_value, "");
  const Token w = single("\"W$00e9$\"\"");
  EXPECT_EQ(w.kind, TokenKind::WString);
  EXPECT_EQ(w.str_value, "W\xC3\xA9\"");
  const Token typed = single("STRING#'abc'");
  EXPECT_EQ(typed.kind, TokenKind::String);
  EXPECT_EQ(typed.type_prefix, "STRING");
}

TEST(StLexer, CommentsNestAndTheLastOneBeforeATokenIsKept) {
  Lexed l = lex_text("(* outer (* inner *) still outer *) a /* b /* c */ d */ b // line\n c");
  ASSERT_TRUE(l.diags.list().empty()) << errors(l)[0];
  ASSERT_EQ(l.tokens.size(), 4u);
  EXPECT_EQ(l.tokens[0].text, "a");
  EXPECT_EQ(l.tokens[0].comment_before, "outer (* inner *) still outer");
  EXPECT_EQ(l.tokens[1].text, "b");
  EXPECT_EQ(l.tokens[2].text, "c");
  EXPECT_EQ(l.tokens[2].comment_before, "line");
}

TEST(StLexer, LongDateAndTimePrefixesAndQuotesInStrings) {
  EXPECT_EQ(single("LD#2024-01-31").type_prefix, "LDATE");
  EXPECT_EQ(single("LDATE#2024-01-31").kind, TokenKind::Date);
  EXPECT_EQ(single("LTOD#01:02:03").type_prefix, "LTOD");
  EXPECT_EQ(single("LTIME_OF_DAY#01:02:03.123456789").kind, TokenKind::TimeOfDay);
  EXPECT_EQ(single("LDT#2024-01-31-01:02:03").type_prefix, "LDT");
  EXPECT_EQ(single("LDATE_AND_TIME#2024-01-31-01:02:03").kind, TokenKind::DateAndTime);
  EXPECT_EQ(single("'a$\"b'").str_value, "a\"b");
  EXPECT_EQ(single("\"it's\"").str_value, "it's");
  EXPECT_EQ(single("WSTRING#\"w\"").type_prefix, "WSTRING");
}

TEST(StLexer, EachCommentKindNestsOnlyWithinItself) {
  // '/*' inside '(* *)' is text: the comment ends at the first '*)'.
  Lexed l = lex_text("(* a /* b *) x /* c (* d */ y");
  ASSERT_TRUE(l.diags.list().empty()) << errors(l)[0];
  ASSERT_EQ(l.tokens.size(), 3u);
  EXPECT_EQ(l.tokens[0].text, "x");
  EXPECT_EQ(l.tokens[1].text, "y");
}

TEST(StLexer, PragmasAreTokens) {
  Lexed l = lex_text("{attribute 'hide'} x");
  ASSERT_EQ(l.tokens.size(), 3u);
  EXPECT_EQ(l.tokens[0].kind, TokenKind::Pragma);
  EXPECT_EQ(l.tokens[0].str_value, "attribute 'hide'");
}

TEST(StLexer, DirectAddresses) {
  for (const char* a : {"%IX0.0", "%QW4", "%MD10", "%I*", "%Q*", "%IX1.2.3", "%IW100", "%ML2", "%QB7"}) {
    const Token t = single(a);
    EXPECT_EQ(t.kind, TokenKind::DirectAddress) << a;
    EXPECT_EQ(t.text, a);
  }
}

TEST(StLexer, OperatorsAndPunctuation) {
  Lexed l = lex_text(":= => .. ** <= >= <> < > = & ^ # [ ] ( ) , ; : . + - * /");
  const TokenKind want[] = {TokenKind::Assign, TokenKind::OutputAssign, TokenKind::DotDot, TokenKind::Power,
                            TokenKind::LessEqual, TokenKind::GreaterEqual, TokenKind::NotEqual, TokenKind::Less,
                            TokenKind::Greater, TokenKind::Equal, TokenKind::Ampersand, TokenKind::Caret,
                            TokenKind::Hash, TokenKind::LBracket, TokenKind::RBracket, TokenKind::LParen,
                            TokenKind::RParen, TokenKind::Comma, TokenKind::Semicolon, TokenKind::Colon,
                            TokenKind::Dot, TokenKind::Plus, TokenKind::Minus, TokenKind::Star, TokenKind::Slash,
                            TokenKind::End};
  ASSERT_EQ(l.tokens.size(), std::size(want));
  for (std::size_t i = 0; i < std::size(want); ++i) EXPECT_EQ(l.tokens[i].kind, want[i]) << i;
}

TEST(StLexer, RangeAfterAnIntegerIsNotAReal) {
  Lexed l = lex_text("1..10");
  ASSERT_EQ(l.tokens.size(), 4u);
  EXPECT_EQ(l.tokens[0].kind, TokenKind::Integer);
  EXPECT_EQ(l.tokens[1].kind, TokenKind::DotDot);
  EXPECT_EQ(l.tokens[2].kind, TokenKind::Integer);
}

TEST(StLexer, ErrorsAtTheirPlaceAndLexingGoesOn) {
  Lexed l = lex_text(
      "a := 2#102;\n"          // digit out of base
      "b := T#5x;\n"           // bad duration unit
      "c := 'open\n"           // unterminated string
      "d := 7#1; e := 1__0;\n" // bad base, double underscore
      "f := 1E3; g := 5ab;\n"  // real without '.', number run into letters
      "h := ? ;\n"             // unknown character
      "i := T#5s3m; j := %QZ1; k := D#2024-13-01;\n"
      "l := 'bad $q escape';\n"
      "(* never closed");
  EXPECT_EQ(errors(l), (std::vector<std::string>{
                           "t.st:1:10: digit '2' is not a base-2 digit",
                           "t.st:2:6: bad duration unit 'x' (d, h, m, s, ms, us, ns)",
                           "t.st:3:6: string not closed: \"'\" missing before the end of the line",
                           "t.st:4:6: bad integer literal: base 7 (IEC 61131-3 has 2#, 8# and 16#)",
                           "t.st:4:16: bad integer literal '1__0': an '_' goes only between digits",
                           "t.st:5:6: bad REAL literal '1E3': IEC 61131-3 needs a '.' before the exponent (e.g. 1.0E3)",
                           "t.st:5:16: bad number: 'ab' right after its digits",
                           "t.st:6:6: unexpected character '?'",
                           "t.st:7:6: bad duration 'T#5s3m': units go from days down to nanoseconds, each once",
                           "t.st:7:19: bad direct address '%QZ1' (e.g. %IX0.0, %QW4, %MD10, %I*)",
                           "t.st:7:30: bad DATE literal '2024-13-01' (expected YYYY-MM-DD)",
                           "t.st:8:11: bad escape in a string: '$q' ($$, $', $\", $L, $N, $P, $R, $T or $hh)",
                           "t.st:9:1: comment '(*' is not closed by '*)'",
                       }));
  // The statements around the errors still lex: 'b' on line 2, ';' after the bad duration.
  int names = 0;
  for (const auto& t : l.tokens) names += t.kind == TokenKind::Identifier;
  EXPECT_EQ(names, 12);
}

TEST(StLexer, FractionOnlyOnTheLastDurationUnit) {
  Lexed l = lex_text("T#1.5s200ms");
  ASSERT_EQ(errors(l).size(), 1u);
  EXPECT_EQ(errors(l)[0], "t.st:1:1: bad duration 'T#1.5s200ms': only the last unit may have a fraction");
}

TEST(StLexer, IntegerTooLargeAndUnclosedThings) {
  Lexed l = lex_text("18446744073709551616 16#1_0000_0000_0000_0000 /* open\n");
  EXPECT_EQ(errors(l), (std::vector<std::string>{
                           "t.st:1:1: integer literal '18446744073709551616' does not fit in 64 bits",
                           "t.st:1:22: integer literal '16#1_0000_0000_0000_0000' does not fit in 64 bits",
                           "t.st:1:47: comment '/*' is not closed by '*/'",
                       }));
  Lexed p = lex_text("{ pragma never closed");
  EXPECT_EQ(errors(p), (std::vector<std::string>{"t.st:1:1: pragma '{' is not closed by '}'"}));
}

TEST(StLexer, ByteOrderMarkAndCrLfLineEnds) {
  Lexed l = lex_text("\xEF\xBB\xBFx :=\r\n 'a';\r\n");
  ASSERT_TRUE(l.diags.list().empty()) << errors(l)[0];
  ASSERT_EQ(l.tokens.size(), 5u);
  EXPECT_EQ(l.tokens[0].loc.text(), "t.st:1:1");
  EXPECT_EQ(l.tokens[2].loc.text(), "t.st:2:2");
  EXPECT_EQ(l.tokens[2].str_value, "a");
}

TEST(StLexer, NonAsciiBytesAreOneError) {
  Lexed l = lex_text("x \xC3\xA9 y");
  EXPECT_EQ(errors(l), (std::vector<std::string>{"t.st:1:3: unexpected character byte 0xC3"}));
  ASSERT_EQ(l.tokens.size(), 4u);
  EXPECT_EQ(l.tokens[2].text, "y");
}

}  // namespace
}  // namespace syncplc::st
