// The checker's expressions: IEC 61131-3 (3rd edition) typing of literals,
// names, operators, member, index and bit access, and calls of user
// functions, standard functions, conversions and FB instances.
#include <algorithm>
#include <cfloat>
#include <cmath>
#include <cstdio>
#include <set>

#include <fmt/format.h>

#include "runtime/st/check_context.hpp"

namespace syncplc::st {

namespace {

std::string int_text(Wide v) {
  if (v < 0) return "-" + int_text(-v);
  std::string s;
  do {
    s.insert(s.begin(), static_cast<char>('0' + static_cast<int>(v % 10)));
    v /= 10;
  } while (v != 0);
  return s;
}

std::string const_text(const ConstValue& c) { return c.is_real ? fmt::format("{}", c.r) : int_text(c.i); }

// "Percent (0..100)"; an anonymous subrange's name already shows its range.
std::string range_text(const Type* t) {
  if (t->name.find('(') != std::string::npos) return t->name;
  return fmt::format("{} ({}..{})", t->name, t->low, t->high);
}

bool is_comparison(BinaryOp op) { return op >= BinaryOp::Less && op <= BinaryOp::NotEqual; }

// Days from 1970-01-01 of a civil date (proleptic Gregorian).
std::int64_t days_from_civil(std::int64_t y, unsigned m, unsigned d) {
  y -= m <= 2;
  const std::int64_t era = (y >= 0 ? y : y - 399) / 400;
  const unsigned yoe = static_cast<unsigned>(y - era * 400);
  const unsigned doy = (153 * (m + (m > 2 ? -3 : 9)) + 2) / 5 + d - 1;
  const unsigned doe = yoe * 365 + yoe / 4 - yoe / 100 + doy;
  return era * 146097 + static_cast<std::int64_t>(doe) - 719468;
}

constexpr std::int64_t kNsPerSecond = 1'000'000'000;

// "hh:mm:ss[.f]" in nanoseconds (the lexer checked the fields).
std::int64_t tod_ns(const std::string& s) {
  int h = 0, m = 0;
  double sec = 0;
  std::sscanf(s.c_str(), "%d:%d:%lf", &h, &m, &sec);
  return (static_cast<std::int64_t>(h) * 3600 + m * 60) * kNsPerSecond + std::llround(sec * 1e9);
}

// "YYYY-MM-DD" in nanoseconds, in 128 bits: the lexer takes years 1 to
// 9999, of which a DATE (64 bits) holds 1677-09-22 to 2262-04-11 only.
Wide date_ns(const std::string& s) {
  int y = 1970, m = 1, d = 1;
  std::sscanf(s.c_str(), "%d-%d-%d", &y, &m, &d);
  return static_cast<Wide>(days_from_civil(y, static_cast<unsigned>(m), static_cast<unsigned>(d))) * 86400 *
         kNsPerSecond;
}

bool fits_64(Wide v) { return v >= INT64_MIN && v <= INT64_MAX; }

// The elementary types in the order a common type of two is looked for:
// the smallest both widen to.
constexpr Elem kWidening[] = {Elem::SINT, Elem::USINT, Elem::INT, Elem::UINT, Elem::DINT, Elem::UDINT,
                              Elem::REAL, Elem::LINT, Elem::ULINT, Elem::LREAL, Elem::BYTE, Elem::WORD,
                              Elem::DWORD, Elem::LWORD, Elem::TIME, Elem::LTIME};

}  // namespace

Val Checker::record(const Expr& e, Val v) {
  ExprInfo& i = info(e);
  i.type = v.type;
  if (v.c) i.constant = v.c;
  else i.constant.reset();
  if (v.lit != Val::Lit::None) lits_.insert(&e);
  else lits_.erase(&e);
  return v;
}

// The common type of two typed operands, or nullptr.
const Type* Checker::common(const Type* a, const Type* b) {
  if (a == b) return a;
  if (a->kind == Type::Kind::String && b->kind == Type::Kind::String)
    return a->wide == b->wide ? (a->length >= b->length ? a : b) : nullptr;
  const auto x = a->scalar(), y = b->scalar();
  if (!x || !y) return nullptr;
  if (widens_to(*x, *y)) return b->is_elem() ? b : elem(*y);
  if (widens_to(*y, *x)) return a->is_elem() ? a : elem(*x);
  for (Elem c : kWidening)
    if (widens_to(*x, c) && widens_to(*y, c)) return elem(c);
  return nullptr;
}

void Checker::settle(const Expr& e, const Type* t) {
  if (lits_.erase(&e) == 0) return;
  ExprInfo& i = info(e);
  i.type = t;
  if (i.constant && !i.constant->is_real && t->scalar() && is_real(*t->scalar()))
    i.constant = ConstValue{true, 0, static_cast<double>(i.constant->i)};
  for (const Expr& o : e.operands) settle(o, t);
  for (const Argument& a : e.args) settle(a.value, t);
}

void Checker::coerce(const Expr& e, const Val& v, const Type* target, std::string_view where) {
  if (v.error() || target->is_error()) return;
  const auto s = target->scalar();
  if (v.lit != Val::Lit::None) {
    if (s && v.c && fits(*v.c, *s) && *s != Elem::BOOL) {
      if (*s == Elem::REAL && v.c->is_real && std::fabs(v.c->r) > FLT_MAX) {
        error(e.loc, fmt::format("{}: value {} does not fit REAL", where, const_text(*v.c)));
        return;
      }
      if (target->kind == Type::Kind::Subrange && !v.c->is_real && (v.c->i < target->low || v.c->i > target->high)) {
        error(e.loc, fmt::format("{}: value {} is outside {}", where, const_text(*v.c), range_text(target)));
        return;
      }
      settle(e, target);
      return;
    }
    if (s && v.c && !v.c->is_real && (is_int(*s) || (is_bits(*s) && *s != Elem::BOOL))) {
      error(e.loc, fmt::format("{}: value {} does not fit {} ({}..{})", where, const_text(*v.c), elem_name(*s),
                               int_text(min_value(*s)), int_text(max_value(*s))));
      return;
    }
    if (s && !v.c && (v.lit == Val::Lit::Int ? is_num(*s) : is_real(*s))) {  // a generic call of literals
      settle(e, target);
      return;
    }
    error(e.loc, fmt::format("{}: expected {}, found {} literal{}", where, target->name,
                             v.lit == Val::Lit::Int ? "an integer" : "a real",
                             s && is_bits(*s) && v.lit == Val::Lit::Int && *s == Elem::BOOL ? " (write TRUE or FALSE)"
                                                                                            : ""));
    return;
  }
  if (assignable(v.type, target)) {
    if (v.c && target->kind == Type::Kind::Subrange && !v.c->is_real && (v.c->i < target->low || v.c->i > target->high))
      error(e.loc, fmt::format("{}: value {} is outside {}", where, const_text(*v.c), range_text(target)));
    if (target->kind == Type::Kind::String && e.kind == ExprKind::Literal &&
        static_cast<int>(e.literal.text.size()) > target->length && !target->wide)
      error(e.loc, fmt::format("{}: a string of {} characters does not fit {}", where, e.literal.text.size(),
                               target->name));
    return;
  }
  const std::string hint = conversion_hint(v.type, target);
  error(e.loc, fmt::format("{}: expected {}, found {}{}", where, target->name, v.type->name,
                           hint.empty() ? "" : " (use " + hint + "(...))"));
}

Val Checker::expect(const Expr& e, const Type* target, std::string_view where) {
  Val v = expr(e, target);
  coerce(e, v, target, where);
  if (!v.error() && v.lit != Val::Lit::None && !target->is_error()) {
    v.lit = Val::Lit::None;
    v.type = target;
  }
  return v;
}

// A literal left untyped where nothing asks for a type takes its default.
void Checker::settle_default(const Expr& e, const Val& v) {
  if (v.lit != Val::Lit::None) settle(e, v.type);
}

Val Checker::literal(const Expr& e, const Type*) {
  const Literal& l = e.literal;
  Val v;
  switch (l.kind) {
    case LiteralKind::Integer: {
      Wide value = static_cast<Wide>(l.int_value);
      if (l.negative) value = -value;
      if (l.type_prefix.empty()) {
        const ConstValue c{false, value, 0};
        v.lit = Val::Lit::Int;
        v.type = fits(c, Elem::DINT) ? elem(Elem::DINT) : fits(c, Elem::LINT) ? elem(Elem::LINT) : elem(Elem::ULINT);
        v.c = c;
        break;
      }
      const auto t = parse_elem(l.type_prefix);
      if (!t || !(is_num(*t) || is_bits(*t))) {
        error(e.loc, fmt::format("{}# cannot prefix an integer", l.type_prefix));
        return record(e, {err()});
      }
      v.type = elem(*t);
      if (is_real(*t)) {
        v.c = ConstValue{true, 0, static_cast<double>(value)};
        break;
      }
      v.c = ConstValue{false, value, 0};
      if (!fits(*v.c, *t)) {
        error(e.loc, fmt::format("{}#{} does not fit {} ({}..{})", l.type_prefix, int_text(value), l.type_prefix,
                                 int_text(min_value(*t)), int_text(max_value(*t))));
        return record(e, {err()});
      }
      break;
    }
    case LiteralKind::Real: {
      double r = l.real_value;
      if (l.negative && r > 0) r = -r;
      v.c = ConstValue{true, 0, r};
      if (l.type_prefix.empty()) {
        v.lit = Val::Lit::Real;
        v.type = elem(Elem::LREAL);
        break;
      }
      const auto t = parse_elem(l.type_prefix);
      if (!t || !is_real(*t)) {
        error(e.loc, fmt::format("{}# cannot prefix a real literal (use REAL# or LREAL#)", l.type_prefix));
        return record(e, {err()});
      }
      if (*t == Elem::REAL && std::fabs(r) > FLT_MAX) {
        error(e.loc, fmt::format("{} does not fit REAL", r));
        return record(e, {err()});
      }
      v.type = elem(*t);
      break;
    }
    case LiteralKind::Bool:
      if (l.int_value > 1) {
        error(e.loc, "BOOL# takes 0, 1, TRUE or FALSE");
        return record(e, {err()});
      }
      v.type = elem(Elem::BOOL);
      v.c = ConstValue{false, static_cast<Wide>(l.int_value), 0};
      break;
    case LiteralKind::Duration:
      v.type = elem(l.type_prefix == "LTIME" ? Elem::LTIME : Elem::TIME);
      v.c = ConstValue{false, l.duration_ns, 0};
      break;
    case LiteralKind::Date:
      v.type = elem(Elem::DATE);
      v.c = ConstValue{false, date_ns(l.text), 0};
      if (!fits_64(v.c->i)) {
        error(e.loc, fmt::format("{}#{} is outside the range of DATE (1677-09-22 to 2262-04-11)", l.type_prefix,
                                 l.text));
        return record(e, {err()});
      }
      break;
    case LiteralKind::TimeOfDay:
      v.type = elem(Elem::TOD);
      v.c = ConstValue{false, tod_ns(l.text), 0};
      break;
    case LiteralKind::DateAndTime: {
      const auto dash = l.text.rfind('-');
      v.type = elem(Elem::DT);
      v.c = ConstValue{false, date_ns(l.text.substr(0, dash)) + tod_ns(l.text.substr(dash + 1)), 0};
      if (!fits_64(v.c->i)) {
        error(e.loc, fmt::format("{}#{} is outside the range of DT (1677-09-21-00:12:44 to "
                                 "2262-04-11-23:47:16.854775807)",
                                 l.type_prefix, l.text));
        return record(e, {err()});
      }
      break;
    }
    case LiteralKind::String:
      v.type = types_.string(std::max<int>(1, static_cast<int>(l.text.size())), false);
      break;
    case LiteralKind::WString: {
      int chars = 0;  // UTF-8: count the characters, not the bytes
      for (unsigned char ch : l.text) chars += (ch & 0xC0) != 0x80;
      v.type = types_.string(std::max(1, chars), true);
      break;
    }
  }
  info(e).symbol = SymbolKind::Constant;
  return record(e, v);
}

Val Checker::name(const Expr& e, const Type* want) {
  if (pou_)
    if (const Variable* var = pou_->find(e.name)) {
      ExprInfo& i = info(e);
      i.symbol = SymbolKind::Variable;
      i.variable = var;
      Val v{var->type};
      if (var->constant && var->value) v.c = var->value;
      return record(e, v);
    }
  // An enumeration value without its type: the one the context wants, or
  // the only enumeration that has it.
  std::vector<const Type*> owners;
  for (const Type* t : enums_)
    if (t->value(e.name)) owners.push_back(t);
  const Type* owner = nullptr;
  if (want && want->kind == Type::Kind::Enum && want->value(e.name)) owner = want;
  else if (owners.size() == 1) owner = owners[0];
  else if (owners.size() > 1) {
    error(e.loc, fmt::format("'{}' is a value of {} and of {}: write {}#{}", e.name, owners[0]->name,
                             owners[1]->name, owners[0]->name, e.name));
    return record(e, {err()});
  }
  if (owner) {
    ExprInfo& i = info(e);
    i.symbol = SymbolKind::EnumValue;
    return record(e, {owner, Val::Lit::None, ConstValue{false, owner->value(e.name)->value, 0}});
  }
  if (functions_.count(name_key(e.name)) || find_std_function(e.name))
    error(e.loc, fmt::format("function '{}' used without a call: write {}(...)", e.name, e.name));
  else
    error(e.loc, fmt::format("unknown name '{}'{}", e.name, suggestion(e.name)));
  return record(e, {err()});
}

const Type* Checker::member_of(const Expr& e, const Type* base, bool writing) {
  ExprInfo& i = info(e);
  if (base->is_error()) return err();
  if (base->kind == Type::Kind::Struct) {
    if (const Field* f = base->field(e.name)) {
      i.symbol = SymbolKind::Field;
      i.field = f;
      return f->type;
    }
    std::vector<std::string_view> names;
    for (const auto& f : base->fields) names.push_back(f.name);
    const std::string best = closest_name(e.name, names);
    error(e.loc, fmt::format("'{}' has no field '{}'{}", base->name, e.name,
                             best.empty() ? "" : " (did you mean " + best + "?)"));
    return err();
  }
  if (base->kind == Type::Kind::FunctionBlock) {
    const Pin* p = base->fb->find(e.name);
    if (!p) {
      std::vector<std::string_view> names;
      for (const auto& x : base->fb->pins)
        if (x.dir == PinDir::Input || x.dir == PinDir::Output) names.push_back(x.name);
      const std::string best = closest_name(e.name, names);
      error(e.loc, fmt::format("'{}' has no input or output '{}'{}", base->name, e.name,
                               best.empty() ? "" : " (did you mean " + best + "?)"));
      return err();
    }
    if (p->dir != PinDir::Input && p->dir != PinDir::Output) {
      error(e.loc, fmt::format("'{}' is internal to {}: only its inputs and outputs are seen from outside", e.name,
                               base->name));
      return err();
    }
    if (writing && p->dir == PinDir::Output) {
      error(e.loc, fmt::format("'{}' is an output of {}: only the block writes it", e.name, base->name));
      return err();
    }
    i.symbol = SymbolKind::FbPin;
    i.pin = p;
    return p->type;
  }
  error(e.loc, fmt::format("'.{}' on a value of type {}, which has no fields", e.name, base->name));
  return err();
}

const Type* Checker::index_of(const Expr& e, const Type* base) {
  bool ok = !base->is_error();
  if (ok && base->kind != Type::Kind::Array) {
    error(e.loc, fmt::format("'[ ]' on a value of type {}, which is not an array", base->name));
    ok = false;
  }
  const std::size_t n = e.operands.size() - 1;
  if (ok && n != base->dims.size()) {
    error(e.loc, fmt::format("{} has {} dimension(s), indexed with {}", base->name, base->dims.size(), n));
    ok = false;
  }
  for (std::size_t k = 1; k < e.operands.size(); ++k) {
    const Expr& ix = e.operands[k];
    Val v = expr(ix, nullptr);
    if (v.error()) { ok = false; continue; }
    const auto s = v.type->scalar();
    if (!s || !is_int(*s)) {
      error(ix.loc, fmt::format("an array index must be an integer (ANY_INT), found {}", v.type->name));
      ok = false;
      continue;
    }
    settle_default(ix, v);
    if (ok && v.c) {
      const ArrayDim& d = base->dims[k - 1];
      if (v.c->i < d.low || v.c->i > d.high) {
        error(ix.loc, fmt::format("index {} is outside {}..{}", int_text(v.c->i), d.low, d.high));
        ok = false;
      }
    }
  }
  return ok ? base->element : err();
}

const Type* Checker::bit_of(const Expr& e, const Type* base) {
  if (base->is_error()) return err();
  const auto s = base->scalar();
  if (!s || !is_bits(*s) || *s == Elem::BOOL) {
    error(e.loc, fmt::format("bit access '.{}' needs a bit string (BYTE, WORD, DWORD, LWORD), found {}", e.bit,
                             base->name));
    return err();
  }
  if (e.bit < 0 || e.bit >= bits(*s)) {
    error(e.loc, fmt::format("bit {} is outside {} (0..{})", e.bit, base->name, bits(*s) - 1));
    return err();
  }
  return elem(Elem::BOOL);
}

const Type* Checker::target(const Expr& e) {
  switch (e.kind) {
    case ExprKind::Name: {
      const Variable* var = pou_ ? pou_->find(e.name) : nullptr;
      if (!var) {
        error(e.loc, fmt::format("unknown variable '{}'{}", e.name, suggestion(e.name)));
        return record(e, {err()}).type;
      }
      info(e).symbol = SymbolKind::Variable;
      info(e).variable = var;
      if (var->constant) {
        error(e.loc, fmt::format("'{}' is a CONSTANT and cannot be assigned", e.name));
        return record(e, {err()}).type;
      }
      for (const Variable* f : for_vars_)
        if (f == var) {
          error(e.loc, fmt::format("'{}' is the control variable of a FOR loop and cannot be assigned in its body",
                                   e.name));
          return record(e, {err()}).type;
        }
      return record(e, {var->type}).type;
    }
    case ExprKind::Member: {
      const Expr& base = e.operands[0];
      const Type* bt = base.kind == ExprKind::Name || base.kind == ExprKind::Member || base.kind == ExprKind::Index
                           ? target(base)
                           : expr(base).type;
      return record(e, {member_of(e, bt, true)}).type;
    }
    case ExprKind::Index: return record(e, {index_of(e, target(e.operands[0]))}).type;
    case ExprKind::BitAccess: return record(e, {bit_of(e, target(e.operands[0]))}).type;
    default:
      expr(e);
      error(e.loc, "only a variable, a field, an element or a bit can be assigned");
      return err();
  }
}

Val Checker::expr(const Expr& e, const Type* want) {
  switch (e.kind) {
    case ExprKind::None: return record(e, {err()});
    case ExprKind::Literal: return literal(e, want);
    case ExprKind::Name: return name(e, want);
    case ExprKind::EnumValue: {
      const Type* t = named_type(e.type_name, e.loc);
      if (t->is_error()) return record(e, {err()});
      if (t->kind != Type::Kind::Enum) {
        error(e.loc, fmt::format("'{}' is not an enumeration", e.type_name));
        return record(e, {err()});
      }
      const EnumValue* v = t->value(e.name);
      if (!v) {
        std::vector<std::string_view> names;
        for (const auto& x : t->values) names.push_back(x.name);
        const std::string best = closest_name(e.name, names);
        error(e.loc, fmt::format("{} has no value '{}'{}", t->name, e.name,
                                 best.empty() ? "" : " (did you mean " + best + "?)"));
        return record(e, {err()});
      }
      info(e).symbol = SymbolKind::EnumValue;
      return record(e, {t, Val::Lit::None, ConstValue{false, v->value, 0}});
    }
    case ExprKind::Member: {
      const Val base = expr(e.operands[0]);
      return record(e, {member_of(e, base.type, false)});
    }
    case ExprKind::Index: {
      const Val base = expr(e.operands[0]);
      return record(e, {index_of(e, base.type)});
    }
    case ExprKind::BitAccess: {
      const Val base = expr(e.operands[0]);
      Val v{bit_of(e, base.type)};
      if (!v.error() && base.c) v.c = ConstValue{false, (base.c->i >> e.bit) & 1, 0};
      return record(e, v);
    }
    case ExprKind::Call: return call(e, false, want);
    case ExprKind::Unary: return unary(e, want);
    case ExprKind::Binary: return binary(e, want);
  }
  return record(e, {err()});
}

Val Checker::unary(const Expr& e, const Type* want) {
  const Expr& o = e.operands[0];
  Val v = expr(o, want);
  if (v.error()) return record(e, {err()});
  const auto s = v.type->scalar();
  if (e.unary_op == UnaryOp::Not) {
    if (v.lit != Val::Lit::None || !s || !is_bits(*s)) {
      error(e.loc, fmt::format("NOT needs BOOL or a bit string (ANY_BIT), found {}",
                               v.lit != Val::Lit::None ? "an untyped literal" : v.type->name));
      return record(e, {err()});
    }
    Val r{elem(*s)};
    if (v.c) r.c = wrap(ConstValue{false, *s == Elem::BOOL ? !v.c->i : ~v.c->i, 0}, r.type);
    return record(e, r);
  }
  if (v.lit == Val::Lit::None) {
    const bool ok = s && (is_num(*s) || is_duration(*s)) &&
                    (e.unary_op == UnaryOp::Plus || !is_unsigned_int(*s));
    if (!ok) {
      error(e.loc, fmt::format("unary '{}' needs a signed number or a duration, found {}",
                               e.unary_op == UnaryOp::Plus ? "+" : "-", v.type->name));
      return record(e, {err()});
    }
    v.type = elem(*s);
  }
  if (v.c && e.unary_op == UnaryOp::Negate) {
    if (v.c->is_real) v.c->r = -v.c->r;
    else v.c->i = -v.c->i;
    if (v.lit == Val::Lit::None) v.c = wrap(*v.c, v.type);
  }
  if (v.lit != Val::Lit::None && v.c && !v.c->is_real)
    v.type = fits(*v.c, Elem::DINT) ? elem(Elem::DINT) : elem(Elem::LINT);
  return record(e, v);
}

namespace {

std::optional<ConstValue> fold(BinaryOp op, const ConstValue& a, const ConstValue& b) {
  if (a.is_real || b.is_real) {
    const double x = a.as_double(), y = b.as_double();
    switch (op) {
      case BinaryOp::Add: return ConstValue{true, 0, x + y};
      case BinaryOp::Subtract: return ConstValue{true, 0, x - y};
      case BinaryOp::Multiply: return ConstValue{true, 0, x * y};
      case BinaryOp::Divide: return y == 0 ? std::nullopt : std::optional<ConstValue>(ConstValue{true, 0, x / y});
      case BinaryOp::Power: return ConstValue{true, 0, std::pow(x, y)};
      case BinaryOp::Less: return ConstValue{false, x < y, 0};
      case BinaryOp::Greater: return ConstValue{false, x > y, 0};
      case BinaryOp::LessEqual: return ConstValue{false, x <= y, 0};
      case BinaryOp::GreaterEqual: return ConstValue{false, x >= y, 0};
      case BinaryOp::Equal: return ConstValue{false, x == y, 0};
      case BinaryOp::NotEqual: return ConstValue{false, x != y, 0};
      default: return std::nullopt;
    }
  }
  const Wide x = a.i, y = b.i;
  // Operands are at most 64 bits wide, so +, - and * cannot overflow 128.
  switch (op) {
    case BinaryOp::Add: return ConstValue{false, x + y, 0};
    case BinaryOp::Subtract: return ConstValue{false, x - y, 0};
    case BinaryOp::Multiply: return ConstValue{false, x * y, 0};
    case BinaryOp::Divide: return y == 0 ? std::nullopt : std::optional<ConstValue>(ConstValue{false, x / y, 0});
    case BinaryOp::Mod: return y == 0 ? std::nullopt : std::optional<ConstValue>(ConstValue{false, x % y, 0});
    case BinaryOp::And: return ConstValue{false, x & y, 0};
    case BinaryOp::Or: return ConstValue{false, x | y, 0};
    case BinaryOp::Xor: return ConstValue{false, x ^ y, 0};
    case BinaryOp::Less: return ConstValue{false, x < y, 0};
    case BinaryOp::Greater: return ConstValue{false, x > y, 0};
    case BinaryOp::LessEqual: return ConstValue{false, x <= y, 0};
    case BinaryOp::GreaterEqual: return ConstValue{false, x >= y, 0};
    case BinaryOp::Equal: return ConstValue{false, x == y, 0};
    case BinaryOp::NotEqual: return ConstValue{false, x != y, 0};
    default: return std::nullopt;
  }
}

}  // namespace

// The type both operands take: the typed one's when the other is a literal
// that fits it, else their common type after implicit widening. Reports and
// returns the error type when there is none.
const Type* Checker::unify(const Expr& e, const Expr& a, Val& x, const Expr& b, Val& y) {
  const std::string where = fmt::format("operand of '{}'", binary_op_text(e.binary_op));
  if (x.lit != Val::Lit::None && y.lit != Val::Lit::None)
    return elem(x.lit == Val::Lit::Real || y.lit == Val::Lit::Real ? Elem::LREAL : x.type->elem);
  // A literal beside a subrange takes its base type (the range binds writes, not operands).
  auto operand_type = [&](const Type* t) { return t->kind == Type::Kind::Subrange ? elem(t->elem) : t; };
  if (x.lit != Val::Lit::None) {
    const std::size_t before = out_.diagnostics.error_count();
    coerce(a, x, operand_type(y.type), where);
    return out_.diagnostics.error_count() == before ? operand_type(y.type) : err();
  }
  if (y.lit != Val::Lit::None) {
    const std::size_t before = out_.diagnostics.error_count();
    coerce(b, y, operand_type(x.type), where);
    return out_.diagnostics.error_count() == before ? operand_type(x.type) : err();
  }
  if (const Type* t = common(x.type, y.type)) return t;
  std::string hint = conversion_hint(y.type, x.type);
  error(e.loc, fmt::format("operands of '{}' have types {} and {}, with no implicit conversion between them{}",
                           binary_op_text(e.binary_op), x.type->name, y.type->name,
                           hint.empty() ? "" : " (use " + hint + "(...) or the reverse)"));
  return err();
}

Val Checker::binary(const Expr& e, const Type* want) {
  const Expr& a = e.operands[0];
  const Expr& b = e.operands[1];
  const BinaryOp op = e.binary_op;
  const Type* operand_want = is_comparison(op) ? nullptr : want;
  Val x = expr(a, operand_want);
  // An enumeration value on the left names the type of an unqualified value on the right.
  Val y = expr(b, is_comparison(op) && x.type->kind == Type::Kind::Enum ? x.type : operand_want);
  if (x.error() || y.error()) return record(e, {err()});
  const auto sx = x.type->scalar(), sy = y.type->scalar();
  const bool lit = x.lit != Val::Lit::None && y.lit != Val::Lit::None;
  auto folded = [&](const Type* t) -> Val {
    Val r{t};
    if (x.c && y.c) {
      r.c = fold(op, *x.c, *y.c);
      if (!r.c && (op == BinaryOp::Divide || op == BinaryOp::Mod)) {
        error(b.loc, "division by zero");
        return record(e, {err()});
      }
      if (r.c && !lit) r.c = wrap(*r.c, t);
    }
    if (lit && !is_comparison(op)) {
      r.lit = x.lit == Val::Lit::Real || y.lit == Val::Lit::Real ? Val::Lit::Real : Val::Lit::Int;
      if (r.c && !r.c->is_real) r.type = fits(*r.c, Elem::DINT) ? elem(Elem::DINT) : elem(Elem::LINT);
    }
    return record(e, r);
  };
  const auto name_of = [](const Val& v) {
    return v.lit == Val::Lit::Int ? std::string("an integer literal")
                                  : v.lit == Val::Lit::Real ? std::string("a real literal") : v.type->name;
  };

  // Durations and dates (3rd edition, table 30).
  const bool tx = sx && x.lit == Val::Lit::None && (is_duration(*sx) || *sx >= Elem::DATE);
  const bool ty = sy && y.lit == Val::Lit::None && (is_duration(*sy) || *sy >= Elem::DATE);
  if ((tx || ty) && !is_comparison(op)) {
    const Type* t = nullptr;
    if (op == BinaryOp::Add || op == BinaryOp::Subtract) {
      if (tx && ty && is_duration(*sx) && is_duration(*sy)) t = common(x.type, y.type);
      else if (tx && ty && !is_duration(*sx) && is_duration(*sy) && *sx != Elem::DATE) t = elem(*sx);  // DT/TOD ± TIME
      else if (tx && ty && op == BinaryOp::Subtract && *sx == *sy) t = elem(Elem::TIME);  // DT - DT
    } else if ((op == BinaryOp::Multiply || op == BinaryOp::Divide) && tx && is_duration(*sx) && !ty &&
               (y.lit != Val::Lit::None || (sy && is_num(*sy)))) {
      settle_default(b, y);
      if (y.c && !y.c->is_real && y.c->i == 0 && op == BinaryOp::Divide) {
        error(b.loc, "division by zero");
        return record(e, {err()});
      }
      return record(e, {x.type});
    } else if (op == BinaryOp::Multiply && ty && is_duration(*sy) && !tx && (x.lit != Val::Lit::None || (sx && is_num(*sx)))) {
      settle_default(a, x);
      return record(e, {y.type});
    }
    if (!t) {
      error(e.loc, fmt::format("'{}' is not defined for {} and {} (durations: TIME + or - TIME, TIME * or / a "
                               "number; DT, TOD + or - TIME; DT - DT, TOD - TOD, DATE - DATE)",
                               binary_op_text(op), name_of(x), name_of(y)));
      return record(e, {err()});
    }
    return folded(t);
  }

  if (op == BinaryOp::Power) {
    // EXPT: a real base (ANY_REAL), any number as the exponent.
    if (x.lit == Val::Lit::None && (!sx || !is_real(*sx))) {
      const std::string hint = sx && is_num(*sx) ? fmt::format(" (use {}_TO_LREAL(...))", x.type->name) : "";
      error(a.loc, fmt::format("'**' needs a real base (ANY_REAL), found {}{}", x.type->name, hint));
      return record(e, {err()});
    }
    if (y.lit == Val::Lit::None && (!sy || !is_num(*sy))) {
      error(b.loc, fmt::format("'**' needs a number as its exponent (ANY_NUM), found {}", y.type->name));
      return record(e, {err()});
    }
    settle_default(b, y);
    // An untyped base is a real literal.
    const bool untyped = x.lit != Val::Lit::None;
    const Type* t = untyped ? elem(Elem::LREAL) : elem(*sx);
    if (!x.c || !y.c) return record(e, Val(t, untyped ? Val::Lit::Real : Val::Lit::None));
    double p = std::pow(x.c->as_double(), y.c->as_double());
    if (t->is(Elem::REAL)) p = static_cast<float>(p);
    return record(e, Val(t, untyped ? Val::Lit::Real : Val::Lit::None, ConstValue{true, 0, p}));
  }

  const Type* t = unify(e, a, x, b, y);
  if (t->is_error()) return record(e, {err()});
  const auto s = t->scalar();
  if (is_comparison(op)) {
    info(e).operand_type = t;
    if (lit) {
      settle_default(a, x);
      settle_default(b, y);
    }
    const bool ordered = op != BinaryOp::Equal && op != BinaryOp::NotEqual;
    const bool ok = s || t->kind == Type::Kind::String || (t->kind == Type::Kind::Enum && !ordered) ||
                    t->kind == Type::Kind::Enum;
    if (!ok) {
      error(e.loc, fmt::format("'{}' cannot compare values of type {}", binary_op_text(op), t->name));
      return record(e, {err()});
    }
    return folded(elem(Elem::BOOL));
  }
  switch (op) {
    case BinaryOp::Add: case BinaryOp::Subtract: case BinaryOp::Multiply: case BinaryOp::Divide:
      if (!lit && !(s && is_num(*s))) {
        error(e.loc, fmt::format("'{}' needs numbers (ANY_NUM), found {}", binary_op_text(op), t->name));
        return record(e, {err()});
      }
      break;
    case BinaryOp::Mod:
      if ((lit && (x.lit == Val::Lit::Real || y.lit == Val::Lit::Real)) || (!lit && !(s && is_int(*s)))) {
        error(e.loc, fmt::format("MOD needs integers (ANY_INT), found {}", lit ? "a real literal" : t->name));
        return record(e, {err()});
      }
      break;
    case BinaryOp::And: case BinaryOp::Or: case BinaryOp::Xor:
      if (lit || !(s && is_bits(*s))) {
        error(e.loc, fmt::format("{} needs BOOL or a bit string (ANY_BIT), found {}", binary_op_text(op),
                                 lit ? "untyped literals" : t->name));
        return record(e, {err()});
      }
      break;
    default: break;
  }
  return folded(lit ? t : (s ? elem(*s) : t));
}

}  // namespace syncplc::st
