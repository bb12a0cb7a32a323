#include "runtime/core/block_harness.hpp"

#include <stdexcept>

#include "runtime/core/finite_guard.hpp"

namespace syncplc {
namespace {

class HarnessSetup final : public BlockSetup {
 public:
  HarnessSetup(const BlockTypeInfo& t, std::string name, IecType dt, std::vector<Cell> params,
               std::vector<bool> connected, std::vector<std::uint32_t> lengths, std::int64_t period,
               std::uint64_t seed, std::vector<std::string>& errors)
      : t_(t), name_(std::move(name)), dt_(dt), params_(std::move(params)), connected_(std::move(connected)),
        lengths_(std::move(lengths)), period_(period), seed_(seed), errors_(errors) {}
  const std::string& instance_name() const override { return name_; }
  const BlockTypeInfo& type() const override { return t_; }
  IecType datatype() const override { return dt_; }
  Cell param_cell(int index) const override {
    if (index < 0 || static_cast<std::size_t>(index) >= params_.size())
      throw std::out_of_range("no such parameter in " + t_.name);
    return params_[static_cast<std::size_t>(index)];
  }
  bool connected(int pin) const override { return connected_.at(static_cast<std::size_t>(pin)); }
  std::uint32_t pin_length(int pin) const override { return lengths_.at(static_cast<std::size_t>(pin)); }
  std::int64_t task_period_ns() const override { return period_; }
  std::uint64_t seed() const override { return seed_; }
  void error(const std::string& message) override { errors_.push_back(message); }
  void unknown_param(std::string_view name) const override {
    errors_.push_back("the factory reads parameter '" + std::string(name) + "', which " + t_.name + " does not declare");
  }

 private:
  const BlockTypeInfo& t_;
  std::string name_;
  IecType dt_;
  std::vector<Cell> params_;
  std::vector<bool> connected_;
  std::vector<std::uint32_t> lengths_;
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
  std::uint32_t total = 0;
  for (const auto& p : type_->pins) {
    std::uint32_t n = 1;
    if (p.is_array()) {
      auto k = static_cast<std::size_t>(type_->param_index(p.length_param));
      double len = cell_as_double(type_->params[k].type, params[k]);
      if (len < 1 || len > p.max_length) {
        errors_.push_back("array pin " + p.name + ": " + p.length_param + " must be 1.." + std::to_string(p.max_length));
        len = 1;
      }
      n = static_cast<std::uint32_t>(len);
    }
    first_.push_back(total);
    length_.push_back(n);
    total += n;
  }
  cells_.resize(total);
  for (std::size_t i = 0; i < type_->pins.size(); ++i) {
    const auto& p = type_->pins[i];
    // Tuning inputs count as connected only when named (else they would set
    // their parameter to 0 on the first scan).
    connected.push_back(p.dir == PinDir::In &&
                        (o.connected ? o.connected->count(p.name) > 0 : p.tunes.empty()));
    IecType pt = p.cls == TypeClass::Exact ? p.type : dt;
    if (!p.init.empty()) {
      std::string err;
      if (auto v = parse_value(pt, p.init, &err))
        for (std::uint32_t k = 0; k < length_[i]; ++k) cells_[first_[i] + k] = *v;
    }
  }
  for (std::size_t i = 0; i < type_->pins.size(); ++i) pin_ptrs_.push_back(&cells_[first_[i]]);
  if (!errors_.empty()) return;
  HarnessSetup setup(*type_, "harness", dt, params, connected, length_, period_, o.seed, errors_);
  block_ = type_->create(setup);
  if (!errors_.empty()) {
    block_.reset();
    return;
  }
  if (block_) block_->bind_pins(pin_ptrs_.data());
}

void BlockHarness::skip_scan() {
  prev_ = now_;
  now_ += period_;
  ++scan_;
}

Cell& BlockHarness::cell(const std::string& pin) { return cell(pin, 0); }

Cell& BlockHarness::cell(const std::string& pin, std::uint32_t i) {
  int p = type_ ? type_->pin_index(pin) : -1;
  if (p < 0) throw std::out_of_range("no pin " + pin);
  if (i >= length_[static_cast<std::size_t>(p)]) throw std::out_of_range("pin " + pin + " has no element " + std::to_string(i));
  return cells_[first_[static_cast<std::size_t>(p)] + i];
}

std::uint32_t BlockHarness::length(const std::string& pin) const {
  int p = type_ ? type_->pin_index(pin) : -1;
  if (p < 0) throw std::out_of_range("no pin " + pin);
  return length_[static_cast<std::size_t>(p)];
}

void BlockHarness::scan() {
  ScanContext ctx;
  ctx.now_ns = now_;
  ctx.dt_ns = scan_ == 0 ? period_ : now_ - prev_;
  ctx.scan = scan_;
  ctx.virtual_time = true;
  ctx.block = 0;
  ctx.events = this;
  execute_guarded(*block_, ctx);
  end_of_scan_guarded(*block_, ctx);
  last_consumed_ = ctx.consumed_ns;
  prev_ = now_;
  now_ += period_;
  ++scan_;
}

}  // namespace syncplc
