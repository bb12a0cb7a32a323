// The Structured Text parser's shared state: one recursive-descent class
// whose stages are split over parser.cpp (the driver: pragmas, the top level,
// errors, resynchronisation and the nesting limit), parse_decls.cpp (POUs,
// TYPE, VAR sections, type specs, initial values), parse_stmts.cpp
// (statements) and parse_exprs.cpp (expressions, literals, calls). Internal
// to runtime/st: the interface is parser.hpp.
#pragma once

#include <algorithm>
#include <cstddef>
#include <string>
#include <string_view>
#include <vector>

#include "runtime/st/ast.hpp"
#include "runtime/st/diagnostic.hpp"
#include "runtime/st/parser.hpp"
#include "runtime/st/token.hpp"

namespace syncplc::st::parsing {

using K = TokenKind;

inline bool is_end_keyword(K k) {
  switch (k) {
    case K::KwEndFunction: case K::KwEndFunctionBlock: case K::KwEndProgram: case K::KwEndType:
    case K::KwEndStruct: case K::KwEndVar: case K::KwEndIf: case K::KwEndCase: case K::KwEndFor:
    case K::KwEndWhile: case K::KwEndRepeat:
      return true;
    default:
      return false;
  }
}

inline bool is_statement_end(K k) {
  return k == K::KwEndIf || k == K::KwEndCase || k == K::KwEndFor || k == K::KwEndWhile || k == K::KwEndRepeat;
}

inline bool is_pou_start(K k) {
  return k == K::KwFunction || k == K::KwFunctionBlock || k == K::KwProgram || k == K::KwType ||
         (k == K::KwVarGlobal);
}

inline bool is_section_start(K k) {
  return k == K::KwVar || k == K::KwVarInput || k == K::KwVarOutput || k == K::KwVarInOut || k == K::KwVarTemp ||
         k == K::KwVarExternal || k == K::KwVarGlobal;
}

inline bool is_statement_start(K k) {
  return k == K::KwIf || k == K::KwCase || k == K::KwFor || k == K::KwWhile || k == K::KwRepeat ||
         k == K::KwExit || k == K::KwContinue || k == K::KwReturn;
}

// The keywords a misspelt word is compared with for "did you mean".
const std::vector<std::string_view>& keyword_spellings();

class Parser {
 public:
  Parser(std::vector<Token> tokens, const SourceFile& file, StDiagnostics& diags);
  CompilationUnit run();

 private:
  // ---- Tokens ----
  const Token& cur() const { return tokens_[pos_]; }
  const Token& peek(std::size_t ahead) const {
    return tokens_[std::min(pos_ + ahead, tokens_.size() - 1)];
  }
  bool at(K k) const { return cur().kind == k; }
  const Token& advance() {
    const Token& t = tokens_[pos_];
    if (pos_ + 1 < tokens_.size()) ++pos_;
    return t;
  }
  bool accept(K k) {
    if (!at(k)) return false;
    advance();
    return true;
  }
  // The lexer reported the token here or the one just before: a syntax
  // error about it would only repeat that.
  bool after_lexical_error() const {
    return cur().kind == K::Error || (pos_ > 0 && tokens_[pos_ - 1].kind == K::Error);
  }

  // ---- Errors, resynchronisation, nesting (parser.cpp) ----
  void expected(std::string_view what);
  bool expect(K k, std::string_view what = {});
  void expect_end(K k);
  void expect_semicolon();
  std::string name(std::string_view what);
  void enter();
  // Too deep: one error, then the rest of the file is skipped (the tree
  // stays within the limit for every later pass).
  struct Depth {
    Parser& p;
    explicit Depth(Parser& parser) : p(parser) { p.enter(); }
    ~Depth() { --p.depth_; }
    Depth(const Depth&) = delete;
    Depth& operator=(const Depth&) = delete;
  };
  bool too_deep() const { return too_deep_; }

  // ---- POUs, TYPE, VAR sections, type specs, initial values (parse_decls.cpp) ----
  Pou pou();
  void type_block();
  K misspelt_section() const;
  VarSection var_section(K as = K::End);
  VarDecl var_decl(bool allow_address);
  TypeSpec type_spec();
  TypeSpec enumeration(TypeSpec& t);
  Subrange subrange();
  Initializer initializer();

  // ---- Statements (parse_stmts.cpp) ----
  bool at_case_label() const;
  std::vector<Statement> statement_list(bool in_case = false);
  void recover();
  Statement statement();
  Statement if_statement(Statement& s);
  Statement case_statement(Statement& s);
  Statement for_statement(Statement& s);
  Statement while_statement(Statement& s);
  Statement repeat_statement(Statement& s);

  // ---- Expressions, literals, calls (parse_exprs.cpp) ----
  static int precedence(K k);
  static BinaryOp binary_op(K k);
  Expr expression();
  Expr binary(int min_prec);
  Expr unary();
  Expr variable_or_call();
  Expr postfix(Expr base);
  static Literal literal_of(const Token& t);
  Expr primary();
  void call_arguments(Expr& e);
  Argument argument();

  std::vector<Token> tokens_;
  std::size_t pos_ = 0;
  StDiagnostics& diags_;
  CompilationUnit unit_;
  bool panic_ = false;
  int depth_ = 0;
  bool too_deep_ = false;
};

}  // namespace syncplc::st::parsing
