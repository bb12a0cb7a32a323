// The code generator's calls: FB instances (user FUNCTION_BLOCKs run on
// their embedded frame; built-in blocks through their Block), user
// FUNCTIONs (arguments copied into the function's static frame, results
// copied out), the standard functions and the type conversions.
#include <fmt/format.h>

#include "runtime/core/iec_convert.hpp"
#include "runtime/st/vm/codegen_context.hpp"
#include "runtime/st/vm/date_fns.hpp"
#include "runtime/st/vm/math_fns.hpp"
#include "runtime/st/vm/st_string.hpp"

namespace syncplc::st::vm {

Place CodeGen::member(Place base, std::uint32_t off, const Type* t) {
  if (base.kind == Place::Kind::Indexed) {
    base.at = ref_of(base);
    base.kind = Place::Kind::Indirect;
    base.k = 0;
  }
  if (base.kind == Place::Kind::Direct) base.at += off;
  else base.k += off;
  base.type = t;
  base.bit = -1;
  return base;
}

void CodeGen::copy_value(std::uint32_t dst, Operand v, const Type* t, const SourceLoc& loc) {
  if (t->kind == Type::Kind::String) {
    StringCall s;
    s.fn = StringFn::Assign;
    s.wide = t->wide;
    s.capacity = t->length;
    s.dst = dst;
    s.args[0] = v.at;
    s.site = site(loc, fmt::format("string cut to {} characters", t->length));
    string_op(s);
    return;
  }
  const std::uint32_t n = cells_of(t);
  if (n == 1) emit(Op::MOV, dst, v.at);
  else emit(Op::MOVN, dst, v.at, n);
}

const VarSlot* CodeGen::slot(std::uint32_t pou, std::string_view name) {
  lay_out(pou);
  for (const VarSlot& v : out_->pous[pou].vars)
    if (same_name(v.name, name)) return &v;
  return nullptr;
}

Operand CodeGen::call(const Expr& e, std::optional<std::uint32_t> into) {
  const ExprInfo* i = program_.info(e);
  switch (i->symbol) {
    case SymbolKind::StdFunction: return std_call(e, *i, into);
    case SymbolKind::Conversion: return conversion(e, *i, into);
    case SymbolKind::UserFunction: return user_function(e, *i, into);
    case SymbolKind::FbCall: fb_call(e); return {0, i->type};
    default: break;
  }
  error(e.loc, "the code generator cannot call this");
  return {0, i->type};
}

void CodeGen::fb_call(const Expr& e) {
  const ExprInfo* i = program_.info(e);
  Place inst;
  if (e.name.empty()) {
    inst = place(e.operands[0]);
  } else {
    const Variable* v = i->variable;
    inst.at = var_cell(v);
    inst.type = v->type;
    if (v->scope == VarScope::InOut || v->scope == VarScope::External) inst.kind = Place::Kind::Indirect;
  }
  if (inst.kind == Place::Kind::Indexed) inst = member(inst, 0, inst.type);
  const Type* t = inst.type;
  const BlockTypeInfo* b = builtin(t);
  const std::uint32_t fp = b ? ~0u : fb_pou(t);
  if (!b && fp == ~0u) {
    error(e.loc, fmt::format("the code generator does not know the function block {}", t->name));
    return;
  }
  auto pin_cell = [&](const Pin* pin) -> std::uint32_t {
    if (b) return builtin_pin_at(t, pin->name);
    const VarSlot* s = slot(fp, pin->name);
    return s ? s->at : 0;
  };
  // Inputs and in-outs, in the order written.
  for (const Argument& a : e.args) {
    auto it = program_.args.find(&a);
    if (it == program_.args.end() || a.output) continue;
    const Pin* pin = it->second;
    if (pin->dir == PinDir::InOut) {
      const Place target = place(a.value);
      note_written(target);
      const std::uint32_t r = ref_of(target);
      write(member(inst, pin_cell(pin), program_.types->elem(Elem::LWORD)),
            {r, program_.types->elem(Elem::LWORD)}, a.loc);
      continue;
    }
    const Operand v = convert(expr(a.value), pin->type, a.value.loc);
    write(member(inst, pin_cell(pin), pin->type), v, a.loc);
  }
  // Links (Axis := X): the block is linked to what the AXIS_REFs name
  // before it runs; the checker made every call give them.
  if (b)
    for (std::size_t k = b->pins.size(); k < t->fb->pins.size(); ++k) {
      const Pin& pin = t->fb->pins[k];
      const auto n = static_cast<std::uint32_t>(pin.type->element_count());
      const Type* ref = pin.type->kind == Type::Kind::Array ? pin.type->element : pin.type;
      const std::uint32_t s =
          site(e.loc, fmt::format("{}: the {} passed names no {}", pin.name, ref->name,
                                  ref->ref_target));
      const auto link = static_cast<std::uint32_t>(k - b->pins.size());
      if (inst.kind == Place::Kind::Direct) emit(Op::LINK_BLOCK, inst.at, pin_cell(&pin), link, n, s);
      else emit(Op::LINK_BLOCK_REF, ref_of(inst), pin_cell(&pin), link, n, s);
    }
  if (inst.kind == Place::Kind::Direct) {
    if (b) emit(Op::CALL_BLOCK, inst.at, 0, b->unit_delay ? 1 : 0);
    else emit(Op::CALL_FB, inst.at, 0, 0, fp);
  } else {
    const std::uint32_t r = ref_of(inst);
    if (b) emit(Op::CALL_BLOCK_REF, r, 0, b->unit_delay ? 1 : 0);
    else emit(Op::CALL_FB_REF, r, 0, 0, fp);
  }
  // Outputs (q => x, NOT q => x).
  for (const Argument& a : e.args) {
    auto it = program_.args.find(&a);
    if (it == program_.args.end() || !a.output || a.value.kind == ExprKind::None) continue;
    const Pin* pin = it->second;
    Operand v = read(member(inst, pin_cell(pin), pin->type));
    if (a.negated) {
      const std::uint32_t n = temp();
      emit(Op::NOT_BOOL, n, v.at);
      v.at = n;
    }
    const Place target = place(a.value);
    write(target, convert(v, target.type, a.loc), a.loc);
  }
}

Operand CodeGen::user_function(const Expr& e, const ExprInfo& i, std::optional<std::uint32_t>) {
  const std::uint32_t fp = pou_index(i.function);
  lay_out(fp);
  FunctionCall call;
  call.pou = fp;
  struct Output {
    const Argument* arg;
    const Pin* pin;
    std::uint32_t temp;
  };
  std::vector<Output> outputs;
  for (const Argument& a : e.args) {
    auto it = program_.args.find(&a);
    if (it == program_.args.end()) continue;
    const Pin* pin = it->second;
    const VarSlot* s = slot(fp, pin->name);
    if (!s) continue;
    if (a.output) {
      if (a.value.kind == ExprKind::None) continue;
      const std::uint32_t n = cells_of(pin->type);
      const std::uint32_t t = temp(n);
      call.out.push_back({s->at, t, n});
      outputs.push_back({&a, pin, t});
      continue;
    }
    if (pin->dir == PinDir::InOut) {
      const Place target = place(a.value);
      note_written(target);
      call.in.push_back({ref_of(target), s->at, 1});
      continue;
    }
    Operand v = convert(expr(a.value), pin->type, a.value.loc);
    const std::uint32_t n = cells_of(pin->type);
    if (pin->type->kind == Type::Kind::String && v.type != pin->type) {
      const std::uint32_t t = temp(n);
      copy_value(t, v, pin->type, a.loc);
      v.at = t;
    }
    call.in.push_back({v.at, s->at, n});
  }
  const Type* rt = i.function->return_type;
  std::uint32_t result = 0;
  if (rt) {
    for (const VarSlot& s : out_->pous[fp].vars)
      if (s.scope == static_cast<int>(VarScope::Return)) {
        result = temp(s.cells);
        call.out.push_back({s.at, result, s.cells});
      }
  }
  out_->calls.push_back(std::move(call));
  const auto k = static_cast<std::uint32_t>(out_->calls.size() - 1);
  my_calls_.push_back(k);
  emit(Op::CALL_FN, 0, 0, 0, k);
  for (const Output& o : outputs) {
    Operand v{o.temp, o.pin->type};
    if (o.arg->negated) {
      const std::uint32_t n = temp();
      emit(Op::NOT_BOOL, n, v.at);
      v.at = n;
    }
    const Place target = place(o.arg->value);
    write(target, convert(v, target.type, o.arg->loc), o.arg->loc);
  }
  return {result, rt ? rt : program_.types->error()};
}

Operand CodeGen::conversion(const Expr& e, const ExprInfo& i, std::optional<std::uint32_t> into) {
  const Conversion& c = *i.conversion;
  const Expr& in = e.args[0].value;
  const Operand v = expr(in);
  const Type* to = i.type;
  const Type* from = v.type;
  if (to->kind == Type::Kind::String || from->kind == Type::Kind::String) {
    if (to->kind == Type::Kind::String && from->kind == Type::Kind::String) {
      error(e.loc, fmt::format("{} is not supported: convert through a number or keep one string kind", e.name));
      return {0, to};
    }
    StringCall s;
    s.site = site(e.loc, fmt::format("{}: text cut or not a value", e.name));
    if (to->kind == Type::Kind::String) {
      s.fn = StringFn::ToString;
      s.wide = to->wide;
      s.capacity = to->length;
      s.type = iec_of(*from->scalar());
      s.dst = into ? *into : temp(cells_of(to));  // into: a variable of this type (assign)
    } else {
      s.fn = StringFn::FromString;
      s.wide = from->wide;
      s.type = iec_of(*to->scalar());
      s.dst = into ? *into : temp();
    }
    s.args[0] = v.at;
    string_op(s);
    return {s.dst, to};
  }
  const auto fe = from->scalar(), te = to->scalar();
  if (!fe || !te) {
    error(e.loc, fmt::format("the code generator cannot convert {} to {}", from->name, to->name));
    return {0, to};
  }
  // DT_TO_DATE, DT_TO_TOD: the day and the time in it (the checker lets no
  // other date conversion through).
  if (*fe == Elem::DT && (*te == Elem::DATE || *te == Elem::TOD)) {
    const std::uint32_t dst = into ? *into : temp();
    emit(*te == Elem::DATE ? Op::DT_TO_DATE : Op::DT_TO_TOD, dst, v.at, 0, 0,
         site(e.loc, fmt::format("{}: the day is before DATE's first (1677-09-22)", e.name)));
    return {dst, to};
  }
  const bool dates = *fe >= Elem::DATE || *te >= Elem::DATE;
  if (dates && *fe != *te) {
    error(e.loc, fmt::format("the code generator cannot convert {} to {}", from->name, to->name));
    return {0, to};
  }
  const IecType fi = iec_of(*fe), ti = iec_of(*te);
  const std::uint32_t dst = into ? *into : temp();
  if (fi == ti && !c.trunc) {
    emit(Op::MOV, dst, v.at);
    return {dst, to};
  }
  emit(Op::CONV, dst, v.at, 0, conversion_index(conversion_fn(fi, ti, c.trunc)),
       site(e.loc, fmt::format("{}: value out of range", e.name)));
  return {dst, to};
}

Operand CodeGen::std_call(const Expr& e, const ExprInfo& i, std::optional<std::uint32_t> into) {
  const StdFunction& f = *i.std_function;
  const auto& bound = program_.std_args.at(&e);
  const Type* t = i.operand_type;
  if (!t) {
    if (f.result == ResultRule::T) {
      t = i.type;
    } else {
      for (const auto& [a, p] : bound)
        if (p->cls == ParamClass::T) {
          t = program_.info(a->value)->type;
          break;
        }
    }
  }
  if (f.generic == GenericClass::AnyString) return string_call(e, i, f, into);
  if (f.generic == GenericClass::None) return time_call(e, i, f, into);
  auto arg = [&](std::string_view name) -> const Expr* {
    for (const auto& [a, p] : bound)
      if (same_name(p->name, name)) return &a->value;
    return nullptr;
  };
  const std::string_view name = f.name;
  const auto n = num_of(t);
  if (!n && !(same_name(name, "SEL") || same_name(name, "MUX"))) {
    error(e.loc, fmt::format("the code generator has no {} for {}", name, t->name));
    return {0, i.type};
  }
  const bool lreal = n && *n == Num::F64;
  auto first = [&] { return convert(expr(bound[0].first->value), t, bound[0].first->value.loc); };
  if (same_name(name, "ABS")) {
    const Operand v = first();
    const std::uint32_t dst = into ? *into : temp();
    emit(op_of(Op::ABS_I8, *n), dst, v.at);
    return {dst, t};
  }
  if (Math1Fn m = math1_fn(name, lreal)) {
    const Operand v = first();
    const std::uint32_t dst = into ? *into : temp();
    emit(Op::MATH1, dst, v.at, 0, math1(m));
    return {dst, t};
  }
  if (Math2Fn m = math2_fn(name, lreal)) {
    const Operand a = convert(expr(bound[0].first->value), t, e.loc);
    const Operand b = convert(expr(bound[1].first->value), t, e.loc);
    const std::uint32_t dst = into ? *into : temp();
    emit(Op::MATH2, dst, a.at, b.at, math2(m));
    return {dst, t};
  }
  if (same_name(name, "TRUNC")) {
    const Operand v = first();
    const std::uint32_t dst = into ? *into : temp();
    emit(Op::CONV, dst, v.at, 0, conversion_index(conversion_fn(iec_of(*t->scalar()), IecType::DINT, true)),
         site(e.loc, "TRUNC: value out of range"));
    return {dst, i.type};
  }
  const Op shifts[] = {Op::SHL_U8, Op::SHR_U8, Op::ROL_U8, Op::ROR_U8};
  const char* shift_names[] = {"SHL", "SHR", "ROL", "ROR"};
  for (int k = 0; k < 4; ++k)
    if (same_name(name, shift_names[k])) {
      const Operand v = first();
      const Operand by = as_i64(expr(bound[1].first->value));
      const int width = *n == Num::U8 ? 0 : *n == Num::U16 ? 1 : *n == Num::U32 ? 2 : 3;
      const std::uint32_t dst = into ? *into : temp();
      emit(static_cast<Op>(static_cast<int>(shifts[k]) + width), dst, v.at, by.at);
      if (t->is(Elem::BOOL)) {
        Cell one;
        one.set<std::uint8_t>(1);
        emit(Op::AND, dst, dst, constant_cell(one));
      }
      return {dst, t};
    }
  if (same_name(name, "MIN") || same_name(name, "MAX")) {
    const Op op = op_of(same_name(name, "MIN") ? Op::MIN_I8 : Op::MAX_I8, *n);
    Operand acc = first();
    for (std::size_t k = 1; k < bound.size(); ++k) {
      const Operand b = convert(expr(bound[k].first->value), t, bound[k].first->value.loc);
      const std::uint32_t dst = k + 1 == bound.size() && into ? *into : temp();
      emit(op, dst, acc.at, b.at);
      acc = {dst, t};
    }
    return acc;
  }
  if (same_name(name, "LIMIT")) {
    const Operand mn = convert(expr(*arg("MN")), t, e.loc);
    const Operand in = convert(expr(*arg("IN")), t, e.loc);
    const Operand mx = convert(expr(*arg("MX")), t, e.loc);
    const std::uint32_t lo = temp();
    emit(op_of(Op::MAX_I8, *n), lo, in.at, mn.at);
    const std::uint32_t dst = into ? *into : temp();
    emit(op_of(Op::MIN_I8, *n), dst, lo, mx.at);
    return {dst, t};
  }
  if (same_name(name, "SEL")) {
    const Operand g = convert(expr(*arg("G")), program_.types->elem(Elem::BOOL), e.loc);
    const Operand in0 = convert(expr(*arg("IN0")), t, e.loc);
    const Operand in1 = convert(expr(*arg("IN1")), t, e.loc);
    const std::uint32_t dst = into && cells_of(t) == 1 ? *into : temp(cells_of(t));
    const std::uint32_t jz = emit(Op::JZ, g.at);
    copy_value(dst, in1, t, e.loc);
    const std::uint32_t jmp = emit(Op::JMP);
    patch(jz, pc());
    copy_value(dst, in0, t, e.loc);
    patch(jmp, pc());
    return {dst, t};
  }
  if (same_name(name, "MUX")) {
    const std::uint32_t c = cells_of(t);
    const std::uint32_t count = static_cast<std::uint32_t>(bound.size() - 1);
    const Operand k = as_i64(expr(bound[0].first->value));
    const std::uint32_t block = temp(1 + count * c);
    emit(Op::MOV, block, k.at);
    for (std::uint32_t m = 0; m < count; ++m) {
      const Expr& x = bound[m + 1].first->value;
      copy_value(block + 1 + m * c, convert(expr(x), t, x.loc), t, x.loc);
    }
    const std::uint32_t dst = into && c == 1 ? *into : temp(c);
    emit(Op::MUX, dst, block, c, count, site(e.loc, fmt::format("MUX: K outside 0..{}", count - 1)));
    return {dst, t};
  }
  error(e.loc, fmt::format("the code generator has no {}", name));
  return {0, i.type};
}

// The functions of the time types (tables 35 and 36): the operators by
// name, as the operators compute them, and the date functions (DATEFN).
Operand CodeGen::time_call(const Expr& e, const ExprInfo& i, const StdFunction& f, std::optional<std::uint32_t> into) {
  const auto& bound = program_.std_args.at(&e);
  // Evaluated in the order written, kept in the order of the parameters.
  std::vector<Operand> v(f.params.size());
  for (const auto& [a, p] : bound) {
    const auto k = static_cast<std::size_t>(p - f.params.data());
    const Operand x = expr(a->value);
    v[k] = p->cls == ParamClass::Fixed ? convert(x, program_.types->elem(p->elem), a->value.loc) : x;
  }
  const std::string_view name = f.name;
  const std::uint32_t dst = into ? *into : temp();
  auto starts = [&](std::string_view prefix) { return name.size() > prefix.size() && same_name(name.substr(0, prefix.size()), prefix); };
  if (starts("ADD_") || same_name(name, "CONCAT_DATE_TOD")) {
    emit(Op::ADD_I64, dst, v[0].at, v[1].at);  // DATE + TOD: the day's midnight plus the time of day
  } else if (starts("SUB_")) {
    emit(Op::SUB_I64, dst, v[0].at, v[1].at);
  } else if (same_name(name, "MUL_TIME") || same_name(name, "DIV_TIME")) {
    // As TIME * k and TIME / k: a real factor rounds to the nanosecond and saturates.
    const bool mul = same_name(name, "MUL_TIME");
    const auto nf = num_of(v[1].type);
    if (nf && (*nf == Num::F32 || *nf == Num::F64)) {
      const Operand r = convert(v[1], program_.types->elem(Elem::LREAL), e.loc);
      emit(Op::MATH2, dst, v[0].at, r.at, math2(mul ? time_mul_real : time_div_real));
    } else {
      emit(mul ? Op::MUL_I64 : Op::DIV_I64, dst, v[0].at, as_i64(v[1]).at, 0,
           mul ? 0u : site(e.loc, "division by zero"));
    }
  } else {
    const DateFn fn = same_name(name, "CONCAT_DATE")   ? DateFn::ConcatDate
                      : same_name(name, "CONCAT_TOD")  ? DateFn::ConcatTod
                      : same_name(name, "CONCAT_DT")   ? DateFn::ConcatDt
                                                       : DateFn::DayOfWeek;
    const auto n = static_cast<std::uint32_t>(v.size());
    const std::uint32_t block = temp(n);
    for (std::uint32_t k = 0; k < n; ++k) emit(Op::MOV, block + k, fn == DateFn::DayOfWeek ? v[k].at : as_i64(v[k]).at);
    emit(Op::DATEFN, dst, block, 0, static_cast<std::uint32_t>(fn),
         site(e.loc, fmt::format("{}: {}", name, fn == DateFn::DayOfWeek ? "no such day" : "a field out of its range, or a date DATE does not hold")));
  }
  return {dst, i.type};
}

Operand CodeGen::string_call(const Expr& e, const ExprInfo& i, const StdFunction& f, std::optional<std::uint32_t> into) {
  const auto& bound = program_.std_args.at(&e);
  const Type* t = i.operand_type ? i.operand_type : i.type;
  StringCall s;
  s.wide = t->wide;
  s.site = site(e.loc, fmt::format("{}: result cut or position out of range", f.name));
  std::vector<std::uint32_t> args;
  for (const auto& [a, p] : bound) {
    const Operand v = expr(a->value);
    args.push_back(p->cls == ParamClass::T ? v.at : as_i64(v).at);
  }
  for (std::size_t k = 0; k < args.size() && k < 4; ++k) s.args[k] = args[k];
  const std::string_view name = f.name;
  if (same_name(name, "LEN") || same_name(name, "FIND")) {
    s.fn = same_name(name, "LEN") ? StringFn::Len : StringFn::Find;
    s.dst = into ? *into : temp();
    string_op(s);
    return {s.dst, i.type};
  }
  const Type* rt = i.type;
  s.capacity = rt->length;
  const std::uint32_t n = cells_of(rt);
  if (same_name(name, "CONCAT")) {
    s.fn = StringFn::Concat;
    std::uint32_t acc = s.args[0];
    // CONCAT(a, b, c, …): chained, each step into a new temporary.
    for (std::size_t m = 1; m < bound.size(); ++m) {
      StringCall step = s;
      step.args[0] = acc;
      step.args[1] = args[m];
      // The last step into the assigned variable, unless it is an operand
      // (a destination never aliases a source, st_string.hpp).
      const bool last = m + 1 == bound.size();
      step.dst = last && into && *into != acc && *into != args[m] ? *into : temp(n);
      string_op(step);
      acc = step.dst;
    }
    return {acc, rt};
  }
  if (same_name(name, "LEFT")) s.fn = StringFn::Left;
  else if (same_name(name, "RIGHT")) s.fn = StringFn::Right;
  else if (same_name(name, "MID")) s.fn = StringFn::Mid;
  else if (same_name(name, "INSERT")) s.fn = StringFn::Insert;
  else if (same_name(name, "DELETE")) s.fn = StringFn::Delete;
  else if (same_name(name, "REPLACE")) s.fn = StringFn::Replace;
  else {
    error(e.loc, fmt::format("the code generator has no {}", name));
    return {0, rt};
  }
  bool aliased = false;
  for (std::uint32_t a : args) aliased = aliased || (into && a == *into);
  s.dst = into && !aliased ? *into : temp(n);
  string_op(s);
  return {s.dst, rt};
}

}  // namespace syncplc::st::vm
