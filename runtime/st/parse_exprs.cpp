// The parser's expressions: precedence climbing over the binary operators,
// unary operators, postfix member, index, bit and call, literals, names,
// enumeration values and call arguments.
#include <cstdint>
#include <utility>

#include "runtime/st/parser_state.hpp"

namespace syncplc::st::parsing {

int Parser::precedence(K k) {
  switch (k) {
    case K::KwOr: return 1;
    case K::KwXor: return 2;
    case K::KwAnd: case K::Ampersand: return 3;
    case K::Equal: case K::NotEqual: return 4;
    case K::Less: case K::Greater: case K::LessEqual: case K::GreaterEqual: return 5;
    case K::Plus: case K::Minus: return 6;
    case K::Star: case K::Slash: case K::KwMod: return 7;
    case K::Power: return 8;
    default: return 0;
  }
}

BinaryOp Parser::binary_op(K k) {
  switch (k) {
    case K::KwOr: return BinaryOp::Or;
    case K::KwXor: return BinaryOp::Xor;
    case K::KwAnd: case K::Ampersand: return BinaryOp::And;
    case K::Equal: return BinaryOp::Equal;
    case K::NotEqual: return BinaryOp::NotEqual;
    case K::Less: return BinaryOp::Less;
    case K::Greater: return BinaryOp::Greater;
    case K::LessEqual: return BinaryOp::LessEqual;
    case K::GreaterEqual: return BinaryOp::GreaterEqual;
    case K::Plus: return BinaryOp::Add;
    case K::Minus: return BinaryOp::Subtract;
    case K::Star: return BinaryOp::Multiply;
    case K::Slash: return BinaryOp::Divide;
    case K::KwMod: return BinaryOp::Mod;
    default: return BinaryOp::Power;
  }
}

Expr Parser::expression() {
  Depth guard(*this);
  if (too_deep()) return {};
  return binary(1);
}

// Precedence climbing; every operator is left-associative (IEC 61131-3
// 3rd edition, table 71), each one applied counts as a level of nesting.
Expr Parser::binary(int min_prec) {
  Expr lhs = unary();
  int chain = 0;
  while (!panic_ && !too_deep()) {
    const int prec = precedence(cur().kind);
    if (prec == 0 || prec < min_prec) break;
    Expr e;
    e.kind = ExprKind::Binary;
    e.loc = cur().loc;
    e.binary_op = binary_op(advance().kind);
    Expr rhs = binary(prec + 1);
    ++chain;
    enter();
    e.operands.push_back(std::move(lhs));
    e.operands.push_back(std::move(rhs));
    lhs = std::move(e);
  }
  depth_ -= chain;
  return lhs;
}

// Negation, unary plus and NOT bind tighter than ** (3rd edition, table 71:
// precedence 8 against 7), so -2 ** 2 is (-2) ** 2.
Expr Parser::unary() {
  if (at(K::Minus) || at(K::Plus) || at(K::KwNot)) {
    Depth guard(*this);
    if (too_deep()) return {};
    Expr e;
    e.kind = ExprKind::Unary;
    e.loc = cur().loc;
    const K k = advance().kind;
    e.unary_op = k == K::Minus ? UnaryOp::Negate : k == K::Plus ? UnaryOp::Plus : UnaryOp::Not;
    e.operands.push_back(unary());
    return e;
  }
  return postfix(primary());
}

Expr Parser::variable_or_call() { return postfix(primary()); }

// a.b[i, j].c, w.3, f(…)
Expr Parser::postfix(Expr base) {
  int chain = 0;
  while (!panic_ && !too_deep()) {
    if (at(K::Dot)) {
      const SourceLoc loc = advance().loc;
      Expr e;
      e.loc = loc;
      if (at(K::Integer) && cur().type_prefix.empty()) {
        e.kind = ExprKind::BitAccess;
        const std::uint64_t bit = advance().int_value;
        e.bit = bit > 63 ? 64 : static_cast<int>(bit);  // the checker reports a bit beyond the type
      } else if (at(K::Identifier)) {
        e.kind = ExprKind::Member;
        e.name = advance().text;
      } else {
        expected("a member name or a bit number after '.'");
        break;
      }
      e.operands.push_back(std::move(base));
      base = std::move(e);
    } else if (at(K::LBracket)) {
      Expr e;
      e.kind = ExprKind::Index;
      e.loc = advance().loc;
      e.operands.push_back(std::move(base));
      do e.operands.push_back(expression());
      while (!panic_ && accept(K::Comma));
      if (!panic_) expect(K::RBracket, "',' or ']'");
      base = std::move(e);
    } else if (at(K::LParen) && (base.kind == ExprKind::Index || base.kind == ExprKind::Member)) {
      // axes[2](…): an FB instance reached through an array or a structure.
      Expr e;
      e.kind = ExprKind::Call;
      e.loc = base.loc;
      e.operands.push_back(std::move(base));
      call_arguments(e);
      base = std::move(e);
    } else if (at(K::Caret)) {
      if (!panic_) diags_.error(cur().loc, "pointer dereference '^' is not supported (no pointers in syncplc's ST)");
      panic_ = true;
      break;
    } else {
      break;
    }
    ++chain;
    enter();
  }
  depth_ -= chain;
  return base;
}

Literal Parser::literal_of(const Token& t) {
  Literal l;
  l.type_prefix = t.type_prefix;
  l.negative = t.negative;
  switch (t.kind) {
    case K::Integer:
      l.kind = t.type_prefix == "BOOL" ? LiteralKind::Bool : LiteralKind::Integer;
      l.int_value = t.int_value;
      break;
    case K::Real: l.kind = LiteralKind::Real; l.real_value = t.real_value; break;
    case K::Duration: l.kind = LiteralKind::Duration; l.duration_ns = t.duration_ns; break;
    case K::Date: l.kind = LiteralKind::Date; l.text = t.str_value; break;
    case K::TimeOfDay: l.kind = LiteralKind::TimeOfDay; l.text = t.str_value; break;
    case K::DateAndTime: l.kind = LiteralKind::DateAndTime; l.text = t.str_value; break;
    case K::String: l.kind = LiteralKind::String; l.text = t.str_value; break;
    case K::WString: l.kind = LiteralKind::WString; l.text = t.str_value; break;
    case K::KwTrue: case K::KwFalse:
      l.kind = LiteralKind::Bool;
      l.int_value = t.kind == K::KwTrue;
      break;
    default: break;
  }
  return l;
}

Expr Parser::primary() {
  Expr e;
  e.loc = cur().loc;
  switch (cur().kind) {
    case K::Integer: case K::Real: case K::Duration: case K::Date: case K::TimeOfDay: case K::DateAndTime:
    case K::String: case K::WString: case K::KwTrue: case K::KwFalse:
      e.kind = ExprKind::Literal;
      e.literal = literal_of(advance());
      return e;
    case K::Error:
      // Reported by the lexer; stands for a value so the rest still parses.
      advance();
      return e;
    case K::LParen: {
      advance();
      Expr inner = expression();
      if (!panic_) expect(K::RParen, "')'");
      return inner;
    }
    case K::Identifier: break;
    default:
      expected("an expression");
      return e;
  }
  e.name = advance().text;
  if (at(K::Hash)) {
    // Colour#Red: an enumeration value with its type.
    advance();
    e.kind = ExprKind::EnumValue;
    e.type_name = std::move(e.name);
    e.name = name("an enumeration value after '#'");
    return e;
  }
  if (!at(K::LParen)) {
    e.kind = ExprKind::Name;
    return e;
  }
  e.kind = ExprKind::Call;
  call_arguments(e);
  return e;
}

// (…) after a callee: '(' [argument {',' argument}] ')'.
void Parser::call_arguments(Expr& e) {
  advance();  // (
  if (accept(K::RParen)) return;
  do {
    e.args.push_back(argument());
  } while (!panic_ && accept(K::Comma));
  if (!panic_) expect(K::RParen, "',' or ')'");
}

// x, IN := x, Q => y, NOT Q => y, Q =>
Argument Parser::argument() {
  Argument a;
  a.loc = cur().loc;
  const bool negated_output = at(K::KwNot) && peek(1).kind == K::Identifier && peek(2).kind == K::OutputAssign;
  if (negated_output) advance();
  if (at(K::Identifier) && (peek(1).kind == K::Assign || peek(1).kind == K::OutputAssign)) {
    a.name = advance().text;
    a.output = advance().kind == K::OutputAssign;
    a.negated = negated_output;
    if (a.output && (at(K::Comma) || at(K::RParen))) return a;  // output left unconnected
    a.value = a.output ? variable_or_call() : expression();
    return a;
  }
  a.value = expression();
  return a;
}

}  // namespace syncplc::st::parsing
