// The code generator's POUs: the order they are compiled in, each frame's
// layout (variables, then temporaries, then constants), its initial image
// (IEC 61131-3 initial values: declared, else the type's own, else zero, an
// enumeration's first value, a subrange's lower bound, an empty string), and
// the emitting of instructions, temporaries, constants and fault sites.
#include <algorithm>
#include <cstring>

#include <fmt/format.h>

#include "runtime/st/vm/block_signatures.hpp"
#include "runtime/st/vm/codegen_context.hpp"
#include "runtime/st/vm/st_string.hpp"
#include "runtime/st/vm/vm.hpp"

namespace syncplc::st::vm {

Num num_of(Elem e) {
  switch (e) {
    case Elem::BOOL: return Num::U8;
    case Elem::SINT: return Num::I8;
    case Elem::INT: return Num::I16;
    case Elem::DINT: return Num::I32;
    case Elem::USINT: case Elem::BYTE: return Num::U8;
    case Elem::UINT: case Elem::WORD: return Num::U16;
    case Elem::UDINT: case Elem::DWORD: return Num::U32;
    case Elem::ULINT: case Elem::LWORD: return Num::U64;
    case Elem::REAL: return Num::F32;
    case Elem::LREAL: return Num::F64;
    default: return Num::I64;  // LINT, TIME, LTIME, DATE, TOD, DT
  }
}

std::optional<Num> num_of(const Type* t) {
  if (t->kind == Type::Kind::Elementary || t->kind == Type::Kind::Subrange || t->kind == Type::Kind::Enum)
    return num_of(t->elem);
  return std::nullopt;
}

IecType iec_of(Elem e) { return runtime_type(e); }

Cell num_cell(Num n, const ConstValue& c) {
  Cell cell;
  switch (n) {
    case Num::F32: cell.set<float>(static_cast<float>(c.as_double())); break;
    case Num::F64: cell.set<double>(c.as_double()); break;
    case Num::I8: cell.set<std::int8_t>(static_cast<std::int8_t>(c.i)); break;
    case Num::I16: cell.set<std::int16_t>(static_cast<std::int16_t>(c.i)); break;
    case Num::I32: cell.set<std::int32_t>(static_cast<std::int32_t>(c.i)); break;
    case Num::I64: cell.set<std::int64_t>(static_cast<std::int64_t>(c.i)); break;
    case Num::U8: cell.set<std::uint8_t>(static_cast<std::uint8_t>(c.i)); break;
    case Num::U16: cell.set<std::uint16_t>(static_cast<std::uint16_t>(c.i)); break;
    case Num::U32: cell.set<std::uint32_t>(static_cast<std::uint32_t>(c.i)); break;
    case Num::U64: cell.set<std::uint64_t>(static_cast<std::uint64_t>(c.i)); break;
  }
  return cell;
}

CodeGen::CodeGen(const CheckedProgram& program, const BlockRegistry* blocks, StDiagnostics& diags)
    : program_(program), blocks_(blocks), diags_(diags), out_(std::make_unique<Module>()) {}

std::unique_ptr<Module> CodeGen::run() {
  const std::size_t n = program_.pous.size();
  out_->pous.resize(n);
  out_->block_slots.resize(n);
  out_->nested.resize(n);
  pous_.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    pous_[i].info = program_.pous[i].get();
    pou_of_[pous_[i].info] = static_cast<std::uint32_t>(i);
    out_->pous[i].name = pous_[i].info->name;
    out_->pous[i].kind = pous_[i].info->kind;
  }
  for (std::size_t i = 0; i < n; ++i) compile_pou(static_cast<std::uint32_t>(i));
  // Every FUNCTION's static frame, one after the other (no recursion: a
  // function is never active twice at once, docs/st.md).
  for (CompiledPou& p : out_->pous)
    if (p.kind == PouKind::Function) {
      p.fn_frame = out_->function_area;
      out_->function_area += p.frame_cells;
    }
  if (diags_.has_errors()) return nullptr;
  finalize(*out_);
  return std::move(out_);
}

std::uint32_t CodeGen::pou_index(const PouInfo* info) { return pou_of_.at(info); }

std::uint32_t CodeGen::fb_pou(const Type* fb_type) {
  for (std::size_t i = 0; i < pous_.size(); ++i)
    if (pous_[i].info->fb == fb_type->fb) return static_cast<std::uint32_t>(i);
  return ~0u;
}

const BlockTypeInfo* CodeGen::builtin(const Type* fb_type, IecType* datatype) {
  if (!fb_type->fb->builtin || !blocks_) return nullptr;
  IecType type = IecType::LREAL;
  const BlockTypeInfo* b = builtin_block(*blocks_, fb_type->fb->name, &type);
  if (datatype) *datatype = type;
  return b;
}

std::uint32_t CodeGen::builtin_pin_at(const Type* fb_type, std::string_view pin) {
  const BuiltinLayout l = builtin_layout(*fb_type->fb);
  for (std::size_t k = 0; k < fb_type->fb->pins.size(); ++k)
    if (same_name(fb_type->fb->pins[k].name, pin)) return l.pin_at[k];
  return 0;
}

std::uint32_t CodeGen::cells_of(const Type* t) {
  switch (t->kind) {
    case Type::Kind::String: return static_cast<std::uint32_t>(string_cells(t->length, t->wide));
    case Type::Kind::Array: return static_cast<std::uint32_t>(t->element_count()) * cells_of(t->element);
    case Type::Kind::Struct: {
      std::uint32_t n = 0;
      for (const Field& f : t->fields) n += cells_of(f.type);
      return n;
    }
    case Type::Kind::FunctionBlock: {
      if (t->fb->builtin) return builtin(t) ? builtin_layout(*t->fb).cells : 1;
      const std::uint32_t p = fb_pou(t);
      if (p == ~0u) return 1;
      compile_pou(p);
      return std::max<std::uint32_t>(out_->pous[p].frame_cells, 1);
    }
    default: return 1;
  }
}

// The initial image of a value of type t at cell `off` of POU `pou`'s image:
// the type's default, then the TYPE's own initial value (named `spelt`).
void CodeGen::default_image(const Type* t, Cell* at, const std::string& spelt, std::uint32_t pou) {
  switch (t->kind) {
    case Type::Kind::Enum:
      if (!t->values.empty()) *at = num_cell(num_of(t->elem), ConstValue{false, t->values.front().value, 0});
      break;
    case Type::Kind::Subrange: *at = num_cell(num_of(t->elem), ConstValue{false, t->low, 0}); break;
    case Type::Kind::Array: {
      const std::uint32_t n = cells_of(t->element);
      const std::int64_t count = t->element_count();
      default_image(t->element, at, "", pou);
      for (std::int64_t k = 1; k < count; ++k) std::memcpy(at + k * n, at, n * sizeof(Cell));
      // Nested blocks and FB instances of the elements after the first.
      if (t->element->kind == Type::Kind::FunctionBlock || t->element->kind == Type::Kind::Struct ||
          t->element->kind == Type::Kind::Array) {
        const Cell* base = out_->pous[pou].image.data();
        const std::uint32_t first = static_cast<std::uint32_t>(at - base);
        auto& slots = out_->block_slots[pou];
        auto& nested = out_->nested[pou];
        const std::size_t slots_before = slots.size(), nested_before = nested.size();
        // Entries made by the first element (at >= first and < first + n).
        std::vector<BlockSlot> s0;
        std::vector<std::pair<std::uint32_t, std::uint32_t>> n0;
        for (std::size_t i = 0; i < slots_before; ++i)
          if (slots[i].at >= first && slots[i].at < first + n) s0.push_back(slots[i]);
        for (std::size_t i = 0; i < nested_before; ++i)
          if (nested[i].first >= first && nested[i].first < first + n) n0.push_back(nested[i]);
        for (std::int64_t k = 1; k < count; ++k) {
          for (BlockSlot s : s0) {
            s.at += static_cast<std::uint32_t>(k * n);
            slots.push_back(s);
          }
          for (auto e : n0) {
            e.first += static_cast<std::uint32_t>(k * n);
            nested.push_back(e);
          }
        }
      }
      break;
    }
    case Type::Kind::Struct: {
      std::uint32_t off = 0;
      for (const Field& f : t->fields) {
        default_image(f.type, at + off, f.spec && f.spec->kind == TypeKind::Named ? f.spec->name : "", pou);
        if (f.init && f.init->kind != InitKind::None) apply_init(*f.init, f.type, at + off);
        off += cells_of(f.type);
      }
      break;
    }
    case Type::Kind::FunctionBlock: {
      const std::uint32_t off = static_cast<std::uint32_t>(at - out_->pous[pou].image.data());
      if (t->fb->builtin) {
        IecType datatype = IecType::LREAL;
        const BlockTypeInfo* b = builtin(t, &datatype);
        // Its links (VAR_IN_OUT AXIS_REF) follow the registry's pins.
        if (!b || b->pins.size() + b->links.size() != t->fb->pins.size() || b->params.size() != t->fb->params.size())
          break;
        BuiltinLayout l = builtin_layout(*t->fb);
        for (std::size_t k = 0; k < b->pins.size(); ++k) {
          const PinDecl& pin = b->pins[k];
          std::optional<Cell> c;
          if (!pin.tunes.empty()) {
            // A tuning input starts at its parameter's value, so the block
            // keeps the parameter until the program writes the input.
            const auto q = static_cast<std::size_t>(b->param_index(pin.tunes));  // the registry made the pin from it
            if (const auto& v = t->fb->params[q].value) c = param_cell(b->params[q].type, *v);
          } else if (!pin.init.empty()) {
            std::string why;
            c = parse_value(pin.cls == TypeClass::Exact ? pin.type : datatype, pin.init, &why);
          }
          if (!c) continue;
          const std::uint32_t end = k + 1 < l.pin_at.size() ? l.pin_at[k + 1] : l.cells;
          for (std::uint32_t i = l.pin_at[k]; i < end; ++i) at[i] = *c;  // an array pin: every element
        }
        out_->block_slots[pou].push_back({b, off, t->fb, std::move(l.pin_at), datatype});
        break;
      }
      const std::uint32_t p = fb_pou(t);
      if (p == ~0u) break;
      compile_pou(p);
      const CompiledPou& fb = out_->pous[p];
      // An FB of no variables has no image (memcpy from null is undefined, even of 0 bytes).
      if (fb.frame_cells) std::memcpy(at, fb.image.data(), fb.frame_cells * sizeof(Cell));
      out_->nested[pou].push_back({off, p});
      break;
    }
    default: break;  // zero: numbers, BOOL, durations, an empty string
  }
  if (!spelt.empty())
    if (auto it = program_.type_inits.find(name_key(spelt)); it != program_.type_inits.end())
      apply_init(*it->second, t, at);
}

// A declared initial value over the default image at `at`.
void CodeGen::apply_init(const Initializer& init, const Type* t, Cell* at) {
  switch (init.kind) {
    case InitKind::None: return;
    case InitKind::Expr: const_cells(init.expr, t, at); return;
    case InitKind::Struct:
      if (t->kind == Type::Kind::Struct) {
        std::uint32_t off = 0;
        for (const Field& f : t->fields) {
          for (const FieldInit& fi : init.fields)
            if (same_name(fi.name, f.name)) apply_init(fi.value, f.type, at + off);
          off += cells_of(f.type);
        }
      } else if (t->kind == Type::Kind::FunctionBlock && t->fb->builtin) {
        // Its inputs' initial values (its parameters made its type).
        for (const FieldInit& fi : init.fields)
          if (const Pin* pin = t->fb->find(fi.name)) apply_init(fi.value, pin->type, at + builtin_pin_at(t, pin->name));
      } else if (t->kind == Type::Kind::FunctionBlock && !t->fb->builtin) {
        const std::uint32_t p = fb_pou(t);
        if (p == ~0u) return;
        for (const FieldInit& fi : init.fields)
          for (const VarSlot& v : out_->pous[p].vars)
            if (same_name(v.name, fi.name)) apply_init(fi.value, v.type, at + v.at);
      }
      return;
    case InitKind::Array: {
      if (t->kind != Type::Kind::Array) return;
      const std::uint32_t n = cells_of(t->element);
      std::int64_t k = 0;
      const std::int64_t count = t->element_count();
      for (const ArrayInitElement& el : init.elements) {
        std::int64_t times = 1;
        if (el.repeat.kind != ExprKind::None)
          if (const ExprInfo* i = program_.info(el.repeat); i && i->constant) times = static_cast<std::int64_t>(i->constant->i);
        for (std::int64_t r = 0; r < times && k < count; ++r, ++k) {
          if (el.value.kind == InitKind::None) continue;  // 3(): default values
          apply_init(el.value, t->element, at + k * n);
        }
      }
      return;
    }
  }
}

// The cells of a constant expression of type t (folded by the checker, or a
// string literal).
void CodeGen::const_cells(const Expr& e, const Type* t, Cell* at) {
  if (t->kind == Type::Kind::String) {
    if (e.kind != ExprKind::Literal) {
      error(e.loc, "a string's initial value must be a literal");
      return;
    }
    const std::string& text = e.literal.text;
    if (t->wide) wstr_set_utf8(at, t->length, text.data(), text.size());
    else str_set(at, t->length, text.data(), text.size());
    return;
  }
  const ExprInfo* i = program_.info(e);
  const auto n = num_of(t);
  if (!i || !i->constant || !n) {
    error(e.loc, "an initial value must be a constant expression");
    return;
  }
  *at = num_cell(*n, *i->constant);
}

// Variables in declaration order, VAR_TEMP last (one block the call resets);
// VAR_IN_OUT and VAR_EXTERNAL are one reference cell each.
void CodeGen::lay_out(std::uint32_t p) {
  PouState& st = pous_[p];
  if (st.stage != PouState::Stage::None) return;
  const PouInfo& info = *st.info;
  CompiledPou& out = out_->pous[p];
  // Embedded FB types first: their frames' sizes are needed here.
  for (const auto& v : info.variables)
    if (v->scope != VarScope::InOut && v->scope != VarScope::External) cells_of(v->type);
  std::uint32_t at = 0;
  auto place_var = [&](const Variable& v) {
    const bool ref = v.scope == VarScope::InOut || v.scope == VarScope::External;
    const std::uint32_t n = ref ? 1 : cells_of(v.type);
    st.at[&v] = at;
    out.vars.push_back({v.name, static_cast<int>(v.scope), v.type, at, n, v.retain, v.persistent, v.constant});
    at += n;
  };
  for (const auto& v : info.variables)
    if (v->scope != VarScope::Temp) place_var(*v);
  out.temp_begin = at;
  for (const auto& v : info.variables)
    if (v->scope == VarScope::Temp) place_var(*v);
  out.temp_cells = info.kind == PouKind::Function ? 0 : at - out.temp_begin;
  out.frame_cells = at;
  out.image.assign(at, Cell{});
  st.stage = PouState::Stage::LaidOut;
  for (const auto& v : info.variables) {
    if (v->scope == VarScope::InOut || v->scope == VarScope::External) continue;
    Cell* cell = out.image.data() + st.at[v.get()];
    default_image(v->type, cell, v->spec && v->spec->kind == TypeKind::Named ? v->spec->name : "", p);
    if (v->init && v->init->kind != InitKind::None) apply_init(*v->init, v->type, cell);
  }
}

std::uint32_t CodeGen::var_cell(const Variable* v) {
  auto& at = pous_[pou_].at;
  auto it = at.find(v);
  return it == at.end() ? 0 : it->second;
}

void CodeGen::compile_pou(std::uint32_t p) {
  PouState& st = pous_[p];
  if (st.stage == PouState::Stage::Done) return;
  if (st.stage == PouState::Stage::LaidOut) return;  // being compiled (the checker refuses recursion)
  lay_out(p);
  // This POU's state, the caller's saved (a frame's layout may compile an
  // embedded FB's POU in the middle of another's).
  const auto saved_pou = pou_;
  const auto* saved_info = info_;
  const auto saved_vars_end = vars_end_, saved_top = temp_top_, saved_high = temp_high_;
  auto saved_constants = std::move(constants_);
  auto saved_constant_at = std::move(constant_at_);
  auto saved_loops = std::move(loops_);
  auto saved_calls = std::move(my_calls_), saved_strings = std::move(my_strings_);
  pou_ = p;
  info_ = st.info;
  vars_end_ = temp_top_ = temp_high_ = out_->pous[p].frame_cells;
  constants_.clear();
  constant_at_.clear();
  loops_.clear();
  my_calls_.clear();
  my_strings_.clear();

  body(info_->pou->body);
  emit(Op::HALT);
  place_constants();
  st.stage = PouState::Stage::Done;

  pou_ = saved_pou;
  info_ = saved_info;
  vars_end_ = saved_vars_end;
  temp_top_ = saved_top;
  temp_high_ = saved_high;
  constants_ = std::move(saved_constants);
  constant_at_ = std::move(saved_constant_at);
  loops_ = std::move(saved_loops);
  my_calls_ = std::move(saved_calls);
  my_strings_ = std::move(saved_strings);
}

// Constants go after the most temporaries in use at once; their tagged
// operands get their final cells.
void CodeGen::place_constants() {
  CompiledPou& out = out_->pous[pou_];
  const std::uint32_t base = temp_high_;
  auto fix = [&](std::uint32_t& x) {
    if (x & kConstTag) x = base + (x & ~kConstTag);
  };
  for (Insn& i : out.code) {
    fix(i.a);
    fix(i.b);
    fix(i.c);
    if (d_is_cell(i.op)) fix(i.d);
  }
  for (std::uint32_t k : my_calls_)
    for (CellCopy& c : out_->calls[k].in) fix(c.from);
  for (std::uint32_t k : my_strings_) {
    StringCall& s = out_->strings[k];
    fix(s.dst);
    for (auto& a : s.args) fix(a);
  }
  out.frame_cells = base + static_cast<std::uint32_t>(constants_.size());
  out.image.resize(out.frame_cells);
  std::copy(constants_.begin(), constants_.end(), out.image.begin() + base);
}

std::uint32_t CodeGen::emit(Op op, std::uint32_t a, std::uint32_t b, std::uint32_t c, std::uint32_t d,
                            std::uint32_t site) {
  Insn i;
  i.op = op;
  i.a = a;
  i.b = b;
  i.c = c;
  i.d = d;
  i.site = site;
  code().push_back(i);
  return pc() - 1;
}

std::uint32_t CodeGen::temp(std::uint32_t cells) {
  const std::uint32_t at = temp_top_;
  temp_top_ += cells;
  temp_high_ = std::max(temp_high_, temp_top_);
  return at;
}

std::uint32_t CodeGen::constant(const Cell* cells, std::uint32_t n) {
  std::vector<std::uint64_t> key(n);
  for (std::uint32_t k = 0; k < n; ++k) key[k] = cells[k].raw;
  if (auto it = constant_at_.find(key); it != constant_at_.end()) return it->second;
  const std::uint32_t at = kConstTag | static_cast<std::uint32_t>(constants_.size());
  constants_.insert(constants_.end(), cells, cells + n);
  constant_at_[key] = at;
  return at;
}

std::uint32_t CodeGen::site(const SourceLoc& loc, const std::string& what) {
  const std::string text = fmt::format("{} at {}:{}:{}", what, loc.file.str(), loc.line, loc.col);
  if (auto it = sites_.find(text); it != sites_.end()) return it->second;
  const auto k = static_cast<std::uint32_t>(out_->sites.size());
  out_->sites.push_back({fault_text(text)});
  sites_[text] = k;
  return k;
}

void CodeGen::error(const SourceLoc& loc, std::string message) { diags_.error(loc, std::move(message)); }

std::unique_ptr<Module> compile(const CheckedProgram& program, const BlockRegistry* blocks,
                                StDiagnostics& diagnostics) {
  CodeGen g(program, blocks, diagnostics);
  return g.run();
}

}  // namespace syncplc::st::vm
