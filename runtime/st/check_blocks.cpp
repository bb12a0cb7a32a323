// Built-in blocks as function block types: each signature's own type (its
// parameters at their defaults), and a type of its own for each set of
// parameter values a declaration gives (`s : TRANSIENT_SYNC := (n := 4)`),
// whose array pins are ARRAY[1..n] (1-based, as array pins are in the
// graph). The values are checked as the YAML loader checks `params:`
// (runtime/core/param_range.hpp: the same range and length messages).
#include <fmt/format.h>

#include "runtime/core/param_range.hpp"
#include "runtime/st/check_context.hpp"

namespace syncplc::st {

namespace {

// A parameter's value as ST writes it (in messages and in the type's name).
std::string param_text(Elem e, const ConstValue& v) {
  if (e == Elem::BOOL) return v.i != 0 ? "TRUE" : "FALSE";
  if (v.is_real) return fmt::format("{}", v.r);
  const auto i = static_cast<long long>(v.i);
  if (is_duration(e)) {
    if (i % 1'000'000'000 == 0) return fmt::format("T#{}s", i / 1'000'000'000);
    if (i % 1'000'000 == 0) return fmt::format("T#{}ms", i / 1'000'000);
    if (i % 1'000 == 0) return fmt::format("T#{}us", i / 1'000);
    return fmt::format("T#{}ns", i);
  }
  if (v.i > INT64_MAX) return fmt::format("{}", static_cast<unsigned long long>(v.i));
  return fmt::format("{}", i);
}

// The value ParamSpec::min/max bound: durations in seconds (as the loader's cell_as_double).
double range_value(Elem e, const ConstValue& v) {
  return is_duration(e) ? static_cast<double>(v.i) * 1e-9 : v.as_double();
}

}  // namespace

std::vector<Pin> Checker::block_pins(const FbType& fb) {
  std::vector<Pin> pins;
  for (const auto& p : block_specs_.at(fb.name)) {
    const auto e = parse_elem(p.type);
    const Type* t = !p.ref_target.empty() ? ref_type(p.type, p.ref_target) : e ? elem(*e) : err();
    if (!p.length_param.empty()) {
      // Sized by its parameter; a parameter without a value (no default, not
      // given) leaves it unknown: such a type is never instanced.
      const BlockSignature::ParamSpec* n = fb.param(p.length_param);
      const double len = n && n->value ? n->value->as_double() : 0;
      if (t->is_error() || len < 1 || len > p.max_length) {
        t = err();
      } else {
        const auto count = static_cast<std::int64_t>(len);
        const Type*& a = pin_arrays_[{count, t}];
        if (!a) {
          Type arr;
          arr.kind = Type::Kind::Array;
          arr.dims.push_back({1, count});
          arr.element = t;
          arr.name = fmt::format("ARRAY[1..{}] OF {}", count, t->name);
          a = types_.add(std::move(arr));
        }
        t = a;
      }
    }
    // A link is IEC's VAR_IN_OUT Axis : AXIS_REF: given a variable at every call.
    pins.push_back({p.name, !p.ref_target.empty() ? PinDir::InOut : p.output ? PinDir::Output : PinDir::Input, t, {}});
  }
  return pins;
}

const Type* Checker::ref_type(const std::string& name, const std::string& target) {
  const Type*& r = out_.named_types[name_key(name)];
  if (r && r->ref_target == target) return r;
  // A structure of one cell whose field ST cannot name: passed, assigned
  // and held in arrays as a structure is, never computed with.
  Type t;
  t.kind = Type::Kind::Struct;
  t.name = name;
  t.ref_target = target;
  t.fields.push_back({"(instance)", elem(Elem::UDINT), {}, nullptr, nullptr});
  r = types_.add(std::move(t));
  return r;
}

void Checker::add_builtin(const BlockSignature& b) {
  block_specs_[b.name] = b.pins;
  FbType fb;
  fb.name = b.name;
  fb.builtin = true;
  fb.doc = b.doc;
  fb.params = b.params;
  fb.pins = block_pins(fb);
  const FbType* f = types_.add_fb(std::move(fb));
  Type t;
  t.kind = Type::Kind::FunctionBlock;
  t.name = b.name;
  t.fb = f;
  fb_types_[name_key(b.name)] = types_.add(std::move(t));
}

bool Checker::incomplete_block(const Type* t, const SourceLoc& loc, std::string_view what) {
  if (t->kind != Type::Kind::FunctionBlock || !t->fb->builtin || t->fb->complete()) return false;
  for (const auto& p : t->fb->params)
    if (!p.value) {
      error(loc, fmt::format("{} of {}: its parameter '{}' has no default value, and only an instance declared on "
                             "its own can be given one ({} := (...))",
                             what, t->name, p.name, t->name));
      break;
    }
  return true;
}

const Type* Checker::block_instance(const Type* base, const Initializer& init, const std::string& var,
                                    const SourceLoc& loc) {
  const FbType& fb = *base->fb;
  std::vector<BlockSignature::ParamSpec> params = fb.params;
  std::vector<SourceLoc> given(params.size(), loc);  // where each value is written
  std::vector<bool> written(params.size(), false);
  bool ok = true;
  if (init.kind == InitKind::Struct)
    for (const FieldInit& f : init.fields) {
      std::size_t k = 0;
      while (k < params.size() && !same_name(params[k].name, f.name)) ++k;
      if (k == params.size()) continue;  // a pin, or a name check_init reports
      BlockSignature::ParamSpec& p = params[k];
      if (f.value.kind != InitKind::Expr) {
        error(f.value.loc, fmt::format("{}.{}: a parameter takes one value", var, p.name));
        ok = false;
        continue;
      }
      const Expr& x = f.value.expr;
      given[k] = x.loc;
      written[k] = true;
      const auto e = parse_elem(p.type);
      if (!e) continue;
      const Val v = expect(x, elem(*e), var + "." + p.name);
      if (v.error()) {
        ok = false;
        continue;
      }
      if (!v.c) {
        error(x.loc, fmt::format("{}.{}: a parameter's value must be a constant expression", var, p.name));
        ok = false;
        continue;
      }
      const ConstValue c = wrap(*v.c, elem(*e));
      const std::string why = param_range_error(var + "." + p.name, param_text(*e, c), range_value(*e, c), p.min, p.max,
                                                p.unit);
      if (!why.empty()) {
        error(x.loc, why);
        ok = false;
        continue;
      }
      p.value = c;
    }
  for (std::size_t k = 0; k < params.size(); ++k)
    if (!params[k].value && !written[k]) {
      error(loc, fmt::format("{}: {} needs its parameter '{}' (it has no default value): give it in the declaration, "
                             "{} : {} := ({} := ...)",
                             var, fb.name, params[k].name, var, fb.name, params[k].name));
      ok = false;
    }
  if (!ok) return err();
  // Array pins: as many elements as their parameter says, within their bounds.
  for (const auto& s : block_specs_.at(fb.name)) {
    if (s.length_param.empty()) continue;
    std::size_t k = 0;
    while (k < params.size() && params[k].name != s.length_param) ++k;
    if (k == params.size()) continue;
    const auto e = parse_elem(params[k].type);
    const std::string why = pin_length_error(var + "." + params[k].name, param_text(e.value_or(Elem::DINT), *params[k].value),
                                             params[k].value->as_double(), s.name, s.max_length);
    if (!why.empty()) {
      error(given[k], why);
      return err();
    }
  }
  // The type's name lists the values that differ from the defaults, in the
  // registry's order: one type (and name) per parameterization.
  std::string args;
  for (std::size_t k = 0; k < params.size(); ++k) {
    const auto e = parse_elem(params[k].type).value_or(Elem::LREAL);
    const std::string text = param_text(e, *params[k].value);
    if (!fb.params[k].value || param_text(e, *fb.params[k].value) != text)
      args += fmt::format("{}{} := {}", args.empty() ? "" : ", ", params[k].name, text);
  }
  if (args.empty()) return base;
  const std::string name = fmt::format("{} ({})", fb.name, args);
  const Type*& t = block_instances_[name];
  if (t) return t;
  FbType own;
  own.name = fb.name;
  own.builtin = true;
  own.doc = fb.doc;
  own.params = std::move(params);
  own.pins = block_pins(own);
  Type ty;
  ty.kind = Type::Kind::FunctionBlock;
  ty.name = name;
  ty.fb = types_.add_fb(std::move(own));
  t = types_.add(std::move(ty));
  return t;
}

}  // namespace syncplc::st
