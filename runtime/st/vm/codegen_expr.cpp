// The code generator's places and expressions: a name, a field, an element
// or a bit as a Place (a frame cell, a cell through a reference, or an
// element of a local array by a checked index), reads and writes of places,
// the implicit widenings, and the operators with IEC 61131-3 typing as the
// checker settled it (the operands of an arithmetic operator take its
// result's type; those of a comparison the type the checker compared in).
#include <fmt/format.h>

#include "runtime/st/vm/codegen_context.hpp"
#include "runtime/st/vm/math_fns.hpp"
#include "runtime/st/vm/st_string.hpp"

namespace syncplc::st::vm {

namespace {

bool is_comparison(BinaryOp op) { return op >= BinaryOp::Less && op <= BinaryOp::NotEqual; }

Op compare_op(BinaryOp op) {
  switch (op) {
    case BinaryOp::Less: return Op::LT_I8;
    case BinaryOp::Greater: return Op::GT_I8;
    case BinaryOp::LessEqual: return Op::LE_I8;
    case BinaryOp::GreaterEqual: return Op::GE_I8;
    case BinaryOp::Equal: return Op::EQ_I8;
    default: return Op::NE_I8;
  }
}

// The jump taken when the comparison is false.
Op jump_unless_op(BinaryOp op) {
  switch (op) {
    case BinaryOp::Less: return Op::JNLT_I8;
    case BinaryOp::Greater: return Op::JNGT_I8;
    case BinaryOp::LessEqual: return Op::JNLE_I8;
    case BinaryOp::GreaterEqual: return Op::JNGE_I8;
    case BinaryOp::Equal: return Op::JNEQ_I8;
    default: return Op::JNNE_I8;
  }
}

StringFn string_compare(BinaryOp op) {
  switch (op) {
    case BinaryOp::Less: return StringFn::Lt;
    case BinaryOp::Greater: return StringFn::Gt;
    case BinaryOp::LessEqual: return StringFn::Le;
    case BinaryOp::GreaterEqual: return StringFn::Ge;
    case BinaryOp::Equal: return StringFn::Eq;
    default: return StringFn::Ne;
  }
}

bool is_real_num(Num n) { return n == Num::F32 || n == Num::F64; }

// The typed LDX/STX of an index cell of type n (integers only; the checker
// allows no other index).
Num index_num(Num n) { return is_real_num(n) ? Num::I64 : n; }

// The jump taken when the comparison is true: when its negation is false
// (integers only: with a NaN operand both a < b and a >= b are false).
Op jump_if_op(BinaryOp op) {
  switch (op) {
    case BinaryOp::Less: return Op::JNGE_I8;
    case BinaryOp::Greater: return Op::JNLE_I8;
    case BinaryOp::LessEqual: return Op::JNGT_I8;
    case BinaryOp::GreaterEqual: return Op::JNLT_I8;
    case BinaryOp::Equal: return Op::JNNE_I8;
    default: return Op::JNEQ_I8;
  }
}

// Durations and dates: a product of these may be a scaled one (TIME * 2).
bool is_time_like(const Type* t) {
  const auto e = t ? t->scalar() : std::nullopt;
  return e && (is_duration(*e) || *e >= Elem::DATE);
}

}  // namespace

// ---- places ----

Place CodeGen::place(const Expr& e) {
  const ExprInfo* i = program_.info(e);
  Place p;
  p.type = i ? i->type : nullptr;
  switch (e.kind) {
    case ExprKind::Name: {
      const Variable* v = i ? i->variable : nullptr;
      if (!v) break;
      p.type = v->type;
      p.at = var_cell(v);
      p.root = v;
      if (v->scope == VarScope::InOut || v->scope == VarScope::External) p.kind = Place::Kind::Indirect;
      return p;
    }
    case ExprKind::Member: {
      Place b = place(e.operands[0]);
      const Type* bt = b.type;
      std::uint32_t off = 0;
      if (bt && bt->kind == Type::Kind::Struct) {
        for (const Field& f : bt->fields) {
          if (same_name(f.name, e.name)) break;
          off += cells_of(f.type);
        }
      } else if (bt && bt->kind == Type::Kind::FunctionBlock) {
        if (builtin(bt)) {
          off = builtin_pin_at(bt, e.name);
        } else {
          const std::uint32_t fp = fb_pou(bt);
          lay_out(fp);
          for (const VarSlot& v : out_->pous[fp].vars)
            if (same_name(v.name, e.name)) off = v.at;
        }
      }
      return member(b, off, i->type);
    }
    case ExprKind::Index: {
      Place b = place(e.operands[0]);
      const Type* at = b.type;
      if (!at || at->kind != Type::Kind::Array) break;
      const std::uint32_t elem_cells = cells_of(at->element);
      // Row-major: the last index varies fastest.
      std::vector<std::uint32_t> strides(at->dims.size());
      std::uint32_t stride = elem_cells;
      for (std::size_t k = at->dims.size(); k-- > 0;) {
        strides[k] = stride;
        stride *= static_cast<std::uint32_t>(at->dims[k].count());
      }
      std::uint32_t static_off = 0;
      bool dynamic = false;
      for (std::size_t k = 1; k < e.operands.size(); ++k) {
        const ExprInfo* xi = program_.info(e.operands[k]);
        if (xi && xi->constant)
          static_off += static_cast<std::uint32_t>(static_cast<std::int64_t>(xi->constant->i) - at->dims[k - 1].low) *
                        strides[k - 1];
        else
          dynamic = true;
      }
      if (!dynamic) return member(b, static_off, at->element);
      auto check = [&](std::size_t k, const Type* index_type) {
        IndexCheck c;
        c.low = at->dims[k].low;
        c.count = static_cast<std::uint64_t>(at->dims[k].count());
        c.stride = strides[k];
        c.index = num_of(index_type).value_or(Num::I64);
        c.site = site(e.operands[k + 1].loc,
                      fmt::format("array index out of bounds ({}..{})", at->dims[k].low, at->dims[k].high));
        out_->indexes.push_back(c);
        out_->scratch_cells = std::max(out_->scratch_cells, c.stride);
        return static_cast<std::uint32_t>(out_->indexes.size() - 1);
      };
      if (b.kind == Place::Kind::Direct && at->dims.size() == 1 && elem_cells == 1) {
        const Operand ix = expr(e.operands[1]);
        Place p2;
        p2.kind = Place::Kind::Indexed;
        p2.at = b.at;
        p2.index = ix.at;
        p2.check = check(0, ix.type);
        p2.type = at->element;
        p2.root = b.root;
        return p2;
      }
      const std::uint32_t r = ref_of(b);
      for (std::size_t k = 1; k < e.operands.size(); ++k) {
        const ExprInfo* xi = program_.info(e.operands[k]);
        if (xi && xi->constant) {
          const auto off = static_cast<std::uint32_t>(static_cast<std::int64_t>(xi->constant->i) - at->dims[k - 1].low) *
                           strides[k - 1];
          if (off) emit(Op::REF_ADD, r, r, off);
          continue;
        }
        const Operand ix = expr(e.operands[k]);
        emit(Op::REF_INDEX, r, r, ix.at, check(k - 1, ix.type));
      }
      Place p2;
      p2.kind = Place::Kind::Indirect;
      p2.at = r;
      p2.type = at->element;
      p2.root = b.root;
      return p2;
    }
    case ExprKind::BitAccess: {
      Place b = place(e.operands[0]);
      b.word = b.type;
      b.bit = e.bit;
      b.type = i->type;
      return b;
    }
    default: break;
  }
  error(e.loc, "the code generator cannot address this expression");
  p.type = p.type ? p.type : program_.types->error();
  return p;
}

std::uint32_t CodeGen::ref_of(const Place& p) {
  const std::uint32_t r = temp();
  switch (p.kind) {
    case Place::Kind::Direct: emit(Op::ADDR, r, p.at); break;
    case Place::Kind::Indirect: emit(Op::REF_ADD, r, p.at, p.k); break;
    case Place::Kind::Indexed:
      emit(Op::ADDR, r, p.at);
      emit(Op::REF_INDEX, r, r, p.index, p.check);
      break;
  }
  return r;
}

Operand CodeGen::read(const Place& p, std::optional<std::uint32_t> into) {
  if (p.bit >= 0) {
    Place w = p;
    w.bit = -1;
    w.type = p.word;
    const Operand word = read(w);
    const std::uint32_t dst = into ? *into : temp();
    emit(Op::GETBIT, dst, word.at, static_cast<std::uint32_t>(p.bit));
    return {dst, p.type};
  }
  const std::uint32_t n = cells_of(p.type);
  switch (p.kind) {
    case Place::Kind::Direct: return {p.at, p.type};
    case Place::Kind::Indirect: {
      const std::uint32_t dst = into && n == 1 ? *into : temp(n);
      if (n == 1) {
        emit(Op::LDI1, dst, p.at, p.k);
      } else {
        std::uint32_t r = p.at;
        if (p.k) {
          r = temp();
          emit(Op::REF_ADD, r, p.at, p.k);
        }
        emit(Op::LDI, dst, r, n);
      }
      return {dst, p.type};
    }
    case Place::Kind::Indexed: {
      const std::uint32_t dst = into ? *into : temp();
      emit(op_of(Op::LDX_I8, index_num(out_->indexes[p.check].index)), dst, p.at, p.index, p.check);
      return {dst, p.type};
    }
  }
  return {p.at, p.type};
}

void CodeGen::note_written(const Place& p) {
  if (!p.root || p.root->scope != VarScope::External) return;
  auto& w = out_->pous[pou_].externals_written;
  for (const std::string& n : w)
    if (same_name(n, p.root->name)) return;
  w.push_back(p.root->name);
}

void CodeGen::write(const Place& p, Operand v, const SourceLoc& loc) {
  if (!p.type || p.type->is_error()) return;
  note_written(p);
  if (p.bit >= 0) {
    Place w = p;
    w.bit = -1;
    w.type = p.word;
    const Operand word = read(w);
    const std::uint32_t t = temp();
    emit(Op::MOV, t, word.at);
    emit(Op::SETBIT, t, v.at, static_cast<std::uint32_t>(p.bit));
    write(w, {t, p.word}, loc);
    return;
  }
  if (p.type->kind == Type::Kind::Subrange) {
    RangeCheck r;
    r.num = num_of(p.type->elem);
    r.low = p.type->low;
    r.high = p.type->high;
    r.site = site(loc, fmt::format("value outside {}", p.type->name));
    out_->ranges.push_back(r);
    const std::uint32_t t = temp();
    emit(Op::RANGE, t, v.at, 0, static_cast<std::uint32_t>(out_->ranges.size() - 1));
    v.at = t;
  }
  const std::uint32_t n = cells_of(p.type);
  if (p.type->kind == Type::Kind::String) {
    // A string is cut to the destination's capacity (the fault says so).
    StringCall s;
    s.fn = StringFn::Assign;
    s.wide = p.type->wide;
    s.capacity = p.type->length;
    s.args[0] = v.at;
    s.site = site(loc, fmt::format("string cut to {} characters", p.type->length));
    if (p.kind == Place::Kind::Direct) {
      s.dst = p.at;
      string_op(s);
      return;
    }
    s.dst = temp(n);
    string_op(s);
    v.at = s.dst;
  }
  switch (p.kind) {
    case Place::Kind::Direct:
      if (n == 1) emit(Op::MOV, p.at, v.at);
      else emit(Op::MOVN, p.at, v.at, n);
      return;
    case Place::Kind::Indirect:
      if (n == 1) {
        emit(Op::STI1, p.at, v.at, p.k);
      } else {
        std::uint32_t r = p.at;
        if (p.k) {
          r = temp();
          emit(Op::REF_ADD, r, p.at, p.k);
        }
        emit(Op::STI, r, v.at, n);
      }
      return;
    case Place::Kind::Indexed:
      emit(op_of(Op::STX_I8, index_num(out_->indexes[p.check].index)), p.at, v.at, p.index, p.check);
      return;
  }
}

// ---- expressions ----

Operand CodeGen::constant_of(const Expr& e, const ExprInfo& i) {
  const auto n = num_of(i.type);
  if (!n) {
    error(e.loc, fmt::format("the code generator has no constant form for {}", i.type->name));
    return {0, i.type};
  }
  return {constant_cell(num_cell(*n, *i.constant)), i.type};
}

Operand CodeGen::expr(const Expr& e, std::optional<std::uint32_t> into) {
  const ExprInfo* i = program_.info(e);
  if (!i || !i->type) {
    error(e.loc, "the code generator found an unchecked expression");
    return {0, program_.types->error()};
  }
  if (i->constant && num_of(i->type)) return constant_of(e, *i);
  switch (e.kind) {
    case ExprKind::Literal:
      if (e.literal.kind == LiteralKind::String || e.literal.kind == LiteralKind::WString) {
        const Type* t = i->type;
        std::vector<Cell> cells(cells_of(t));
        if (t->wide) wstr_set_utf8(cells.data(), t->length, e.literal.text.data(), e.literal.text.size());
        else str_set(cells.data(), t->length, e.literal.text.data(), e.literal.text.size());
        return {constant(cells.data(), static_cast<std::uint32_t>(cells.size())), t};
      }
      break;
    case ExprKind::Name:
    case ExprKind::Member:
    case ExprKind::Index:
    case ExprKind::BitAccess: return read(place(e), into);
    case ExprKind::Call: return call(e, into);
    case ExprKind::Unary: return unary(e, into);
    case ExprKind::Binary: return binary(e, into);
    default: break;
  }
  error(e.loc, "the code generator has no form for this expression");
  return {0, i->type};
}

// The implicit conversions the checker allowed (IEC 61131-3 ed. 3, 6.6.1.6.2):
// value-preserving, so one widening instruction or none (an unsigned value or
// a bit string keeps its bits in a wider cell).
Operand CodeGen::convert(Operand v, const Type* to, const SourceLoc& loc) {
  if (!to || !v.type || to->is_error() || v.type->is_error() || v.type == to) return {v.at, to ? to : v.type};
  const auto nf = num_of(v.type), nt = num_of(to);
  if (!nf || !nt) return {v.at, v.type->kind == Type::Kind::String ? v.type : to};
  if (*nf == *nt) return {v.at, to};
  Op family;
  switch (*nt) {
    case Num::F64: family = Op::WIDEN_TO_F64_I8; break;
    case Num::F32: family = Op::WIDEN_TO_F32_I8; break;
    case Num::I64: family = Op::WIDEN_TO_I64_I8; break;
    case Num::I32: family = Op::WIDEN_TO_I32_I8; break;
    case Num::I16: family = Op::WIDEN_TO_I16_I8; break;
    default: {
      const bool from_unsigned = *nf == Num::U8 || *nf == Num::U16 || *nf == Num::U32 || *nf == Num::U64;
      if (from_unsigned) return {v.at, to};  // the same bits
      error(loc, fmt::format("the code generator has no implicit conversion from {} to {}", v.type->name, to->name));
      return {v.at, to};
    }
  }
  const std::uint32_t dst = temp();
  emit(op_of(family, *nf), dst, v.at);
  return {dst, to};
}

Operand CodeGen::as_i64(Operand v) {
  const auto n = num_of(v.type);
  if (!n || *n == Num::I64 || *n == Num::U64) return v;
  const std::uint32_t dst = temp();
  emit(op_of(Op::WIDEN_TO_I64_I8, *n), dst, v.at);
  return {dst, program_.types->elem(Elem::LINT)};
}

Operand CodeGen::unary(const Expr& e, std::optional<std::uint32_t> into) {
  const ExprInfo* i = program_.info(e);
  const Type* t = i->type;
  if (e.unary_op == UnaryOp::Plus) return convert(expr(e.operands[0]), t, e.loc);
  const Operand v = convert(expr(e.operands[0]), t, e.loc);
  const auto n = num_of(t);
  const std::uint32_t dst = into ? *into : temp();
  if (e.unary_op == UnaryOp::Negate) {
    emit(op_of(Op::NEG_I8, *n), dst, v.at);
    return {dst, t};
  }
  Op op = Op::NOT_U64;
  if (t->is(Elem::BOOL)) op = Op::NOT_BOOL;
  else if (*n == Num::U8) op = Op::NOT_U8;
  else if (*n == Num::U16) op = Op::NOT_U16;
  else if (*n == Num::U32) op = Op::NOT_U32;
  emit(op, dst, v.at);
  return {dst, t};
}

Operand CodeGen::binary(const Expr& e, std::optional<std::uint32_t> into) {
  const ExprInfo* i = program_.info(e);
  const Type* t = i->type;
  const BinaryOp op = e.binary_op;
  const Expr& ea = e.operands[0];
  const Expr& eb = e.operands[1];
  if (is_comparison(op)) {
    const Type* ot = i->operand_type;
    const Operand a = convert(expr(ea), ot, ea.loc);
    const Operand b = convert(expr(eb), ot, eb.loc);
    const std::uint32_t dst = into ? *into : temp();
    if (ot && ot->kind == Type::Kind::String) {
      StringCall s;
      s.fn = string_compare(op);
      s.wide = ot->wide;
      s.dst = dst;
      s.args[0] = a.at;
      s.args[1] = b.at;
      string_op(s);
      return {dst, t};
    }
    const auto n = ot ? num_of(ot) : std::nullopt;
    if (!n) {
      error(e.loc, "the code generator cannot compare these values");
      return {dst, t};
    }
    emit(op_of(compare_op(op), *n), dst, a.at, b.at);
    return {dst, t};
  }
  const auto n = num_of(t);
  if (!n) {
    error(e.loc, fmt::format("the code generator has no '{}' for {}", binary_op_text(op), t->name));
    return {0, t};
  }
  if (op == BinaryOp::Power) {
    const Operand a = convert(expr(ea), t, ea.loc);
    const Operand b = convert(expr(eb), t, eb.loc);
    const std::uint32_t dst = into ? *into : temp();
    emit(Op::MATH2, dst, a.at, b.at, math2(math2_fn("EXPT", *n == Num::F64)));
    return {dst, t};
  }
  if ((op == BinaryOp::Add || op == BinaryOp::Subtract) && !is_time_like(t)) {
    // x * y +/- z and z +/- x * y in one instruction (the operands evaluated
    // in the order written, the product rounded before the sum as MUL does).
    auto product = [&](const Expr& x) {
      const ExprInfo* xi = program_.info(x);
      return x.kind == ExprKind::Binary && x.binary_op == BinaryOp::Multiply && xi && xi->type == t && !xi->constant;
    };
    const bool left = product(ea), right = !left && product(eb);
    if (left || right) {
      // Each operand converted where MUL and ADD would convert it: after
      // the operands evaluated before (a call there may change a variable).
      const Expr& pe = left ? ea : eb;
      Operand z;
      if (right) z = expr(ea);
      Operand x = expr(pe.operands[0]);
      Operand y = expr(pe.operands[1]);
      x = convert(x, t, pe.operands[0].loc);
      y = convert(y, t, pe.operands[1].loc);
      z = left ? convert(expr(eb), t, eb.loc) : convert(z, t, ea.loc);
      const std::uint32_t dst = into ? *into : temp();
      const bool add = op == BinaryOp::Add;
      const Op fused = left ? (add ? Op::MULADD_I8 : Op::MULSUB_I8) : (add ? Op::ADDMUL_I8 : Op::SUBMUL_I8);
      emit(op_of(fused, *n), dst, x.at, y.at, z.at);
      return {dst, t};
    }
  }
  Operand a = expr(ea);
  Operand b = expr(eb);
  const std::uint32_t dst = into ? *into : temp();
  // Durations and dates scaled by a number (TIME * 2, TIME / 1.5, 2 * TIME).
  const auto na = num_of(a.type), nb = num_of(b.type);
  const bool scaled = (op == BinaryOp::Multiply || op == BinaryOp::Divide) && *n == Num::I64 && t->scalar() &&
                      (is_duration(*t->scalar()) || *t->scalar() >= Elem::DATE) && a.type != b.type;
  if (scaled) {
    if (op == BinaryOp::Multiply && !(a.type->scalar() && is_duration(*a.type->scalar()))) std::swap(a, b);
    const auto nf = num_of(b.type);
    if (nf && is_real_num(*nf)) {
      const Operand f = convert(b, program_.types->elem(Elem::LREAL), eb.loc);
      emit(Op::MATH2, dst, a.at, f.at, math2(op == BinaryOp::Multiply ? time_mul_real : time_div_real));
      return {dst, t};
    }
    const Operand k = as_i64(b);
    emit(op == BinaryOp::Multiply ? Op::MUL_I64 : Op::DIV_I64, dst, a.at, k.at, 0,
         op == BinaryOp::Divide ? site(e.loc, "division by zero") : 0u);
    return {dst, t};
  }
  (void)na;
  (void)nb;
  a = convert(a, t, ea.loc);
  b = convert(b, t, eb.loc);
  switch (op) {
    case BinaryOp::Add: emit(op_of(Op::ADD_I8, *n), dst, a.at, b.at); break;
    case BinaryOp::Subtract: emit(op_of(Op::SUB_I8, *n), dst, a.at, b.at); break;
    case BinaryOp::Multiply: emit(op_of(Op::MUL_I8, *n), dst, a.at, b.at); break;
    case BinaryOp::Divide: emit(op_of(Op::DIV_I8, *n), dst, a.at, b.at, 0, site(e.loc, "division by zero")); break;
    case BinaryOp::Mod: emit(op_of(Op::MOD_I8, *n), dst, a.at, b.at, 0, site(e.loc, "MOD by zero")); break;
    case BinaryOp::And: emit(Op::AND, dst, a.at, b.at); break;
    case BinaryOp::Or: emit(Op::OR, dst, a.at, b.at); break;
    case BinaryOp::Xor: emit(Op::XOR, dst, a.at, b.at); break;
    default: error(e.loc, "the code generator has no form for this operator"); break;
  }
  return {dst, t};
}

// Conditions become jumps: IF a AND b tests a, then b, with no BOOL
// computed; IF NOT a jumps on a. The right operand of AND (OR) is skipped
// when the left one is FALSE (TRUE), which IEC's AND does not do, so only a
// right operand whose evaluation cannot be seen is skipped: no call, no
// division, no index, no conversion (none of them can fault or write).
bool CodeGen::skippable(const Expr& e) const {
  const ExprInfo* i = program_.info(e);
  if (!i || !i->type || i->type->is_error()) return false;
  if (i->constant) return true;
  switch (e.kind) {
    case ExprKind::Literal: return true;
    case ExprKind::Name: return i->variable != nullptr;
    case ExprKind::Member:
    case ExprKind::BitAccess:
    case ExprKind::Unary: return skippable(e.operands[0]);
    case ExprKind::Binary: {
      if (e.binary_op == BinaryOp::Divide || e.binary_op == BinaryOp::Mod || e.binary_op == BinaryOp::Power)
        return false;
      const Type* ot = i->operand_type ? i->operand_type : i->type;
      if (!num_of(ot)) return false;  // strings
      return skippable(e.operands[0]) && skippable(e.operands[1]);
    }
    default: return false;
  }
}

namespace {

bool is_bool_op(const Expr& e, const ExprInfo* i, BinaryOp op) {
  return e.kind == ExprKind::Binary && e.binary_op == op && i && !i->constant && i->type && i->type->is(Elem::BOOL);
}
bool is_bool_not(const Expr& e, const ExprInfo* i) {
  return e.kind == ExprKind::Unary && e.unary_op == UnaryOp::Not && i && !i->constant && i->type &&
         i->type->is(Elem::BOOL);
}

}  // namespace

std::vector<std::uint32_t> CodeGen::jumps_unless(const Expr& cond) {
  const ExprInfo* i = program_.info(cond);
  if (is_bool_op(cond, i, BinaryOp::And) && skippable(cond.operands[1])) {
    std::vector<std::uint32_t> out = jumps_unless(cond.operands[0]);
    for (std::uint32_t j : jumps_unless(cond.operands[1])) out.push_back(j);
    return out;
  }
  if (is_bool_op(cond, i, BinaryOp::Or) && skippable(cond.operands[1])) {
    const std::vector<std::uint32_t> taken = jumps_if(cond.operands[0]);
    std::vector<std::uint32_t> out = jumps_unless(cond.operands[1]);
    for (std::uint32_t j : taken) patch(j, pc());
    return out;
  }
  if (is_bool_not(cond, i)) return jumps_if(cond.operands[0]);
  if (cond.kind == ExprKind::Binary && is_comparison(cond.binary_op) && i && !i->constant && i->operand_type &&
      num_of(i->operand_type)) {
    const Type* ot = i->operand_type;
    TempScope scope(*this);
    const Operand a = convert(expr(cond.operands[0]), ot, cond.loc);
    const Operand b = convert(expr(cond.operands[1]), ot, cond.loc);
    return {emit(op_of(jump_unless_op(cond.binary_op), *num_of(ot)), a.at, b.at)};
  }
  TempScope scope(*this);
  const Operand v = expr(cond);
  return {emit(Op::JZ, v.at)};
}

std::vector<std::uint32_t> CodeGen::jumps_if(const Expr& cond) {
  const ExprInfo* i = program_.info(cond);
  if (is_bool_op(cond, i, BinaryOp::Or) && skippable(cond.operands[1])) {
    std::vector<std::uint32_t> out = jumps_if(cond.operands[0]);
    for (std::uint32_t j : jumps_if(cond.operands[1])) out.push_back(j);
    return out;
  }
  if (is_bool_op(cond, i, BinaryOp::And) && skippable(cond.operands[1])) {
    const std::vector<std::uint32_t> not_taken = jumps_unless(cond.operands[0]);
    std::vector<std::uint32_t> out = jumps_if(cond.operands[1]);
    for (std::uint32_t j : not_taken) patch(j, pc());
    return out;
  }
  if (is_bool_not(cond, i)) return jumps_unless(cond.operands[0]);
  const Num on = i && i->operand_type ? num_of(i->operand_type).value_or(Num::F64) : Num::F64;
  if (cond.kind == ExprKind::Binary && is_comparison(cond.binary_op) && i && !i->constant && !is_real_num(on)) {
    const Type* ot = i->operand_type;
    TempScope scope(*this);
    const Operand a = convert(expr(cond.operands[0]), ot, cond.loc);
    const Operand b = convert(expr(cond.operands[1]), ot, cond.loc);
    return {emit(op_of(jump_if_op(cond.binary_op), on), a.at, b.at)};
  }
  TempScope scope(*this);
  const Operand v = expr(cond);
  return {emit(Op::JNZ, v.at)};
}

namespace {

// The index of f in a module's function table, added when not there yet.
template <class F>
std::uint32_t intern(std::vector<F>& table, F f) {
  for (std::size_t k = 0; k < table.size(); ++k)
    if (table[k] == f) return static_cast<std::uint32_t>(k);
  table.push_back(f);
  return static_cast<std::uint32_t>(table.size() - 1);
}

}  // namespace

std::uint32_t CodeGen::math1(Math1Fn f) { return intern(out_->math1, f); }
std::uint32_t CodeGen::math2(Math2Fn f) { return intern(out_->math2, f); }
std::uint32_t CodeGen::conversion_index(ConvertFn f) { return intern(out_->conversions, f); }

std::uint32_t CodeGen::string_op(StringCall s) {
  out_->strings.push_back(s);
  const auto k = static_cast<std::uint32_t>(out_->strings.size() - 1);
  my_strings_.push_back(k);
  emit(Op::STRFN, 0, 0, 0, k);
  return k;
}

}  // namespace syncplc::st::vm
