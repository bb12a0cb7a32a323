// The Structured Text lexer: source text to tokens, each with file:line:col
// (columns count bytes from 1). Lexical errors (an unterminated comment or
// string, a bad literal, an unknown character) are reported at their place
// and lexing goes on, so one run finds them all.
#pragma once

#include <string_view>
#include <vector>

#include "runtime/st/diagnostic.hpp"
#include "runtime/st/token.hpp"

namespace syncplc::st {

// Tokens of `source`, ending with one TokenKind::End. Never throws for any input.
std::vector<Token> lex(std::string_view source, const SourceFile& file, StDiagnostics& diagnostics);

}  // namespace syncplc::st
