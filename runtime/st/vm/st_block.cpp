// ST POUs as blocks (st_block.hpp): the block type and the Block that runs an
// Instance in the scan.
#include "runtime/st/vm/st_block.hpp"

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

class StBlock final : public Block {
 public:
  StBlock(std::shared_ptr<const StUnit> unit, std::uint32_t pou, BlockSetup& setup, std::vector<PinCell> inputs,
          std::vector<PinCell> outputs, std::vector<std::pair<int, int>> written, std::int64_t budget)
      : unit_(std::move(unit)),
        instance_(unit_->module, pou,
                  InstanceSetup{setup.instance_name(), setup.task_period_ns(), setup.seed()}),
        inputs_(std::move(inputs)),
        outputs_(std::move(outputs)),
        written_(std::move(written)),
        budget_(budget) {
    const BlockTypeInfo& t = setup.type();
    // Each VAR_EXTERNAL reference cell of the instance (nested ones too) to its read pin.
    for (const auto& [cell, name] : instance_.externals()) {
      const int pin = t.pin_index(name + kExternalReadSuffix);
      if (pin >= 0) externals_.push_back({pin, cell});
    }
  }

  void execute(ScanContext& ctx) noexcept override {
    Cell* frame = instance_.frame();
    // The references follow the pins (bound again when an online change moves the block).
    for (const PinCell& e : externals_) frame[e.cell].raw = reinterpret_cast<std::uintptr_t>(pin_cell(e.pin));
    for (const PinCell& in : inputs_) frame[in.cell] = *pin_cell(in.pin);
    if (!instance_.scan(ctx, budget_)) ctx.fault(instance_.stopped());
    for (const PinCell& out : outputs_) *pin_cell(out.pin) = frame[out.cell];
    for (const auto& [from, to] : written_) *pin_cell(to) = *pin_cell(from);
  }

 private:
  std::shared_ptr<const StUnit> unit_;  // the module, its checked program and sources live as long as the block
  Instance instance_;
  std::vector<PinCell> inputs_, outputs_, externals_;
  std::vector<std::pair<int, int>> written_;  // read pin -> write pin of each written VAR_EXTERNAL
  std::int64_t budget_;
};

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
  t.doc = info && info->pou ? info->pou->doc : "";
  t.reference = info && info->pou ? info->pou->loc.text() : "";
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
  std::vector<std::pair<int, int>> written;
  for (const StExternal& e : st_externals(*unit, pou)) {
    IecType type;
    if (!pin_type(e.type, &type)) {
      *why = fmt::format("{}: VAR_EXTERNAL {} : {}: a tag is an elementary value", e.loc.text(), e.name, e.type->name);
      return std::nullopt;
    }
    PinDecl r;
    r.name = e.name + kExternalReadSuffix;
    r.dir = syncplc::PinDir::In;
    r.type = type;
    r.doc = fmt::format("the tag {} as the scan starts (VAR_EXTERNAL)", e.name);
    const int read_pin = static_cast<int>(t.pins.size());
    t.pins.push_back(std::move(r));
    if (e.written) {
      PinDecl w;
      w.name = e.name;
      w.dir = syncplc::PinDir::Out;
      w.type = type;
      w.doc = fmt::format("the tag {} as the POU left it (VAR_EXTERNAL)", e.name);
      written.push_back({read_pin, static_cast<int>(t.pins.size())});
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
  t.create = [unit, pou, inputs, outputs, written](BlockSetup& s) -> std::unique_ptr<Block> {
    // The budget from the task's watchdog, else its period.
    const std::int64_t time_ns = s.task_watchdog_ns() > 0 ? s.task_watchdog_ns() : s.task_period_ns();
    const std::int64_t budget = std::max<std::int64_t>(1000, time_ns / kNsPerBackwardJump);
    return std::make_unique<StBlock>(unit, pou, s, inputs, outputs, written, budget);
  };
  return t;
}

}  // namespace syncplc::st::vm
