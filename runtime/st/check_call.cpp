// The checker's calls: FB instances (named inputs :=, outputs =>, VAR_IN_OUT
// bound to a variable), user FUNCTIONs (positional or named), the standard
// functions of std_functions.hpp and the type conversions.
#include <algorithm>
#include <set>

#include <fmt/format.h>

#include "runtime/st/check_context.hpp"

namespace syncplc::st {

namespace {

const char* dir_word(PinDir d) {
  switch (d) {
    case PinDir::Input: return "VAR_INPUT";
    case PinDir::Output: return "VAR_OUTPUT";
    case PinDir::InOut: return "VAR_IN_OUT";
    default: return "internal variable";
  }
}

// Whether e names a place (a VAR_IN_OUT needs one, not a value).
bool is_place(const Expr& e) {
  return e.kind == ExprKind::Name || e.kind == ExprKind::Member || e.kind == ExprKind::Index ||
         e.kind == ExprKind::BitAccess;
}

}  // namespace

// An argument of a call in error is still checked for its own mistakes.
void Checker::skim(const Argument& a) {
  if (a.value.kind == ExprKind::None) return;
  if (a.output) target(a.value);
  else expr(a.value);
}

// The arguments of an FB instance call or a user function call, against the
// parameters `params` (inputs, in-outs and outputs in declaration order).
void Checker::bind_args(const Expr& e, const std::string& callee, const std::vector<const Pin*>& params) {
  std::set<const Pin*> bound;
  std::size_t positional = 0;
  std::vector<const Pin*> positional_params;
  for (const Pin* p : params)
    if (p->dir == PinDir::Input || p->dir == PinDir::InOut) positional_params.push_back(p);
  for (const Argument& a : e.args) {
    const Pin* p = nullptr;
    if (a.name.empty()) {
      if (positional >= positional_params.size()) {
        error(a.loc, fmt::format("{} takes {} input(s); this argument is one too many", callee,
                                 positional_params.size()));
        if (a.value.kind != ExprKind::None) expr(a.value);
        continue;
      }
      p = positional_params[positional++];
    } else {
      for (const Pin* q : params)
        if (same_name(q->name, a.name)) p = q;
      if (!p) {
        std::vector<std::string_view> names;
        for (const Pin* q : params) names.push_back(q->name);
        const std::string best = closest_name(a.name, names);
        error(a.loc, fmt::format("{} has no {} '{}'{}", callee, a.output ? "output" : "input", a.name,
                                 best.empty() ? "" : " (did you mean " + best + "?)"));
        skim(a);
        continue;
      }
    }
    out_.args[&a] = p;
    if (!bound.insert(p).second) error(a.loc, fmt::format("'{}' is given twice", p->name));
    if (a.output) {
      if (p->dir != PinDir::Output) {
        error(a.loc, fmt::format("'{}' is a {} of {}: '=>' takes an output", p->name, dir_word(p->dir), callee));
        continue;
      }
      if (a.value.kind == ExprKind::None) continue;  // q => : left unconnected
      const Type* t = target(a.value);
      if (a.negated && !p->type->is(Elem::BOOL) && !p->type->is_error())
        error(a.loc, fmt::format("NOT {} => needs a BOOL output, '{}' is {}", p->name, p->name, p->type->name));
      if (!t->is_error() && !assignable(p->type, t)) {
        const std::string hint = conversion_hint(p->type, t);
        error(a.value.loc, fmt::format("output '{}' => : expected {}, found {}{}", p->name, t->name, p->type->name,
                                       hint.empty() ? "" : " (use a variable of type " + p->type->name + ")"));
      }
      continue;
    }
    if (p->dir == PinDir::Output) {
      error(a.loc, fmt::format("'{}' is an output of {}: connect it with '=>'", p->name, callee));
      expr(a.value);
      continue;
    }
    if (p->dir == PinDir::InOut) {
      if (!is_place(a.value)) {
        error(a.value.loc, fmt::format("VAR_IN_OUT '{}' of {} needs a variable, not a value", p->name, callee));
        expr(a.value);
        continue;
      }
      const Type* t = target(a.value);
      // A VAR_IN_OUT is bound to the variable itself: the types must be the same.
      // Arrays of the same bounds and element type are the same type (a
      // block's ARRAY[1..n] OF AXIS_REF pin and the program's variable).
      auto same_array = [](const Type* x, const Type* y) {
        if (x->kind != Type::Kind::Array || y->kind != Type::Kind::Array || x->element != y->element ||
            x->dims.size() != y->dims.size())
          return false;
        for (std::size_t k = 0; k < x->dims.size(); ++k)
          if (x->dims[k].low != y->dims[k].low || x->dims[k].high != y->dims[k].high) return false;
        return true;
      };
      if (!t->is_error() && !p->type->is_error() && t != p->type && !same_array(t, p->type) &&
          !(t->kind == Type::Kind::String && p->type->kind == Type::Kind::String && t->wide == p->type->wide))
        error(a.value.loc, fmt::format("VAR_IN_OUT '{}' of {}: expected a variable of type {}, found {}", p->name,
                                       callee, p->type->name, t->name));
      continue;
    }
    expect(a.value, p->type, fmt::format("input '{}' of {}", p->name, callee));
  }
  for (const Pin* p : params)
    if (p->dir == PinDir::InOut && !bound.count(p))
      error(e.loc, fmt::format("VAR_IN_OUT '{}' of {} must be given a variable", p->name, callee));
}

void Checker::fb_call(const Expr& e, const Type* fb_type, const std::string& instance) {
  std::vector<const Pin*> params;
  for (const Pin& p : fb_type->fb->pins)
    if (p.dir == PinDir::Input || p.dir == PinDir::Output || p.dir == PinDir::InOut) params.push_back(&p);
  bind_args(e, instance + " (" + fb_type->name + ")", params);
  // A built-in block's link given a VAR_EXTERNAL AXIS_REF by name: a claim
  // the loader checks exclusive links with (once per instance and axis).
  if (!fb_type->fb->builtin || !pou_ || e.name.empty()) return;
  for (const Argument& a : e.args) {
    const auto it = out_.args.find(&a);
    if (it == out_.args.end() || it->second->dir != PinDir::InOut || it->second->type->ref_target.empty()) continue;
    if (a.value.kind != ExprKind::Name) continue;
    const ExprInfo* i = out_.info(a.value);
    if (!i || !i->variable || i->variable->scope != VarScope::External) continue;
    LinkClaim c{pou_->name, instance, fb_type->fb->name, it->second->name, i->variable->name, a.value.loc};
    const bool seen = std::any_of(out_.link_claims.begin(), out_.link_claims.end(), [&](const LinkClaim& o) {
      return o.pou == c.pou && same_name(o.instance, c.instance) && o.pin == c.pin && same_name(o.external, c.external);
    });
    if (!seen) out_.link_claims.push_back(std::move(c));
  }
}

Val Checker::call(const Expr& e, bool as_statement, const Type* want) {
  ExprInfo* i = &info(e);
  auto fb_result = [&](const Type* t, const std::string& instance) -> Val {
    info(e).symbol = SymbolKind::FbCall;
    if (auto it = fb_pous_.find(t->fb); it != fb_pous_.end()) record_call(it->second, e.loc);
    fb_call(e, t, instance);
    if (!as_statement) {
      error(e.loc, fmt::format("calling the instance '{}' is a statement, not a value: call it, then read its outputs "
                               "({}.output)",
                               instance, instance));
      return record(e, {err()});
    }
    return record(e, {t});
  };
  if (e.name.empty()) {  // axes[2](…)
    const Val callee = expr(e.operands[0]);
    if (callee.error()) {
      for (const Argument& a : e.args)
        skim(a);
      return record(e, {err()});
    }
    if (callee.type->kind != Type::Kind::FunctionBlock) {
      error(e.loc, fmt::format("only a function block instance can be called, this is a {}", callee.type->name));
      return record(e, {err()});
    }
    return fb_result(callee.type, "instance");
  }
  // Inside a FUNCTION its name is also its result variable; called, the name
  // is the function (a recursive call, which check_cycles reports).
  if (pou_)
    if (const Variable* v = pou_->find(e.name); v && v->scope != VarScope::Return) {
      i->variable = v;
      if (v->type->kind == Type::Kind::FunctionBlock) return fb_result(v->type, v->name);
      if (!v->type->is_error())
        error(e.loc, fmt::format("'{}' is a variable of type {}, not a function or an FB instance", e.name,
                                 v->type->name));
      return record(e, {err()});
    }
  if (auto it = functions_.find(name_key(e.name)); it != functions_.end()) {
    const PouInfo& f = *it->second;
    info(e).symbol = SymbolKind::UserFunction;
    info(e).function = &f;
    record_call(&f, e.loc);
    std::vector<const Pin*> params;
    for (const auto& p : f.params) params.push_back(&p);
    bind_args(e, e.name, params);
    return record(e, {f.return_type ? f.return_type : err()});
  }
  if (const StdFunction* f = find_std_function(e.name)) return std_call(e, *f, want);
  if (const auto c = parse_conversion(e.name)) return conversion_call(e, *c);
  std::vector<std::string_view> names = std_function_names();
  for (const auto& [k, p] : functions_) names.push_back(p->name);
  if (pou_)
    for (const auto& v : pou_->variables)
      if (v->type->kind == Type::Kind::FunctionBlock) names.push_back(v->name);
  const std::string best = closest_name(e.name, names);
  error(e.loc, fmt::format("unknown function or FB instance '{}'{}", e.name,
                           best.empty() ? "" : " (did you mean " + best + "?)"));
  for (const Argument& a : e.args)
    skim(a);
  return record(e, {err()});
}

Val Checker::std_call(const Expr& e, const StdFunction& f, const Type*) {
  info(e).symbol = SymbolKind::StdFunction;
  info(e).std_function = &f;
  // Each argument with its parameter: positional in order; named by the
  // parameter's name (a repeated last one numbered: IN1, IN2, …).
  std::vector<std::pair<const Argument*, const StdParam*>> bound;
  bool ok = true;
  for (std::size_t k = 0; k < e.args.size(); ++k) {
    const Argument& a = e.args[k];
    const StdParam* p = nullptr;
    if (a.output) {
      error(a.loc, fmt::format("{} has no outputs to connect with '=>'", f.name));
      ok = false;
      continue;
    }
    if (!a.name.empty()) {
      for (const auto& q : f.params)
        if (same_name(q.name, a.name)) p = &q;
      if (!p && f.variadic && a.name.size() > f.params.back().name.size() &&
          same_name(a.name.substr(0, f.params.back().name.size()), f.params.back().name))
        p = &f.params.back();
      if (!p) {
        error(a.loc, fmt::format("{} has no input '{}'", f.name, a.name));
        expr(a.value);
        ok = false;
        continue;
      }
    } else if (k < f.params.size()) {
      p = &f.params[k];
    } else if (f.variadic) {
      p = &f.params.back();
    } else {
      error(a.loc, fmt::format("{} takes {} argument(s), found {}", f.name, f.params.size(), e.args.size()));
      expr(a.value);
      ok = false;
      continue;
    }
    bound.push_back({&a, p});
  }
  if (ok && e.args.size() < f.min_args) {
    error(e.loc, fmt::format("{} takes {}{} argument(s), found {}", f.name, f.variadic ? "at least " : "", f.min_args,
                             e.args.size()));
    ok = false;
  }
  // The generic type T: the common type of the typed T arguments.
  std::vector<std::pair<const Argument*, Val>> generic;
  const Type* t = nullptr;
  bool all_literal = true;
  Val::Lit lit_kind = Val::Lit::Int;
  for (auto& [a, p] : bound) {
    Val v = expr(a->value, p->cls == ParamClass::Bool    ? elem(Elem::BOOL)
                           : p->cls == ParamClass::Fixed ? elem(p->elem)
                                                         : nullptr);
    if (v.error()) {
      ok = false;
      continue;
    }
    const auto s = v.type->scalar();
    const std::string where = fmt::format("{} of {}", p->name, f.name);
    switch (p->cls) {
      case ParamClass::Bool: coerce(a->value, v, elem(Elem::BOOL), where); break;
      case ParamClass::Fixed: coerce(a->value, v, elem(p->elem), where); break;
      case ParamClass::AnyInt:
      case ParamClass::AnyNum:
        if (v.lit == Val::Lit::Int || (v.lit == Val::Lit::Real && p->cls == ParamClass::AnyNum) ||
            (v.lit == Val::Lit::None && s && (p->cls == ParamClass::AnyInt ? is_int(*s) : is_num(*s)))) {
          settle_default(a->value, v);
        } else {
          error(a->value.loc, fmt::format("{}: expected {}, found {}", where,
                                          p->cls == ParamClass::AnyInt ? "an integer (ANY_INT)" : "a number (ANY_NUM)",
                                          v.lit == Val::Lit::Real ? "a real literal" : v.type->name));
          ok = false;
        }
        break;
      case ParamClass::T:
        generic.push_back({a, v});
        if (v.lit == Val::Lit::None) {
          all_literal = false;
          const Type* c = t ? common(t, v.type) : v.type;
          if (!c) {
            error(a->value.loc, fmt::format("{}: {} and {} have no common type (the inputs of {} take one type)",
                                            where, t->name, v.type->name, f.name));
            ok = false;
          } else {
            t = c;
          }
        } else if (v.lit == Val::Lit::Real) {
          lit_kind = Val::Lit::Real;
        }
        break;
    }
  }
  if (!ok) return record(e, {err()});
  out_.std_args[&e] = bound;
  Val result;
  if (!generic.empty() && all_literal) {
    // Literals only: a number whose type the context decides (MAX(1, 2)).
    const Type* d = elem(lit_kind == Val::Lit::Real || f.generic == GenericClass::AnyReal ? Elem::LREAL : Elem::DINT);
    if (f.generic == GenericClass::AnyBits || f.generic == GenericClass::AnyString ||
        (f.generic == GenericClass::AnyInt && lit_kind == Val::Lit::Real)) {
      error(e.loc, fmt::format("{} needs {} arguments; give a literal its type (e.g. WORD#16#FF)", f.name,
                               generic_class_name(f.generic)));
      return record(e, {err()});
    }
    // The arguments stay untyped literals: settling the call settles them.
    if (f.result != ResultRule::T) {
      for (auto& [a, v] : generic) settle(a->value, d);
      return record(e, {elem(f.result == ResultRule::Int ? Elem::INT : Elem::DINT)});
    }
    result.type = d;
    result.lit = f.generic == GenericClass::AnyReal ? Val::Lit::Real : lit_kind;
    return record(e, result);
  }
  if (t && !in_generic_class(t, f.generic)) {
    error(e.loc, fmt::format("{} needs {} inputs, found {}", f.name, generic_class_name(f.generic), t->name));
    return record(e, {err()});
  }
  for (auto& [a, v] : generic) coerce(a->value, v, t, fmt::format("input of {}", f.name));
  info(e).operand_type = t;
  switch (f.result) {
    case ResultRule::T: result.type = t ? t : err(); break;
    case ResultRule::Int: result.type = elem(Elem::INT); break;
    case ResultRule::Dint: result.type = elem(Elem::DINT); break;
    case ResultRule::Fixed: result.type = elem(f.result_elem); break;
  }
  return record(e, result);
}

Val Checker::conversion_call(const Expr& e, const Conversion& c) {
  info(e).symbol = SymbolKind::Conversion;
  info(e).conversion = c;
  if (e.args.size() != 1 || e.args[0].output || (!e.args[0].name.empty() && !same_name(e.args[0].name, "IN"))) {
    error(e.loc, fmt::format("{} takes one input", e.name));
    for (const Argument& a : e.args)
      if (a.value.kind != ExprKind::None) expr(a.value);
    return record(e, {err()});
  }
  const Expr& in = e.args[0].value;
  const Type* from = c.from ? elem(*c.from) : c.from_string ? types_.string(80, false) : c.from_wstring ? types_.string(80, true) : nullptr;
  if (from) {
    expect(in, from, fmt::format("input of {}", e.name));
  } else {
    const Val v = expr(in);
    if (!v.error() && !v.type->scalar() && v.type->kind != Type::Kind::String) {
      error(in.loc, fmt::format("{} converts an elementary value, found {}", e.name, v.type->name));
      return record(e, {err()});
    }
    settle_default(in, v);
  }
  const Type* to = c.to ? elem(*c.to) : types_.string(80, c.to_wstring);
  // Of the date types IEC 61131-3 (Table 22) converts DT to its DATE and
  // its TOD; nothing converts a date to or from a number, and their text
  // forms are not done yet (docs/st.md).
  const Type* seen = from ? from : info(in).type;
  const auto fe = seen ? seen->scalar() : std::nullopt;
  const bool from_date = fe && *fe >= Elem::DATE, to_date = c.to && *c.to >= Elem::DATE;
  if ((from_date || to_date) && !(fe && c.to && *fe == *c.to) &&
      !(fe == Elem::DT && (c.to == Elem::DATE || c.to == Elem::TOD))) {
    const std::string origin = fe == Elem::TOD ? "TOD#00:00:00" : fe == Elem::DT ? "DT#1970-01-01-00:00:00" : "D#1970-01-01";
    error(e.loc, fmt::format("{}: a DATE, TOD or DT converts only as DT_TO_DATE and DT_TO_TOD (IEC 61131-3 "
                             "Table 22); {}",
                             e.name,
                             from_date && !to_date
                                 ? fmt::format("its number is a duration's: TIME_TO_LINT(x - {}) (milliseconds)", origin)
                                 : std::string("build one from its fields (CONCAT_DATE, CONCAT_TOD, CONCAT_DT) or "
                                               "with its arithmetic (DT#1970-01-01-00:00:00 + T#...)")));
    return record(e, {err()});
  }
  return record(e, {to});
}

}  // namespace syncplc::st
