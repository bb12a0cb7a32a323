// The checker's statements: assignment compatibility, BOOL conditions, CASE
// selectors and labels (no two labels overlap), FOR control variables (a
// local integer, not assigned in the body), EXIT and CONTINUE inside loops.
#include <algorithm>

#include <fmt/format.h>

#include "runtime/st/check_context.hpp"

namespace syncplc::st {

namespace {

const char* scope_word(VarScope s) {
  switch (s) {
    case VarScope::Input: return "VAR_INPUT";
    case VarScope::Output: return "VAR_OUTPUT";
    case VarScope::InOut: return "VAR_IN_OUT";
    case VarScope::External: return "VAR_EXTERNAL";
    case VarScope::Global: return "VAR_GLOBAL";
    case VarScope::Return: return "the function's result";
    default: return "VAR";
  }
}

std::string target_name(const Expr& e) {
  switch (e.kind) {
    case ExprKind::Name: return e.name;
    case ExprKind::Member: return target_name(e.operands[0]) + "." + e.name;
    case ExprKind::Index: return target_name(e.operands[0]) + "[…]";
    case ExprKind::BitAccess: return target_name(e.operands[0]) + "." + std::to_string(e.bit);
    default: return "?";
  }
}

}  // namespace

void Checker::body(const std::vector<Statement>& stmts) {
  for (const Statement& s : stmts) statement(s);
}

void Checker::condition(const Expr& e, std::string_view what) { expect(e, elem(Elem::BOOL), what); }

void Checker::statement(const Statement& s) {
  switch (s.kind) {
    case StmtKind::Empty: return;
    case StmtKind::Assign: {
      const Type* t = target(s.target);
      const Val v = expr(s.value, t);
      coerce(s.value, v, t, fmt::format("assignment to '{}'", target_name(s.target)));
      if (t->kind == Type::Kind::FunctionBlock && !v.error())
        error(s.loc, "an FB instance cannot be assigned (it holds the block's state)");
      return;
    }
    case StmtKind::Call:
      if (s.value.kind == ExprKind::Call) call(s.value, true);
      else expr(s.value);
      return;
    case StmtKind::If:
      for (const IfBranch& b : s.branches) {
        condition(b.condition, "IF condition");
        body(b.body);
      }
      body(s.else_body);
      return;
    case StmtKind::Case: return case_statement(s);
    case StmtKind::For: return for_statement(s);
    case StmtKind::While:
    case StmtKind::Repeat:
      if (s.kind == StmtKind::While) condition(s.value, "WHILE condition");
      ++loop_depth_;
      body(s.body);
      --loop_depth_;
      if (s.kind == StmtKind::Repeat) condition(s.value, "UNTIL condition");
      return;
    case StmtKind::Exit:
    case StmtKind::Continue:
      if (loop_depth_ == 0)
        error(s.loc, fmt::format("{} outside a loop (FOR, WHILE or REPEAT)",
                                 s.kind == StmtKind::Exit ? "EXIT" : "CONTINUE"));
      return;
    case StmtKind::Return: return;
  }
}

void Checker::case_statement(const Statement& s) {
  Val sel = expr(s.value);
  const Type* t = sel.type;
  if (!sel.error()) {
    if (sel.lit == Val::Lit::Int) settle_default(s.value, sel);
    const auto e = t->scalar();
    if (t->kind != Type::Kind::Enum && !(e && is_int(*e))) {
      error(s.value.loc, fmt::format("a CASE selector must be an integer (ANY_INT) or an enumeration, found {}",
                                     sel.lit == Val::Lit::Real ? "a real literal" : t->name));
      t = err();
    }
  }
  struct Range {
    Wide low, high;
    SourceLoc loc;
  };
  std::vector<Range> seen;
  for (const CaseBranch& b : s.cases) {
    for (const CaseLabel& l : b.labels) {
      std::optional<Wide> lo, hi;
      for (const Expr* x : {&l.low, &l.high}) {
        if (x->kind == ExprKind::None) continue;
        const Val v = expect(*x, t, "CASE label");
        if (v.error() || t->is_error()) continue;
        if (!v.c) {
          error(x->loc, "a CASE label must be a constant");
          continue;
        }
        (x == &l.low ? lo : hi) = v.c->i;
      }
      if (!lo || (l.high.kind != ExprKind::None && !hi)) continue;
      if (!hi) hi = lo;
      if (*lo > *hi) {
        error(l.loc, "a CASE range's lower bound is above its upper bound");
        continue;
      }
      for (const Range& r : seen)
        if (*lo <= r.high && r.low <= *hi) {
          error(l.loc, fmt::format("CASE label overlaps the label at {}", r.loc.text()));
          break;
        }
      seen.push_back({*lo, *hi, l.loc});
    }
    body(b.body);
  }
  body(s.else_body);
}

void Checker::for_statement(const Statement& s) {
  const Variable* var = nullptr;
  const Type* t = err();
  if (s.target.kind != ExprKind::Name) {
    error(s.target.loc, "a FOR control variable must be a plain variable");
  } else if (!(var = pou_->find(s.target.name))) {
    error(s.target.loc, fmt::format("unknown variable '{}'{}", s.target.name, suggestion(s.target.name)));
    record(s.target, {err()});
  } else {
    info(s.target).symbol = SymbolKind::Variable;
    info(s.target).variable = var;
    record(s.target, {var->type});
    const auto e = var->type->scalar();
    if (!e || !is_int(*e)) {
      if (!var->type->is_error())
        error(s.target.loc, fmt::format("a FOR control variable must be an integer (ANY_INT), '{}' is {}", var->name,
                                        var->type->name));
    } else if (var->scope != VarScope::Local && var->scope != VarScope::Temp) {
      error(s.target.loc, fmt::format("a FOR control variable must be local (VAR or VAR_TEMP), '{}' is {}", var->name,
                                      scope_word(var->scope)));
    } else if (var->constant) {
      error(s.target.loc, fmt::format("'{}' is a CONSTANT and cannot be a FOR control variable", var->name));
    } else if (std::find(for_vars_.begin(), for_vars_.end(), var) != for_vars_.end()) {
      error(s.target.loc, fmt::format("'{}' is already the control variable of an enclosing FOR", var->name));
    } else {
      t = var->type;
    }
  }
  expect(s.value, t, "FOR start");
  expect(s.to, t, "FOR end");
  if (s.by.kind != ExprKind::None) {
    const Val by = expect(s.by, t, "FOR step (BY)");
    if (!by.error() && by.c && !by.c->is_real && by.c->i == 0) error(s.by.loc, "FOR step (BY) 0 never ends the loop");
  }
  if (var) for_vars_.push_back(var);
  ++loop_depth_;
  body(s.body);
  --loop_depth_;
  if (var) for_vars_.pop_back();
}

}  // namespace syncplc::st
