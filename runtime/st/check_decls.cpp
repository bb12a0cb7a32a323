// The checker's declarations: TYPEs, POU signatures, variables and their
// initial values, and the driver that checks every POU's body after all
// declarations are known (so a POU may use a type or FB declared later or in
// another file).
#include <algorithm>
#include <set>

#include <fmt/format.h>

#include "runtime/st/check_context.hpp"
#include "runtime/st/parser.hpp"

namespace syncplc::st {

namespace {

VarScope scope_of(VarSectionKind k) {
  switch (k) {
    case VarSectionKind::Var: return VarScope::Local;
    case VarSectionKind::Input: return VarScope::Input;
    case VarSectionKind::Output: return VarScope::Output;
    case VarSectionKind::InOut: return VarScope::InOut;
    case VarSectionKind::Temp: return VarScope::Temp;
    case VarSectionKind::External: return VarScope::External;
    case VarSectionKind::Global: return VarScope::Global;
  }
  return VarScope::Local;
}

PinDir pin_dir(VarScope s) {
  switch (s) {
    case VarScope::Input: return PinDir::Input;
    case VarScope::Output: return PinDir::Output;
    case VarScope::InOut: return PinDir::InOut;
    case VarScope::Temp: return PinDir::Temp;
    case VarScope::External: return PinDir::External;
    default: return PinDir::Local;
  }
}

const char* pou_word(PouKind k) {
  switch (k) {
    case PouKind::Function: return "FUNCTION";
    case PouKind::FunctionBlock: return "FUNCTION_BLOCK";
    case PouKind::Program: return "PROGRAM";
  }
  return "";
}

bool same_type(const Type* a, const Type* b) {
  if (a == b || a->is_error() || b->is_error()) return true;
  if (a->kind == Type::Kind::String && b->kind == Type::Kind::String)
    return a->wide == b->wide && a->length == b->length;
  return false;
}

}  // namespace

std::string type_text(const Type* t) { return t->name; }

bool fits(const ConstValue& v, Elem e) {
  if (v.is_real) return is_real(e);
  if (is_real(e)) return true;
  if (!is_int(e) && !is_bits(e)) return false;
  return v.i >= min_value(e) && v.i <= max_value(e);
}

ConstValue wrap(ConstValue v, const Type* t) {
  const auto e = t->scalar();
  if (!e || v.is_real) return v;
  if (is_real(*e)) return ConstValue{true, 0, static_cast<double>(v.i)};
  if (!is_int(*e) && !is_bits(*e)) return v;
  // Integer overflow wraps in the type, as the runtime does.
  const int n = bits(*e);
  const UWide mask = (static_cast<UWide>(1) << n) - 1;
  UWide u = static_cast<UWide>(v.i) & mask;
  if (is_signed_int(*e) && (u >> (n - 1)) != 0) v.i = static_cast<Wide>(u) - (static_cast<Wide>(1) << n);
  else v.i = static_cast<Wide>(u);
  return v;
}

const Variable* PouInfo::find(std::string_view n) const {
  for (const auto& v : variables)
    if (same_name(v->name, n)) return v.get();
  return nullptr;
}

const ExprInfo* CheckedProgram::info(const Expr& e) const {
  auto it = exprs.find(&e);
  return it == exprs.end() ? nullptr : &it->second;
}

const PouInfo* CheckedProgram::pou(std::string_view n) const {
  for (const auto& p : pous)
    if (same_name(p->name, n)) return p.get();
  return nullptr;
}

Checker::Checker(CheckedProgram& out, const std::vector<BlockSignature>& blocks) : out_(out), types_(*out.types) {
  for (const auto& b : blocks) add_builtin(b);
}

std::string Checker::suggestion(std::string_view n) {
  std::vector<std::string_view> names;
  if (pou_)
    for (const auto& v : pou_->variables) names.push_back(v->name);
  for (const auto& [k, p] : functions_) names.push_back(p->name);
  const std::string best = closest_name(n, names);
  return best.empty() ? "" : " (did you mean " + best + "?)";
}

const Type* Checker::named_type(const std::string& n, const SourceLoc& loc) {
  if (const auto e = parse_elem(n)) return elem(*e);
  const std::string key = name_key(n);
  if (auto it = out_.named_types.find(key); it != out_.named_types.end()) return it->second;
  if (auto it = fb_types_.find(key); it != fb_types_.end()) return it->second;
  if (auto it = type_decls_.find(key); it != type_decls_.end()) {
    if (std::find(resolving_.begin(), resolving_.end(), key) != resolving_.end()) {
      error(loc, fmt::format("type '{}' is defined in terms of itself", n));
      return out_.named_types[key] = err();
    }
    // Types resolve one through another, recursively: as the parser's
    // nesting, their depth is limited (the named ones here, the anonymous
    // ones of one declaration by the parser), so a generated chain cannot
    // exhaust the stack, here nor in a later pass over the types.
    if (type_depth_ >= kMaxNesting) {
      error(loc, fmt::format("type '{}' is nested deeper than {} levels", n, kMaxNesting));
      return out_.named_types[key] = err();
    }
    resolving_.push_back(key);
    const TypeDecl& d = *it->second;
    const Type* t = resolve(d.type, d.name);
    resolving_.pop_back();
    if (d.init.kind != InitKind::None) {
      check_init(d.init, t);
      out_.type_inits[key] = &d.init;
    }
    return out_.named_types[key] = t;
  }
  std::vector<std::string_view> names;
  for (int i = 0; i < kElemCount; ++i) names.push_back(elem_name(static_cast<Elem>(i)));
  names.push_back("STRING");
  names.push_back("WSTRING");
  for (const auto& [k, d] : type_decls_) names.push_back(d->name);
  for (const auto& [k, t] : fb_types_) names.push_back(t->name);
  const std::string best = closest_name(n, names);
  error(loc, fmt::format("unknown type '{}'{}", n, best.empty() ? "" : " (did you mean " + best + "?)"));
  return err();
}

std::optional<std::int64_t> Checker::const_int(const Expr& e, const Type* want, const char* what) {
  const Val v = expr(e, want);
  if (v.error()) return std::nullopt;
  const auto s = v.type->scalar();
  if (!v.c || v.c->is_real || !s || !is_int(*s)) {
    error(e.loc, fmt::format("{} must be a constant integer expression", what));
    return std::nullopt;
  }
  if (v.lit != Val::Lit::None) settle(e, v.type);
  if (v.c->i < INT64_MIN || v.c->i > INT64_MAX) {
    error(e.loc, fmt::format("{} is out of range", what));
    return std::nullopt;
  }
  return static_cast<std::int64_t>(v.c->i);
}

const Type* Checker::resolve(const TypeSpec& spec, const std::string& name_for_new) {
  ++type_depth_;
  const Type* t = resolve_spec(spec, name_for_new);
  --type_depth_;
  return t;
}

const Type* Checker::resolve_spec(const TypeSpec& spec, const std::string& name_for_new) {
  switch (spec.kind) {
    case TypeKind::Named: return named_type(spec.name, spec.loc);
    case TypeKind::String: {
      int length = 80;
      if (spec.length.kind != ExprKind::None) {
        const auto n = const_int(spec.length, nullptr, "a string's length");
        if (!n) return err();
        if (*n < 1 || *n > 65535) {
          error(spec.length.loc, fmt::format("a string's length must be 1 to 65535, found {}", *n));
          return err();
        }
        length = static_cast<int>(*n);
      }
      return types_.string(length, spec.wide);
    }
    case TypeKind::Array: {
      Type t;
      t.kind = Type::Kind::Array;
      t.loc = spec.loc;
      bool ok = true;
      for (const auto& d : spec.dims) {
        const auto lo = const_int(d.low, nullptr, "an array bound");
        const auto hi = const_int(d.high, nullptr, "an array bound");
        if (!lo || !hi) { ok = false; continue; }
        if (*lo > *hi) {
          error(d.loc, fmt::format("array bounds {}..{}: the lower bound is above the upper", *lo, *hi));
          ok = false;
          continue;
        }
        t.dims.push_back({*lo, *hi});
      }
      t.element = spec.element.empty() ? err() : resolve(spec.element[0], "");
      if (!ok || t.element->is_error() || incomplete_block(t.element, spec.loc, "an array")) return err();
      std::string dims;
      for (const auto& d : t.dims) dims += (dims.empty() ? "" : ",") + fmt::format("{}..{}", d.low, d.high);
      t.name = name_for_new.empty() ? fmt::format("ARRAY[{}] OF {}", dims, t.element->name) : name_for_new;
      return types_.add(std::move(t));
    }
    case TypeKind::Struct: {
      Type t;
      t.kind = Type::Kind::Struct;
      t.loc = spec.loc;
      t.name = name_for_new.empty() ? "STRUCT" : name_for_new;
      for (const auto& m : spec.members) {
        const Type* ft = resolve(m.type, "");
        if (incomplete_block(ft, m.type.loc, "a field")) ft = err();
        if (m.init.kind != InitKind::None) check_init(m.init, ft);
        for (std::size_t i = 0; i < m.names.size(); ++i) {
          const SourceLoc& loc = i < m.name_locs.size() ? m.name_locs[i] : m.loc;
          if (const Field* f = t.field(m.names[i]))
            error(loc, fmt::format("duplicate field '{}' (first at {})", m.names[i], f->loc.text()));
          else
            t.fields.push_back({m.names[i], ft, loc, &m.init, &m.type});
        }
      }
      return types_.add(std::move(t));
    }
    case TypeKind::Enum: {
      Type t;
      t.kind = Type::Kind::Enum;
      t.loc = spec.loc;
      t.name = name_for_new.empty() ? "enumeration" : name_for_new;
      t.elem = Elem::INT;
      if (!spec.name.empty()) {
        const auto base = parse_elem(spec.name);
        if (!base || !is_int(*base)) {
          error(spec.loc, fmt::format("an enumeration's base type must be an integer type, found '{}'", spec.name));
          return err();
        }
        t.elem = *base;
      }
      std::int64_t next = 0;
      for (const auto& en : spec.enumerators) {
        std::int64_t v = next;
        if (en.value.kind != ExprKind::None)
          if (const auto c = const_int(en.value, elem(t.elem), "an enumeration value")) v = *c;
        if (!fits(ConstValue{false, v, 0}, t.elem))
          error(en.loc, fmt::format("value {} of '{}' does not fit {}", v, en.name, elem_name(t.elem)));
        if (const EnumValue* d = t.value(en.name))
          error(en.loc, fmt::format("duplicate enumeration value '{}' (first at {})", en.name, d->loc.text()));
        else
          t.values.push_back({en.name, v, en.loc});
        next = v + 1;
      }
      const Type* p = types_.add(std::move(t));
      enums_.push_back(p);
      return p;
    }
    case TypeKind::Subrange: {
      const auto base = parse_elem(spec.name);
      if (!base || !is_int(*base)) {
        error(spec.loc, fmt::format("a subrange's base type must be an integer type, found '{}'", spec.name));
        return err();
      }
      if (spec.dims.empty()) return err();
      const auto lo = const_int(spec.dims[0].low, elem(*base), "a subrange bound");
      const auto hi = const_int(spec.dims[0].high, elem(*base), "a subrange bound");
      if (!lo || !hi) return err();
      if (*lo > *hi) {
        error(spec.dims[0].loc, fmt::format("subrange {}..{}: the lower bound is above the upper", *lo, *hi));
        return err();
      }
      Type t;
      t.kind = Type::Kind::Subrange;
      t.loc = spec.loc;
      t.elem = *base;
      t.low = *lo;
      t.high = *hi;
      t.name = name_for_new.empty() ? fmt::format("{} ({}..{})", elem_name(*base), *lo, *hi) : name_for_new;
      return types_.add(std::move(t));
    }
  }
  return err();
}

void Checker::check_init(const Initializer& init, const Type* type, bool block_params) {
  if (type->is_error()) return;
  switch (init.kind) {
    case InitKind::None: return;
    case InitKind::Expr: {
      const Val v = expect(init.expr, type, "initial value");
      const bool literal_string = init.expr.kind == ExprKind::Literal &&
                                  (init.expr.literal.kind == LiteralKind::String ||
                                   init.expr.literal.kind == LiteralKind::WString);
      if (!v.error() && !v.c && !literal_string)
        error(init.expr.loc, "an initial value must be a constant expression");
      return;
    }
    case InitKind::Struct: {
      if (type->kind != Type::Kind::Struct && type->kind != Type::Kind::FunctionBlock) {
        error(init.loc, fmt::format("a structure initial value for a {}", type_text(type)));
        return;
      }
      std::set<std::string> seen;
      for (const auto& f : init.fields) {
        if (!seen.insert(name_key(f.name)).second) {
          error(f.loc, fmt::format("'{}' is initialised twice", f.name));
          continue;
        }
        if (type->kind == Type::Kind::Struct) {
          const Field* field = type->field(f.name);
          if (!field) {
            std::vector<std::string_view> names;
            for (const auto& x : type->fields) names.push_back(x.name);
            const std::string best = closest_name(f.name, names);
            error(f.loc, fmt::format("'{}' has no field '{}'{}", type->name, f.name,
                                     best.empty() ? "" : " (did you mean " + best + "?)"));
            continue;
          }
          check_init(f.value, field->type);
        } else {
          const FbType& fb = *type->fb;
          if (fb.builtin && fb.param(f.name)) {
            if (!block_params)
              error(f.loc, fmt::format("parameter '{}' of {}: a built-in block's parameters are given in the "
                                       "declaration of an instance on its own, not inside an array or a structure",
                                       f.name, fb.name));
            continue;
          }
          const Pin* pin = fb.find(f.name);
          if (!pin || pin->dir == PinDir::InOut || pin->dir == PinDir::External) {
            std::vector<std::string_view> names;
            for (const auto& x : fb.pins)
              if (x.dir != PinDir::InOut && x.dir != PinDir::External) names.push_back(x.name);
            for (const auto& x : fb.params) names.push_back(x.name);
            const std::string best = closest_name(f.name, names);
            error(f.loc, fmt::format("'{}' has no input{} or variable '{}' to initialise{}", type->name,
                                     fb.builtin ? ", parameter" : "", f.name,
                                     best.empty() ? "" : " (did you mean " + best + "?)"));
            continue;
          }
          check_init(f.value, pin->type);
        }
      }
      return;
    }
    case InitKind::Array: {
      if (type->kind != Type::Kind::Array) {
        error(init.loc, fmt::format("an array initial value for a {}", type_text(type)));
        return;
      }
      std::int64_t count = 0;
      for (const auto& el : init.elements) {
        std::int64_t n = 1;
        if (el.repeat.kind != ExprKind::None) {
          const auto r = const_int(el.repeat, nullptr, "a repetition count");
          if (!r) continue;
          if (*r < 0) {
            error(el.repeat.loc, "a repetition count must not be negative");
            continue;
          }
          n = *r;
        }
        check_init(el.value, type->element);
        count += n;
      }
      if (count > type->element_count())
        error(init.loc, fmt::format("{} initial values for an array of {} elements", count, type->element_count()));
      return;
    }
  }
}

void Checker::declare_section(PouInfo* info, const VarSection& section, VarScope scope,
                              std::vector<std::unique_ptr<Variable>>& into) {
  for (const auto& d : section.decls) {
    const Type* t = resolve(d.type, "");
    // A built-in block's instance: its type is that of the parameters its
    // initializer gives (its inputs' initial values are still checked when
    // a parameter is wrong, against the block's own type).
    const Type* declared = t;
    const bool in_function = info && info->kind == PouKind::Function;
    if (in_function && t->kind == Type::Kind::FunctionBlock)
      error(d.type.loc, fmt::format("a FUNCTION keeps no state, so it cannot hold an instance of {}", t->name));
    const bool instance = scope != VarScope::InOut && scope != VarScope::External && !in_function;
    if (instance && t->kind == Type::Kind::FunctionBlock && t->fb->builtin && !d.names.empty())
      t = block_instance(t, d.init, d.names[0], d.name_locs.empty() ? d.loc : d.name_locs[0]);
    if (scope == VarScope::InOut || scope == VarScope::External) {
      if (d.init.kind != InitKind::None)
        error(d.init.loc, fmt::format("a {} variable takes no initial value",
                                      scope == VarScope::InOut ? "VAR_IN_OUT" : "VAR_EXTERNAL"));
    } else {
      check_init(d.init, t->is_error() ? declared : t, true);
    }
    if (section.constant && d.init.kind == InitKind::None && scope != VarScope::External)
      error(d.loc, "a CONSTANT needs an initial value");
    for (std::size_t i = 0; i < d.names.size(); ++i) {
      const SourceLoc& loc = i < d.name_locs.size() ? d.name_locs[i] : d.loc;
      const std::string& n = d.names[i];
      const Variable* dup = nullptr;
      for (const auto& v : into)
        if (same_name(v->name, n)) dup = v.get();
      if (dup) {
        error(loc, fmt::format("duplicate name '{}' (first declared at {})", n, dup->loc.text()));
        continue;
      }
      auto v = std::make_unique<Variable>();
      v->name = n;
      v->scope = scope;
      v->type = t;
      v->constant = section.constant;
      v->retain = section.retain || section.persistent;
      v->persistent = section.persistent;
      v->address = d.address;
      v->init = &d.init;
      v->spec = &d.type;
      v->loc = loc;
      if (section.constant && d.init.kind == InitKind::Expr) {
        const ExprInfo* ei = out_.info(d.init.expr);
        if (ei && ei->constant) v->value = ei->constant;
      }
      if (scope == VarScope::External) {
        auto g = globals_.find(name_key(n));
        if (g != globals_.end()) {
          if (!same_type(g->second->type, t))
            error(loc, fmt::format("VAR_EXTERNAL '{}' is {} here but {} in its VAR_GLOBAL at {}", n, t->name,
                                   g->second->type->name, g->second->loc.text()));
          if (g->second->constant && !section.constant)
            error(loc, fmt::format("'{}' is a global CONSTANT: declare it in VAR_EXTERNAL CONSTANT", n));
          v->value = g->second->value;
        }
        out_.externals.push_back({info ? info->name : "", n, t, section.constant, loc});
      }
      into.push_back(std::move(v));
    }
  }
}

void Checker::declare_pou_variables(PouInfo& info, const Pou& pou) {
  if (pou.kind == PouKind::Function) {
    auto r = std::make_unique<Variable>();
    r->name = pou.name;
    r->scope = VarScope::Return;
    r->type = info.return_type;
    r->loc = pou.loc;
    info.variables.push_back(std::move(r));
  }
  for (const auto& s : pou.sections) {
    if (s.kind == VarSectionKind::External && pou.kind == PouKind::Function)
      error(s.loc, "a FUNCTION cannot use VAR_EXTERNAL (IEC 61131-3 gives functions no access to globals)");
    declare_section(&info, s, scope_of(s.kind), info.variables);
  }
}

void Checker::run(const std::vector<const CompilationUnit*>& units) {
  // Names of types and POUs first, so declarations may refer to later ones.
  std::map<std::string, SourceLoc> taken;
  auto claim = [&](const std::string& n, const SourceLoc& loc, const char* what) {
    if (parse_elem(n) || same_name(n, "STRING") || same_name(n, "WSTRING")) {
      error(loc, fmt::format("'{}' is an elementary type and cannot name a {}", n, what));
      return false;
    }
    auto [it, fresh] = taken.emplace(name_key(n), loc);
    if (!fresh) {
      error(loc, fmt::format("duplicate name '{}' (first declared at {})", n, it->second.text()));
      return false;
    }
    if (fb_types_.count(name_key(n)) != 0 || find_std_function(n) != nullptr) {
      error(loc, fmt::format("'{}' is the name of a built-in {}", n,
                             find_std_function(n) ? "function" : "function block"));
      return false;
    }
    return true;
  };
  for (const CompilationUnit* u : units)
    for (const auto& d : u->types)
      if (claim(d.name, d.loc, "type")) type_decls_[name_key(d.name)] = &d;
  for (const CompilationUnit* u : units)
    for (const auto& p : u->pous) {
      auto info = std::make_unique<PouInfo>();
      info->pou = &p;
      info->name = p.name;
      info->kind = p.kind;
      if (!claim(p.name, p.loc, pou_word(p.kind))) {
        out_.pous.push_back(std::move(info));
        continue;
      }
      if (p.kind == PouKind::FunctionBlock) {
        FbType fb;
        fb.name = p.name;
        fb.doc = p.doc;
        fb.loc = p.loc;
        FbType* f = types_.add_fb(std::move(fb));
        info->fb = f;
        fb_pous_[f] = info.get();
        Type t;
        t.kind = Type::Kind::FunctionBlock;
        t.name = p.name;
        t.fb = f;
        t.loc = p.loc;
        fb_types_[name_key(p.name)] = types_.add(std::move(t));
      } else if (p.kind == PouKind::Function) {
        functions_[name_key(p.name)] = info.get();
      }
      out_.pous.push_back(std::move(info));
    }
  for (const auto& [key, d] : type_decls_) named_type(d->name, d->loc);
  for (const CompilationUnit* u : units)
    for (const auto& s : u->globals) declare_section(nullptr, s, VarScope::Global, out_.globals);
  for (const auto& g : out_.globals) globals_[name_key(g->name)] = g.get();
  // Signatures and variables of every POU, then the bodies.
  for (auto& info : out_.pous) {
    pou_ = info.get();
    if (info->kind == PouKind::Function)
      info->return_type = info->pou->return_type.empty() ? err() : resolve(info->pou->return_type[0], "");
    declare_pou_variables(*info, *info->pou);
    if (info->kind == PouKind::Function)
      for (const auto& v : info->variables)
        if (v->scope == VarScope::Input || v->scope == VarScope::InOut || v->scope == VarScope::Output)
          info->params.push_back({v->name, pin_dir(v->scope), v->type, v->loc});
    if (info->fb) {
      auto* fb = const_cast<FbType*>(info->fb);
      for (const auto& v : info->variables) fb->pins.push_back({v->name, pin_dir(v->scope), v->type, v->loc});
    }
  }
  for (auto& info : out_.pous) {
    pou_ = info.get();
    loop_depth_ = 0;
    for_vars_.clear();
    body(info->pou->body);
  }
  pou_ = nullptr;
  check_cycles();
}

CheckedProgram check(const std::vector<const CompilationUnit*>& units, const std::vector<BlockSignature>& blocks) {
  CheckedProgram out;
  Checker c(out, blocks);
  c.run(units);
  return out;
}

}  // namespace syncplc::st
