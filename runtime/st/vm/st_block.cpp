// ST POUs as blocks (st_block.hpp): the block type and the Block that runs an
// Instance in the scan.
#include "runtime/st/vm/st_block.hpp"

#include "runtime/st/vm/var_path.hpp"

#include <algorithm>
#include <cstring>

#include <fmt/format.h>

namespace syncplc::st::vm {

namespace {

// The per-scan budget of backward jumps (docs/st.md, "Loops"): one per 10 ns
// of the task's watchdog time, or of its period when it has no watchdog: a
// runaway loop ends in about the time the scan may take, on every run alike
// (virtual or real time), and its fault names the loop.
constexpr std::int64_t kNsPerBackwardJump = 10;

struct PinCell {
  int pin = 0;
  std::uint32_t cell = 0;
};

// A written VAR_EXTERNAL: its read pin copied to its write pin after the scan.
struct Written {
  int from = 0, to = 0;
  std::uint32_t count = 1;
};

class StBlock final : public Block {
 public:
  StBlock(std::shared_ptr<const StUnit> unit, std::uint32_t pou, BlockSetup& setup, std::vector<PinCell> inputs,
          std::vector<PinCell> outputs, std::vector<Written> written, std::int64_t budget, int frame_pin)
      : unit_(std::move(unit)),
        instance_(unit_->module, pou,
                  InstanceSetup{setup.instance_name(), setup.task_period_ns(), setup.seed()}),
        inputs_(std::move(inputs)),
        outputs_(std::move(outputs)),
        written_(std::move(written)),
        budget_(budget),
        frame_pin_(frame_pin) {
    const BlockTypeInfo& t = setup.type();
    // Each VAR_EXTERNAL reference cell of the instance (nested ones too) to its read pin.
    for (const auto& [cell, name] : instance_.externals()) {
      const int pin = t.pin_index(name + kExternalReadSuffix);
      if (pin >= 0) externals_.push_back({pin, cell});
      // An AXIS_REF (VAR_EXTERNAL X : AXIS_REF) refers to the cell holding its link's number.
      if (const int l = t.link_index(name); l >= 0) refs_.push_back({l, cell});
    }
    ref_values_.assign(t.links.size(), Cell{});
    instance_.set_target_count(static_cast<std::uint32_t>(t.links.size()));
  }

  // VAR_EXTERNAL X : AXIS_REF reaches the instance the loader linked as X.
  void link(int link, std::uint32_t element, Block& target) noexcept override {
    (void)element;
    instance_.set_target(static_cast<std::uint32_t>(link), &target);
  }

  void execute(ScanContext& ctx) noexcept override {
    Cell* frame = instance_.frame();
    // The references follow the pins (bound again when an online change moves the block).
    for (const PinCell& e : externals_) frame[e.cell].raw = reinterpret_cast<std::uintptr_t>(pin_cell(e.pin));
    // Each AXIS_REF's number, set again (the POU may have assigned to it).
    for (std::size_t k = 0; k < ref_values_.size(); ++k) ref_values_[k].raw = k + 1;
    for (const PinCell& r : refs_)
      frame[r.cell].raw = reinterpret_cast<std::uintptr_t>(&ref_values_[static_cast<std::size_t>(r.pin)]);
    for (const PinCell& in : inputs_) frame[in.cell] = *pin_cell(in.pin);
    if (!instance_.scan(ctx, budget_)) ctx.fault(instance_.stopped());
    for (const PinCell& out : outputs_) *pin_cell(out.pin) = frame[out.cell];
    for (const Written& w : written_) std::memcpy(pin_cell(w.to), pin_cell(w.from), w.count * sizeof(Cell));
  }

  void set_retained(std::vector<std::pair<std::uint32_t, std::uint32_t>> cells, std::uint32_t layout) {
    retained_ = std::move(cells);
    retain_layout_ = layout;
    retain_cells_ = 0;
    for (const auto& [at, n] : retained_) retain_cells_ += n;
  }
  // RETAIN variables (docs/store.md, "Retained block instances"): their cells, in declaration order.
  std::uint32_t retain_cells() const noexcept override { return retain_cells_; }
  std::uint32_t retain_layout() const noexcept override { return retain_layout_; }
  void save_retain(Cell* out) const noexcept override {
    const Cell* frame = instance_.frame();
    for (const auto& [at, n] : retained_) {
      std::memcpy(out, frame + at, n * sizeof(Cell));
      out += n;
    }
  }
  void load_retain(const Cell* in) noexcept override {
    Cell* frame = instance_.frame();
    for (const auto& [at, n] : retained_) {
      std::memcpy(frame + at, in, n * sizeof(Cell));
      in += n;
    }
  }

 private:
  std::shared_ptr<const StUnit> unit_;  // the module, its checked program and sources live as long as the block
  Instance instance_;
  std::vector<PinCell> inputs_, outputs_, externals_;
  std::vector<PinCell> refs_;     // (link, reference cell) of each AXIS_REF VAR_EXTERNAL
  std::vector<Cell> ref_values_;  // link k's AXIS_REF value: k + 1

  // The frame lives in its pin: published, monitored and forced like pins.
  // Bound at the load, it moves there with its initial values; bound again
  // (an online change moved the pin's cells, and what they hold), it takes
  // what is there.
  void pins_bound() noexcept override {
    instance_.relocate(pin_cell(frame_pin_), !placed_);
    placed_ = true;
  }

  std::vector<Written> written_;  // read pin -> write pin of each written VAR_EXTERNAL
  std::int64_t budget_;
  int frame_pin_;
  bool placed_ = false;
  std::vector<std::pair<std::uint32_t, std::uint32_t>> retained_;  // (cell, count) of the RETAIN variables
  std::uint32_t retain_cells_ = 0, retain_layout_ = 1;
};

// The variables of POU `pou` at `at` as leaves (BlockTypeInfo::VariableLeaf).
void leaves(const Module& m, std::uint32_t pou, std::uint32_t at, const std::string& prefix,
            std::vector<BlockTypeInfo::VariableLeaf>& out, int depth, bool retain, bool persistent);

void type_leaves(const Module& m, const Type* t, std::uint32_t at, const std::string& path,
                 std::vector<BlockTypeInfo::VariableLeaf>& out, int depth, bool retain, bool persistent) {
  if (depth > 32) return;
  switch (t->kind) {
    case Type::Kind::Struct: {
      std::uint32_t off = 0;
      for (const Field& f : t->fields) {
        type_leaves(m, f.type, at + off, path + "." + f.name, out, depth + 1, retain, persistent);
        off += frame_cells_of(m, f.type);
      }
      return;
    }
    case Type::Kind::Array: {
      const Type* e = t->element;
      if (e->kind != Type::Kind::Struct && e->kind != Type::Kind::FunctionBlock && e->kind != Type::Kind::Array) break;
      const std::uint32_t n = frame_cells_of(m, e);
      for (std::int64_t k = 0; k < t->element_count(); ++k)
        type_leaves(m, e, at + static_cast<std::uint32_t>(k) * n, fmt::format("{}[#{}]", path, k), out, depth + 1,
                    retain, persistent);
      return;
    }
    case Type::Kind::FunctionBlock:
      if (t->fb->builtin) {  // its pins; the Block* cell before them belongs to the instance
        const BuiltinLayout l = builtin_layout(*t->fb);
        for (std::size_t k = 0; k < t->fb->pins.size(); ++k) {
          const Pin& pin = t->fb->pins[k];
          if (pin.dir == PinDir::InOut) continue;  // a link: a reference, and the target last linked
          out.push_back({path + "." + pin.name, pin.type->name, at + l.pin_at[k], frame_cells_of(m, pin.type), retain,
                         persistent});
        }
      } else if (const int fp = m.find(t->fb->name); fp >= 0) {
        leaves(m, static_cast<std::uint32_t>(fp), at, path + ".", out, depth + 1, retain, persistent);
      }
      return;
    default: break;
  }
  out.push_back({path, t->name, at, frame_cells_of(m, t), retain, persistent});
}

void leaves(const Module& m, std::uint32_t pou, std::uint32_t at, const std::string& prefix,
            std::vector<BlockTypeInfo::VariableLeaf>& out, int depth, bool retain, bool persistent) {
  for (const VarSlot& v : m.pous[pou].vars) {
    if (v.scope == static_cast<int>(VarScope::External) || v.scope == static_cast<int>(VarScope::InOut) ||
        v.scope == static_cast<int>(VarScope::Temp))
      continue;  // references, and what each call sets again
    // A RETAIN instance of an FB retains all of it (IEC 61131-3 ed. 3, 6.5.6).
    type_leaves(m, v.type, at + v.at, prefix + v.name, out, depth, retain || v.retain, persistent || v.persistent);
  }
}

// A hash of what POU `pou` runs: its code, frame and image, and those of
// the POUs it embeds or calls (FNV-1a 64). Equal for an unchanged POU in a
// reloaded project: the online change keeps such an instance as it is.
std::uint64_t code_identity(const Module& m, std::uint32_t pou) {
  std::vector<std::uint32_t> pending{pou}, seen;  // POUs whose code is still to hash
  std::uint64_t h = 0xcbf29ce484222325ull;
  auto mix = [&](std::uint64_t v) {
    for (int k = 0; k < 8; ++k) h = (h ^ ((v >> (8 * k)) & 0xFF)) * 0x100000001b3ull;
  };
  auto mix_text = [&](std::string_view t) {
    for (unsigned char c : t) h = (h ^ c) * 0x100000001b3ull;
    mix(t.size());
  };
  while (!pending.empty()) {
    const std::uint32_t p = pending.back();
    pending.pop_back();
    if (std::find(seen.begin(), seen.end(), p) != seen.end()) continue;
    seen.push_back(p);
    const CompiledPou& c = m.pous[p];
    mix_text(c.name);
    mix(c.frame_cells);
    for (const Cell& x : c.image) mix(x.raw);
    for (const VarSlot& v : c.vars) {
      mix_text(v.name);
      mix_text(v.type->name);
      mix(v.at);
      mix(static_cast<std::uint64_t>(v.scope));
    }
    for (const Insn& i : c.code) {
      mix(static_cast<std::uint64_t>(i.op));
      mix(i.a);
      mix(i.b);
      mix(i.c);
      mix(i.d);
      mix_text(m.sites.empty() ? "" : m.sites[std::min<std::size_t>(i.site, m.sites.size() - 1)].message);
      if (i.op == Op::CALL_FB || i.op == Op::CALL_FB_REF) pending.push_back(i.d);
      if (i.op == Op::CALL_FN) pending.push_back(m.calls[i.d].pou);
    }
    for (const auto& [off, fb] : m.nested[p]) pending.push_back(fb);
  }
  return h;
}

bool pin_type(const Type* t, IecType* out) {
  const auto s = t->scalar();
  if (t->kind == Type::Kind::Enum) {
    *out = runtime_type(t->elem);
    return true;
  }
  if (!s) return false;
  *out = runtime_type(*s);
  return true;
}

// The variables to monitor (BlockTypeInfo::monitored): every elementary
// value below `path`, arrays element by element with their real indices.
struct MonitorWalk {
  const Module& m;
  BlockTypeInfo& t;

  bool full() const { return t.monitored.size() >= BlockTypeInfo::kMaxMonitored; }

  void add(const std::string& path, std::uint32_t at, IecType type) {
    if (full()) ++t.monitored_left_out;
    else t.monitored.push_back({path, at, type});
  }

  void pou_vars(std::uint32_t pou, std::uint32_t at, const std::string& prefix, int depth,
                const std::vector<PinDecl>* pins) {
    for (const VarSlot& v : m.pous[pou].vars) {
      if (v.scope == static_cast<int>(VarScope::External) || v.scope == static_cast<int>(VarScope::InOut) ||
          v.scope == static_cast<int>(VarScope::Temp))
        continue;  // references, and what each call sets again
      // The instance's own pins are shown as pins.
      if (pins && std::any_of(pins->begin(), pins->end(), [&](const PinDecl& d) { return same_name(d.name, v.name); }))
        continue;
      type(v.type, at + v.at, prefix + v.name, depth);
    }
  }

  void type(const Type* ty, std::uint32_t at, const std::string& path, int depth) {
    if (depth > 32) return;
    IecType iec;
    switch (ty->kind) {
      case Type::Kind::String: return;  // not a cell's value
      case Type::Kind::Struct: {
        std::uint32_t off = 0;
        for (const Field& f : ty->fields) {
          type(f.type, at + off, path + "." + f.name, depth + 1);
          off += frame_cells_of(m, f.type);
        }
        return;
      }
      case Type::Kind::Array: {
        const std::uint32_t stride = frame_cells_of(m, ty->element);
        const std::int64_t n = ty->element_count();
        for (std::int64_t k = 0; k < n; ++k) {
          if (full()) {  // the rest only counted
            t.monitored_left_out += static_cast<std::size_t>(n - k);
            return;
          }
          // Row-major, the last index fastest (as the code generator lays it out).
          std::string index;
          std::int64_t rest = k;
          std::vector<std::int64_t> idx(ty->dims.size());
          for (std::size_t d = ty->dims.size(); d-- > 0;) {
            idx[d] = ty->dims[d].low + rest % ty->dims[d].count();
            rest /= ty->dims[d].count();
          }
          for (std::size_t d = 0; d < idx.size(); ++d) index += (d ? ", " : "") + std::to_string(idx[d]);
          type(ty->element, at + static_cast<std::uint32_t>(k) * stride, path + "[" + index + "]", depth + 1);
        }
        return;
      }
      case Type::Kind::FunctionBlock:
        if (ty->fb->builtin) {
          const BuiltinLayout l = builtin_layout(*ty->fb);
          for (std::size_t k = 0; k < ty->fb->pins.size(); ++k)
            if (ty->fb->pins[k].dir != PinDir::InOut)  // a link: a reference
              type(ty->fb->pins[k].type, at + l.pin_at[k], path + "." + ty->fb->pins[k].name, depth + 1);
        } else if (const int fp = m.find(ty->fb->name); fp >= 0) {
          pou_vars(static_cast<std::uint32_t>(fp), at, path + ".", depth + 1, nullptr);
        }
        return;
      default:
        if (pin_type(ty, &iec)) add(path, at, iec);
        return;
    }
  }
};

void collect_externals(const StUnit& unit, std::uint32_t pou, std::vector<StExternal>& out, int depth) {
  const Module& m = *unit.module;
  const CompiledPou& p = m.pous[pou];
  const PouInfo* info = unit.checked.pou(p.name);
  for (const VarSlot& v : p.vars) {
    if (v.scope != static_cast<int>(VarScope::External)) continue;
    bool written = false;
    for (const std::string& w : p.externals_written) written = written || same_name(w, v.name);
    StExternal* e = nullptr;
    for (auto& x : out)
      if (same_name(x.name, v.name)) e = &x;
    if (!e) {
      const Variable* var = info ? info->find(v.name) : nullptr;
      out.push_back({v.name, v.type, false, var && var->constant, var ? var->loc : SourceLoc{}});
      e = &out.back();
    }
    e->written = e->written || written;
  }
  if (depth > 64) return;
  for (const auto& [off, fb] : m.nested[pou]) {
    bool seen = false;  // an FB type once is enough (every instance binds the same names)
    for (const auto& [o2, f2] : m.nested[pou])
      if (f2 == fb && o2 < off) seen = true;
    if (!seen) collect_externals(unit, fb, out, depth + 1);
  }
}

}  // namespace

std::vector<StExternal> st_externals(const StUnit& unit, std::uint32_t pou) {
  std::vector<StExternal> out;
  collect_externals(unit, pou, out, 0);
  return out;
}

std::optional<BlockTypeInfo> st_block_type(std::shared_ptr<const StUnit> unit, std::uint32_t pou, std::string* why) {
  const CompiledPou& p = unit->module->pous[pou];
  const PouInfo* info = unit->checked.pou(p.name);
  BlockTypeInfo t;
  t.name = p.name;
  t.category = p.kind == PouKind::Program ? "Structured Text programs" : "Structured Text function blocks";
  // The POU's comment as one paragraph (its line breaks and indents are the source's layout).
  for (char c : info && info->pou ? info->pou->doc : std::string()) {
    const bool space = c == ' ' || c == '\n' || c == '\t' || c == '\r';
    if (space && (t.doc.empty() || t.doc.back() == ' ')) continue;
    t.doc += space ? ' ' : c;
  }
  while (!t.doc.empty() && t.doc.back() == ' ') t.doc.pop_back();
  t.reference = info && info->pou ? info->pou->loc.text() : "";
  for (const VarSlot& v : p.vars)
    if (v.scope == static_cast<int>(VarScope::InOut) && t.not_instanceable.empty())
      t.not_instanceable =
          p.kind == PouKind::Program
              ? fmt::format("PROGRAM {} has VAR_IN_OUT {}: an instance the project makes has nothing to bind it "
                            "(reach a tag with VAR_EXTERNAL instead)",
                            p.name, v.name)
              : fmt::format("FUNCTION_BLOCK {} has VAR_IN_OUT {}: an instance the project makes has nothing to bind "
                            "it (call {} from a POU that passes {}, or make it a VAR_INPUT and a VAR_OUTPUT)",
                            p.name, v.name, p.name, v.name);
  std::vector<PinCell> inputs, outputs;
  if (p.kind == PouKind::FunctionBlock) {
    for (const VarSlot& v : p.vars) {
      const bool in = v.scope == static_cast<int>(VarScope::Input);
      const bool out = v.scope == static_cast<int>(VarScope::Output);
      IecType type;
      if ((!in && !out) || !pin_type(v.type, &type)) continue;  // others: reached as instance.var
      PinDecl d;
      d.name = v.name;
      d.dir = in ? syncplc::PinDir::In : syncplc::PinDir::Out;
      d.type = type;
      d.doc = fmt::format("{} {} : {}", in ? "VAR_INPUT" : "VAR_OUTPUT", v.name, v.type->name);
      // An unconnected input starts from the variable's initial value.
      d.init = format_value(type, p.image[v.at]);
      (in ? inputs : outputs).push_back({static_cast<int>(t.pins.size()), v.at});
      t.pins.push_back(std::move(d));
    }
  }
  std::vector<Written> written;
  for (const StExternal& e : st_externals(*unit, pou)) {
    // VAR_EXTERNAL X : AXIS_REF: a link to the MC_AXIS instance X of the
    // project (docs/st.md, "Motion control blocks"), ordered before this one.
    if (!e.type->ref_target.empty()) {
      t.links.push_back({e.name, e.type->ref_target,
                         fmt::format("VAR_EXTERNAL {} : {}: the {} instance {} ({})", e.name, e.type->name,
                                     e.type->ref_target, e.name, e.loc.text())});
      continue;
    }
    if (e.type->kind == Type::Kind::Array && !e.type->element->ref_target.empty()) {
      *why = fmt::format("{}: VAR_EXTERNAL {} : {}: an {} is declared one by one (VAR_EXTERNAL X : {}), an array "
                         "of them is a variable of the POU",
                         e.loc.text(), e.name, e.type->name, e.type->element->name, e.type->element->name);
      return std::nullopt;
    }
    // An elementary tag, or an array tag as ARRAY[lo..hi] OF an elementary type.
    const Type* element = e.type;
    std::uint32_t count = 1;
    if (e.type->kind == Type::Kind::Array && e.type->dims.size() == 1) {
      element = e.type->element;
      count = static_cast<std::uint32_t>(e.type->dims[0].count());
    }
    IecType type;
    if (!pin_type(element, &type) || count > kMaxPinLength) {
      *why = fmt::format("{}: VAR_EXTERNAL {} : {}: a tag is an elementary value or a one-dimensional array of one "
                         "(at most {} elements)",
                         e.loc.text(), e.name, e.type->name, kMaxPinLength);
      return std::nullopt;
    }
    std::string length_param;
    if (element != e.type) {
      ParamDecl len;
      len.name = "(length of " + e.name + ")";
      len.type = IecType::UDINT;
      len.default_value = std::to_string(count);
      len.min = len.max = static_cast<double>(count);
      len.doc = "elements of the array tag (set by the compiler)";
      length_param = len.name;
      t.params.push_back(std::move(len));
    }
    PinDecl r;
    r.name = e.name + kExternalReadSuffix;
    r.dir = syncplc::PinDir::In;
    r.type = type;
    r.length_param = length_param;
    r.doc = fmt::format("the tag {} as the scan starts (VAR_EXTERNAL)", e.name);
    const int read_pin = static_cast<int>(t.pins.size());
    t.pins.push_back(std::move(r));
    if (e.written) {
      PinDecl w;
      w.name = e.name;
      w.dir = syncplc::PinDir::Out;
      w.type = type;
      w.length_param = length_param;
      w.doc = fmt::format("the tag {} as the POU left it (VAR_EXTERNAL)", e.name);
      written.push_back({read_pin, static_cast<int>(t.pins.size()), count});
      t.pins.push_back(std::move(w));
    }
  }
  for (std::size_t i = 0; i < t.pins.size(); ++i)
    for (std::size_t j = i + 1; j < t.pins.size(); ++j)
      if (same_name(t.pins[i].name, t.pins[j].name)) {
        *why = fmt::format("{}: {} has two pins named {} (a VAR_EXTERNAL's pins are NAME and NAME{})",
                           t.reference, p.name, t.pins[i].name, kExternalReadSuffix);
        return std::nullopt;
      }
  // The frame as an array output pin sized by a parameter the compiler sets.
  if (p.frame_cells > kMaxFrameCells) {
    *why = fmt::format("{}: {} needs {} cells for its variables; an instance may have at most {}", t.reference, p.name,
                       p.frame_cells, kMaxFrameCells);
    return std::nullopt;
  }
  const std::uint32_t frame_cells = std::max<std::uint32_t>(p.frame_cells, 1);
  ParamDecl cells;
  cells.name = kVariablesParam;
  cells.type = IecType::UDINT;
  cells.default_value = std::to_string(frame_cells);
  cells.min = cells.max = static_cast<double>(frame_cells);
  cells.doc = "cells of the instance's variables (set by the compiler)";
  t.params.push_back(std::move(cells));
  PinDecl frame;
  frame.name = kVariablesPin;
  frame.dir = syncplc::PinDir::Out;
  frame.type = IecType::LWORD;
  frame.length_param = kVariablesParam;
  frame.max_length = kMaxFrameCells;
  frame.doc = "the instance's variables, reached as instance.name (docs/st.md)";
  const int frame_pin = static_cast<int>(t.pins.size());
  t.pins.push_back(std::move(frame));
  t.variables_pin = frame_pin;
  leaves(*unit->module, pou, 0, "", t.variable_leaves, 0, false, false);
  MonitorWalk{*unit->module, t}.pou_vars(pou, 0, "", 0, &t.pins);
  // RETAIN variables: the block's retained state, cell ranges of its frame.
  std::vector<std::pair<std::uint32_t, std::uint32_t>> retained;
  std::uint64_t layout = 0xcbf29ce484222325ull;
  for (const auto& leaf : t.variable_leaves)
    if (leaf.retain) {
      retained.emplace_back(leaf.element, leaf.count);
      for (unsigned char ch : leaf.path + ":" + leaf.type) layout = (layout ^ ch) * 0x100000001b3ull;
    }
  // What the instance runs, as a parameter: part of its signature's
  // structure, so a changed body re-creates it (and carries its variables).
  ParamDecl code;
  code.name = kCodeParam;
  code.type = IecType::LWORD;
  code.default_value = fmt::format("16#{:016X}", code_identity(*unit->module, pou));
  code.doc = "identity of the compiled code (set by the compiler)";
  t.params.push_back(std::move(code));
  t.variable = [unit, pou](std::string_view path, std::string* error) -> std::optional<BlockTypeInfo::Variable> {
    const auto r = resolve_path(*unit->module, pou, path, error);
    if (!r) return std::nullopt;
    if (r->reference) {
      *error = "a VAR_IN_OUT or VAR_EXTERNAL refers to another variable (name the tag itself)";
      return std::nullopt;
    }
    if (r->bit >= 0) {
      *error = "a bit of a variable cannot be addressed alone: address the whole variable";
      return std::nullopt;
    }
    IecType type;
    if (!pin_type(r->type, &type)) {
      *error = fmt::format("it is a {}: address one of its elements or fields", r->type->name);
      return std::nullopt;
    }
    BlockTypeInfo::Variable v{r->at, type};
    if (r->constant) v.read_only = "it is a VAR CONSTANT: the program uses its declared value";
    else if (r->temp) v.read_only = "it is a VAR_TEMP: the program sets it again at every call";
    if (r->type->kind == Type::Kind::Subrange) v.range = std::pair{r->type->low, r->type->high};
    return v;
  };
  const auto retain_layout = static_cast<std::uint32_t>(layout ^ (layout >> 32));
  t.create = [unit, pou, inputs, outputs, written, frame_pin, retained, retain_layout](BlockSetup& s) -> std::unique_ptr<Block> {
    // The budget from the task's watchdog, else its period.
    const std::int64_t time_ns = s.task_watchdog_ns() > 0 ? s.task_watchdog_ns() : s.task_period_ns();
    const std::int64_t budget = std::max<std::int64_t>(1000, time_ns / kNsPerBackwardJump);
    auto b = std::make_unique<StBlock>(unit, pou, s, inputs, outputs, written, budget, frame_pin);
    b->set_retained(retained, retain_layout);
    return b;
  };
  return t;
}

}  // namespace syncplc::st::vm
