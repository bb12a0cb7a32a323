// The parser's driver (see parser_state.hpp for how its stages are split):
// pragmas set aside, the top level of a file, "expected X, found Y" once per
// mistake, the resynchronisation helpers and the nesting limit; parse().
#include "runtime/st/parser.hpp"

#include <string>

#include <fmt/format.h>

#include "runtime/st/lexer.hpp"
#include "runtime/st/parser_state.hpp"

namespace syncplc::st {

namespace parsing {

// The keywords a misspelt word is compared with for "did you mean".
const std::vector<std::string_view>& keyword_spellings() {
  static const std::vector<std::string_view> words = [] {
    std::vector<std::string_view> w;
    for (int k = static_cast<int>(K::KwFunction); k <= static_cast<int>(K::KwFalse); ++k)
      w.push_back(describe(static_cast<K>(k)));
    return w;
  }();
  return words;
}

Parser::Parser(std::vector<Token> tokens, const SourceFile& file, StDiagnostics& diags) : diags_(diags) {
  unit_.file = file;
  // Pragmas are skipped here, with a note; a comment before one stays with the next token.
  tokens_.reserve(tokens.size());
  std::string carried;
  bool carried_directly_before = false;
  for (auto& t : tokens) {
    if (t.kind == K::Pragma) {
      diags_.note(t.loc, fmt::format("pragma '{}' ignored",
                                     t.text.size() > 60 ? t.text.substr(0, 60) + "…" : t.text));
      if (!t.comment_before.empty()) {
        carried = std::move(t.comment_before);
        carried_directly_before = t.comment_directly_before;
      }
      continue;
    }
    if (t.comment_before.empty() && !carried.empty()) {
      t.comment_before = std::move(carried);
      t.comment_directly_before = carried_directly_before;
    }
    carried.clear();
    tokens_.push_back(std::move(t));
  }
}

CompilationUnit Parser::run() {
  while (!at(K::End)) {
    panic_ = false;
    switch (cur().kind) {
      case K::KwFunction: case K::KwFunctionBlock: case K::KwProgram:
        unit_.pous.push_back(pou());
        break;
      case K::KwType:
        type_block();
        break;
      case K::KwVarGlobal:
        unit_.globals.push_back(var_section());
        break;
      default:
        expected("FUNCTION, FUNCTION_BLOCK, PROGRAM, TYPE or VAR_GLOBAL");
        advance();
        while (!at(K::End) && !is_pou_start(cur().kind)) advance();
    }
  }
  return std::move(unit_);
}

// "expected X, found Y" at the current token, once until the parser has
// resynchronised; none for a token the lexer already reported.
void Parser::expected(std::string_view what) {
  if (!panic_ && !too_deep_ && !after_lexical_error()) {
    std::string msg = fmt::format("expected {}, found {}", what, describe(cur()));
    if (cur().kind == K::Identifier)
      if (const std::string near = closest_name(upper(cur().text), keyword_spellings()); !near.empty())
        msg += fmt::format(" (did you mean {}?)", near);
    diags_.error(cur().loc, std::move(msg));
  }
  panic_ = true;
}

bool Parser::expect(K k, std::string_view what) {
  if (accept(k)) return true;
  expected(what.empty() ? describe(k) : what);
  return false;
}

// A statement's closing keyword: a different END_ of a statement is taken
// as the misspelt one (one error, not one per enclosing block).
void Parser::expect_end(K k) {
  if (accept(k)) {
    expect_semicolon();
    return;
  }
  expected(describe(k));
  if (is_statement_end(cur().kind)) {
    advance();
    accept(K::Semicolon);
  }
}

void Parser::expect_semicolon() {
  if (accept(K::Semicolon)) return;
  // Reported without skipping: the next statement is most likely fine.
  expected("';'");
  panic_ = false;
}

std::string Parser::name(std::string_view what) {
  if (at(K::Identifier)) return advance().text;
  expected(what);
  return {};
}

void Parser::enter() {
  if (++depth_ > kMaxNesting && !too_deep_) {
    too_deep_ = true;
    diags_.error(cur().loc, fmt::format("nesting deeper than {} levels (expressions, statements and operator "
                                        "chains together); the rest of the file is not parsed", kMaxNesting));
  }
  if (too_deep_) pos_ = tokens_.size() - 1;
}

}  // namespace parsing

ParseResult parse(std::string_view source, const SourceFile& file) {
  ParseResult r;
  std::vector<Token> tokens = lex(source, file, r.diagnostics);
  r.unit = parsing::Parser(std::move(tokens), file, r.diagnostics).run();
  return r;
}

}  // namespace syncplc::st
