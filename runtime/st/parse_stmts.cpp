// The parser's statements: statement lists and their recovery after an
// error, assignments and calls, IF, CASE, FOR, WHILE, REPEAT, EXIT,
// CONTINUE, RETURN.
#include <string>

#include <fmt/format.h>

#include "runtime/st/parser_state.hpp"

namespace syncplc::st::parsing {

// Whether the tokens here start a CASE label (1:, 1, 2:, 1..5:, Red:, Colour#Red:, -1:).
bool Parser::at_case_label() const {
  switch (cur().kind) {
    case K::Integer: case K::Minus: case K::Plus: case K::Real: case K::Duration: case K::String:
      return true;
    case K::Identifier: {
      const K k = peek(1).kind;
      return k == K::Colon || k == K::Comma || k == K::DotDot || k == K::Hash;
    }
    default:
      return false;
  }
}

std::vector<Statement> Parser::statement_list(bool in_case) {
  std::vector<Statement> list;
  bool after_error = false;
  for (;;) {
    const K k = cur().kind;
    // The END_VAR of a misspelt section (VAR_INPT x : INT; END_VAR), already
    // reported: skipped rather than taken as the end of the body.
    if (after_error && k == K::KwEndVar) {
      advance();
      accept(K::Semicolon);
      continue;
    }
    if (k == K::End || is_end_keyword(k) || k == K::KwElsif || k == K::KwElse || k == K::KwUntil ||
        is_pou_start(k) || (in_case && at_case_label()))
      break;
    if (is_section_start(k)) {
      expected("a statement (variable sections go before the first statement)");
      var_section();
      continue;
    }
    const std::size_t before = pos_;
    Statement s = statement();
    after_error = panic_;
    if (panic_) {
      recover();
    } else {
      list.push_back(std::move(s));
    }
    if (pos_ == before) advance();
  }
  return list;
}

// After a syntax error in a statement: skip to the next ';' or the THEN,
// DO or OF that ends a statement's head (taken), or to a keyword that
// starts or ends a statement (left for the list).
void Parser::recover() {
  while (!at(K::End)) {
    const K k = cur().kind;
    if (k == K::Semicolon || k == K::KwThen || k == K::KwDo || k == K::KwOf) {
      advance();
      break;
    }
    if (is_end_keyword(k) || is_statement_start(k) || k == K::KwElsif || k == K::KwElse || k == K::KwUntil ||
        is_pou_start(k) || is_section_start(k))
      break;
    advance();
  }
  panic_ = false;
}

Statement Parser::statement() {
  Depth guard(*this);
  Statement s;
  s.loc = cur().loc;
  if (too_deep()) return s;
  switch (cur().kind) {
    case K::Semicolon:
      advance();
      s.kind = StmtKind::Empty;
      return s;
    case K::KwIf: return if_statement(s);
    case K::KwCase: return case_statement(s);
    case K::KwFor: return for_statement(s);
    case K::KwWhile: return while_statement(s);
    case K::KwRepeat: return repeat_statement(s);
    case K::KwExit: advance(); s.kind = StmtKind::Exit; expect_semicolon(); return s;
    case K::KwContinue: advance(); s.kind = StmtKind::Continue; expect_semicolon(); return s;
    case K::KwReturn: advance(); s.kind = StmtKind::Return; expect_semicolon(); return s;
    case K::Identifier: break;
    default:
      expected("a statement");
      return s;
  }
  const Token& first = cur();
  Expr e = variable_or_call();
  if (panic_) return s;
  if (accept(K::Assign)) {
    s.kind = StmtKind::Assign;
    s.target = std::move(e);
    s.value = expression();
    if (!panic_) expect_semicolon();
    return s;
  }
  if (e.kind == ExprKind::Call) {
    s.kind = StmtKind::Call;
    s.value = std::move(e);
    expect_semicolon();
    return s;
  }
  if (!panic_ && !too_deep_ && !after_lexical_error()) {
    std::string msg = fmt::format("expected ':=' or a call after '{}', found {}", first.text, describe(cur()));
    if (e.kind == ExprKind::Name)
      if (const std::string near = closest_name(upper(first.text), keyword_spellings()); !near.empty())
        msg += fmt::format(" (did you mean {}?)", near);
    diags_.error(cur().loc, std::move(msg));
  }
  panic_ = true;
  return s;
}

Statement Parser::if_statement(Statement& s) {
  s.kind = StmtKind::If;
  do {
    IfBranch b;
    b.loc = cur().loc;
    advance();  // IF / ELSIF
    b.condition = expression();
    if (!panic_) expect(K::KwThen, "THEN");
    if (panic_) {
      recover();
      accept(K::KwThen);
    }
    b.body = statement_list();
    s.branches.push_back(std::move(b));
  } while (at(K::KwElsif));
  if (accept(K::KwElse)) {
    s.has_else = true;
    s.else_body = statement_list();
  }
  expect_end(K::KwEndIf);
  panic_ = false;
  return s;
}

Statement Parser::case_statement(Statement& s) {
  s.kind = StmtKind::Case;
  advance();
  s.value = expression();
  if (!panic_) expect(K::KwOf, "OF");
  if (panic_) {
    recover();
    accept(K::KwOf);
  }
  while (at_case_label()) {
    CaseBranch b;
    b.loc = cur().loc;
    do {
      CaseLabel l;
      l.loc = cur().loc;
      l.low = expression();
      if (!panic_ && accept(K::DotDot)) l.high = expression();
      b.labels.push_back(std::move(l));
    } while (!panic_ && accept(K::Comma));
    if (!panic_) expect(K::Colon, "':' after the case labels");
    if (panic_) recover();
    b.body = statement_list(true);
    s.cases.push_back(std::move(b));
  }
  if (accept(K::KwElse)) {
    s.has_else = true;
    s.else_body = statement_list();
  }
  expect_end(K::KwEndCase);
  panic_ = false;
  return s;
}

Statement Parser::for_statement(Statement& s) {
  s.kind = StmtKind::For;
  advance();
  s.target.loc = cur().loc;
  s.target.name = name("the FOR loop's control variable");
  s.target.kind = ExprKind::Name;
  if (!panic_) expect(K::Assign, "':='");
  if (!panic_) s.value = expression();
  if (!panic_) expect(K::KwTo, "TO");
  if (!panic_) s.to = expression();
  if (!panic_ && accept(K::KwBy)) s.by = expression();
  if (!panic_) expect(K::KwDo, "DO");
  if (panic_) {
    recover();
    accept(K::KwDo);
  }
  s.body = statement_list();
  expect_end(K::KwEndFor);
  panic_ = false;
  return s;
}

Statement Parser::while_statement(Statement& s) {
  s.kind = StmtKind::While;
  advance();
  s.value = expression();
  if (!panic_) expect(K::KwDo, "DO");
  if (panic_) {
    recover();
    accept(K::KwDo);
  }
  s.body = statement_list();
  expect_end(K::KwEndWhile);
  panic_ = false;
  return s;
}

Statement Parser::repeat_statement(Statement& s) {
  s.kind = StmtKind::Repeat;
  advance();
  s.body = statement_list();
  if (expect(K::KwUntil, "UNTIL")) s.value = expression();
  if (panic_) recover();
  expect_end(K::KwEndRepeat);
  panic_ = false;
  return s;
}

}  // namespace syncplc::st::parsing
