// The tokens of IEC 61131-3 (3rd edition) Structured Text, each with its
// place in the file: what the lexer hands the parser.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>

#include "runtime/core/config_node.hpp"

namespace syncplc::st {

enum class TokenKind {
  End,         // end of the file
  Identifier,  // text: as written; compared case-insensitively (upper())
  // Literals; a typed literal's type (INT#5) is in Token::type_prefix.
  Integer,   // int_value (the magnitude; a sign is the unary minus)
  Real,      // real_value
  Duration,  // duration_ns (T#, TIME#, LTIME#)
  Date,      // str_value: the date as written after the prefix (D#2024-01-31)
  TimeOfDay,
  DateAndTime,
  String,   // str_value: the characters, escapes decoded
  WString,  // str_value: UTF-8 of the characters
  DirectAddress,  // text: %IX0.0, %QW4, %I*
  Pragma,         // {…}: the parser skips it with a note
  // Punctuation and operators.
  LParen, RParen, LBracket, RBracket, Comma, Semicolon, Colon, Assign /* := */, OutputAssign /* => */,
  Dot, DotDot, Hash, Plus, Minus, Star, Slash, Power /* ** */, Ampersand, Equal, NotEqual, Less,
  LessEqual, Greater, GreaterEqual, Caret,
  // Keywords (case-insensitive).
  KwFunction, KwEndFunction, KwFunctionBlock, KwEndFunctionBlock, KwProgram, KwEndProgram,
  KwType, KwEndType, KwStruct, KwEndStruct, KwArray, KwOf, KwString, KwWString,
  KwVar, KwVarInput, KwVarOutput, KwVarInOut, KwVarTemp, KwVarExternal, KwVarGlobal, KwEndVar,
  KwConstant, KwRetain, KwNonRetain, KwPersistent, KwAt,
  KwIf, KwThen, KwElsif, KwElse, KwEndIf, KwCase, KwEndCase, KwFor, KwTo, KwBy, KwDo, KwEndFor,
  KwWhile, KwEndWhile, KwRepeat, KwUntil, KwEndRepeat, KwExit, KwContinue, KwReturn,
  KwNot, KwAnd, KwOr, KwXor, KwMod, KwTrue, KwFalse,
  Error,  // a character or literal the lexer reported; the parser skips it silently
};

struct Token {
  TokenKind kind = TokenKind::End;
  SourceLoc loc;
  std::string text;         // the source text as written
  std::string type_prefix;  // typed literal: the type before '#', upper case ("INT", "LREAL", "TIME")
  std::uint64_t int_value = 0;
  bool negative = false;  // INT#-5, REAL#-1.5: the sign inside a typed literal
  double real_value = 0;
  std::int64_t duration_ns = 0;
  std::string str_value;
  // The comments before this token on adjacent lines, without their
  // delimiters, joined by newlines (a POU's documentation).
  std::string comment_before;
  // Whether they stand directly before it: on lines of their own, ending on
  // the line before it (not a trailing comment of the previous token's line,
  // not separated by a blank line).
  bool comment_directly_before = false;
};

// How a kind reads in messages: "';'", "END_IF", "identifier".
std::string_view describe(TokenKind kind);
// How a token reads in messages: "identifier 'foo'", "END_IF", "end of file".
std::string describe(const Token& token);
// The keyword spelt by `upper` (an identifier in upper case), or Identifier.
TokenKind keyword_kind(std::string_view upper);
bool is_keyword(TokenKind kind);
std::string upper(std::string_view text);

}  // namespace syncplc::st
