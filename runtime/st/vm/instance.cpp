// An instance's area and its embedded built-in blocks (instance.hpp).
#include "runtime/st/vm/instance.hpp"

#include <cstring>
#include <stdexcept>

#include <fmt/format.h>

#include "runtime/st/checker.hpp"
#include "runtime/st/vm/block_signatures.hpp"

namespace syncplc::st::vm {

namespace {

// What a built-in block's factory sees of an instance embedded in ST: every
// input is given by the ST code (connected), the parameters and the array
// pins' lengths are those of its FB type (its declaration's, checked).
class EmbeddedSetup final : public BlockSetup {
 public:
  EmbeddedSetup(std::string name, const BlockSlot& slot, const InstanceSetup& s)
      : name_(std::move(name)), type_(*slot.type), fb_(*slot.fb), datatype_(slot.datatype), setup_(s) {}
  const std::string& instance_name() const override { return name_; }
  const BlockTypeInfo& type() const override { return type_; }
  IecType datatype() const override { return datatype_; }
  Cell param_cell(int index) const override {
    const auto k = static_cast<std::size_t>(index);
    const auto& v = fb_.params[k].value;
    return v ? vm::param_cell(type_.params[k].type, *v) : Cell{};
  }
  bool connected(int pin) const override { return type_.pins[static_cast<std::size_t>(pin)].dir == syncplc::PinDir::In; }
  std::uint32_t pin_length(int pin) const override {
    const Type* t = fb_.pins[static_cast<std::size_t>(pin)].type;
    return t->kind == Type::Kind::Array ? static_cast<std::uint32_t>(t->element_count()) : 1;
  }
  std::int64_t task_period_ns() const override { return setup_.task_period_ns; }
  std::uint64_t seed() const override {
    std::uint64_t h = setup_.seed ^ 0x9E3779B97F4A7C15ull;  // the instance's name mixed in (FNV-1a)
    for (unsigned char ch : name_) h = (h ^ ch) * 0x100000001B3ull;
    return h;
  }
  void error(const std::string& message) override { errors_.push_back(message); }
  void unknown_param(std::string_view name) const override {
    const_cast<EmbeddedSetup*>(this)->errors_.push_back(fmt::format("unknown parameter '{}'", name));
  }
  const std::vector<std::string>& errors() const { return errors_; }

 private:
  std::string name_;
  const BlockTypeInfo& type_;
  const FbType& fb_;
  IecType datatype_;
  const InstanceSetup& setup_;
  std::vector<std::string> errors_;
};

}  // namespace

Instance::Instance(std::shared_ptr<const Module> module, std::uint32_t pou, const InstanceSetup& setup)
    : module_(std::move(module)), pou_(pou), compiled_(&module_->pous[pou]) {
  const CompiledPou& p = module_->pous[pou];
  const std::uint32_t frame = p.frame_cells;
  area_.assign(frame + module_->function_area + module_->scratch_cells, Cell{});
  if (frame) std::memcpy(area_.data(), p.image.data(), frame * sizeof(Cell));  // a POU of no variables has no image
  frame_ = area_.data();
  create_blocks(pou, 0, setup, setup.name);
  find_externals(pou, 0);
  vm_.module = module_.get();
  vm_.functions = area_.data() + frame;
  vm_.scratch = area_.data() + frame + module_->function_area;
}

void Instance::create_blocks(std::uint32_t pou, std::uint32_t at, const InstanceSetup& setup,
                             const std::string& path) {
  const CompiledPou& p = module_->pous[pou];
  for (const BlockSlot& s : module_->block_slots[pou]) {
    std::string member;
    for (const VarSlot& v : p.vars)
      if (s.at >= v.at && s.at < v.at + v.cells) member = v.name;
    const std::string name = path + "." + member;
    // The checker gave every parameter its value (the declaration's or the
    // default) or refused the program: this is a module out of step with it.
    for (const auto& q : s.fb->params)
      if (!q.value)
        throw std::runtime_error(fmt::format("{} ({}): parameter '{}' has no value", name, s.type->name, q.name));
    EmbeddedSetup b(name, s, setup);
    std::unique_ptr<Block> block = s.type->create(b);
    if (!b.errors().empty() || !block)
      throw std::runtime_error(fmt::format("{} ({}): {}", name, s.type->name,
                                           b.errors().empty() ? "not created" : b.errors().front()));
    auto pins = std::make_unique<Cell*[]>(s.pin_at.size());
    Cell* cells = area_.data() + at + s.at;
    for (std::size_t k = 0; k < s.pin_at.size(); ++k) pins[k] = cells + s.pin_at[k];
    block->bind_pins(pins.get());
    cells[0].raw = reinterpret_cast<std::uintptr_t>(block.get());
    block_at_.push_back(at + s.at);
    blocks_.push_back(std::move(block));
    pins_.push_back(std::move(pins));
    slots_.push_back(&s);
  }
  for (const auto& [off, fb] : module_->nested[pou]) {
    std::string member;
    for (const VarSlot& v : p.vars)
      if (off >= v.at && off < v.at + v.cells) member = v.name;
    create_blocks(fb, at + off, setup, path + "." + member);
  }
}

void Instance::find_externals(std::uint32_t pou, std::uint32_t at) {
  for (const VarSlot& v : module_->pous[pou].vars)
    if (v.scope == static_cast<int>(VarScope::External)) externals_.emplace_back(at + v.at, v.name);
  for (const auto& [off, fb] : module_->nested[pou]) find_externals(fb, at + off);
}

bool Instance::scan(ScanContext& ctx, std::int64_t loop_budget) noexcept {
  vm_.ctx = &ctx;
  vm_.budget = loop_budget;
  vm_.stopped = nullptr;
  return run(vm_, *compiled_, frame_);
}

void Instance::relocate(Cell* to, bool carry) noexcept {
  if (to == frame_) return;
  if (carry) std::memmove(to, frame_, frame_cells() * sizeof(Cell));
  frame_ = to;
  for (std::size_t k = 0; k < block_at_.size(); ++k) {
    Cell** pins = pins_[k].get();
    Cell* cells = frame_ + block_at_[k];
    const std::vector<std::uint32_t>& pin_at = slots_[k]->pin_at;
    for (std::size_t i = 0; i < pin_at.size(); ++i) pins[i] = cells + pin_at[i];
  }
}

bool Instance::bind_external(std::string_view name, Cell* cell) noexcept {
  for (const VarSlot& v : module_->pous[pou_].vars)
    if (v.scope == static_cast<int>(VarScope::External) && same_name(v.name, name)) {
      frame_[v.at].raw = reinterpret_cast<std::uintptr_t>(cell);
      return true;
    }
  return false;
}

}  // namespace syncplc::st::vm
