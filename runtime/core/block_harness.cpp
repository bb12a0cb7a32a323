#include "runtime/core/block_harness.hpp"

#include <stdexcept>

namespace syncplc {
namespace {

class HarnessSetup final : public BlockSetup {
 public:
  HarnessSetup(const BlockTypeInfo& t, std::string name, IecType dt, std::vector<Cell> params,
               std::vector<bool> connected, std::int64_t period, std::uint64_t seed, std::vector<std::string>& errors)
      : t_(t), name_(std::move(name)), dt_(dt), params_(std::move(params)), connected_(std::move(connected)),
        period_(period), seed_(seed), errors_(errors) {}
  const std::string& instance_name() const override { return name_; }
  const BlockTypeInfo& type() const override { return t_; }
  IecType datatype() const override { return dt_; }
  Cell param_cell(int index) const override {
    if (index < 0 || static_cast<std::size_t>(index) >= params_.size())
      throw std::out_of_range("no such parameter in " + t_.name);
    return params_[static_cast<std::size_t>(index)];
  }
  bool connected(int pin) const override { return connected_.at(static_cast<std::size_t>(pin)); }
  std::int64_t task_period_ns() const override { return period_; }
  std::uint64_t seed() const override { return seed_; }
  void error(const std::string& message) override { errors_.push_back(message); }

 private:
  const BlockTypeInfo& t_;
  std::string name_;
  IecType dt_;
  std::vector<Cell> params_;
  std::vector<bool> connected_;
  std::int64_t period_;
  std::uint64_t seed_;
  std::vector<std::string>& errors_;
};

}  // namespace

BlockHarness::BlockHarness(const BlockRegistry& registry, const std::string& type_name, Options o)
    : period_(o.period_ns) {
  type_ = registry.find(type_name);
  if (!type_) {
    errors_.push_back("unknown block type " + type_name);
    return;
  }
  IecType dt = o.datatype.value_or(type_->default_datatype.value_or(IecType::LREAL));
  std::vector<Cell> params;
  for (const auto& p : type_->params) {
    std::string text = p.default_value;
    if (auto it = o.params.find(p.name); it != o.params.end()) text = it->second;
    std::string err;
    auto v = parse_value(p.type, text, &err);
    if (!v) {
      errors_.push_back("parameter " + p.name + ": " + err);
      params.emplace_back();
    } else {
      params.push_back(*v);
    }
  }
  for (const auto& [k, _] : o.params)
    if (type_->param_index(k) < 0) errors_.push_back("unknown parameter " + k);
  std::vector<bool> connected;
  cells_.resize(type_->pins.size());
  for (std::size_t i = 0; i < type_->pins.size(); ++i) {
    const auto& p = type_->pins[i];
    connected.push_back(p.dir == PinDir::In && (!o.connected || o.connected->count(p.name) > 0));
    IecType pt = p.cls == TypeClass::Exact ? p.type : dt;
    if (!p.init.empty()) {
      std::string err;
      if (auto v = parse_value(pt, p.init, &err)) cells_[i] = *v;
    }
  }
  for (auto& c : cells_) pin_ptrs_.push_back(&c);
  if (!errors_.empty()) return;
  HarnessSetup setup(*type_, "harness", dt, params, connected, period_, o.seed, errors_);
  block_ = type_->create(setup);
  if (!errors_.empty()) {
    block_.reset();
    return;
  }
  if (block_) block_->bind_pins(pin_ptrs_.data());
}

Cell& BlockHarness::cell(const std::string& pin) {
  int i = type_ ? type_->pin_index(pin) : -1;
  if (i < 0) throw std::out_of_range("no pin " + pin);
  return cells_[static_cast<std::size_t>(i)];
}

void BlockHarness::scan() {
  ScanContext ctx;
  ctx.now_ns = now_;
  ctx.dt_ns = scan_ == 0 ? period_ : now_ - prev_;
  ctx.scan = scan_;
  ctx.virtual_time = true;
  ctx.block = 0;
  ctx.events = this;
  block_->execute(ctx);
  block_->end_of_scan();
  last_consumed_ = ctx.consumed_ns;
  prev_ = now_;
  now_ += period_;
  ++scan_;
}

}  // namespace syncplc
