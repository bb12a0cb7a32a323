// The Structured Text parser: recursive descent over the lexer's tokens,
// precedence climbing for expressions, into the AST of ast.hpp. No types are
// checked here (the next stage does). Every syntax error is reported as
// "expected X, found Y" at its place; the parser then resynchronises (at ';',
// END_IF, END_VAR, END_FUNCTION_BLOCK, …) so one run finds all of a file's
// errors. Nesting (expressions and statements together, operator chains
// counted) is limited to kMaxNesting levels, so hostile input cannot exhaust
// the stack of the parser or of the passes that walk the tree after it.
#pragma once

#include <string_view>

#include "runtime/st/ast.hpp"
#include "runtime/st/diagnostic.hpp"

namespace syncplc::st {

inline constexpr int kMaxNesting = 256;

struct ParseResult {
  CompilationUnit unit;
  StDiagnostics diagnostics;  // the lexer's and the parser's, in the order found
  bool ok() const { return !diagnostics.has_errors(); }
};

// Lexes and parses one source file. Never throws for any input (a failed
// allocation aside).
ParseResult parse(std::string_view source, const SourceFile& file);

}  // namespace syncplc::st
