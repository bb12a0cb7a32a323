#include "runtime/core/block.hpp"

#include <algorithm>
#include <limits>
#include <stdexcept>

#include "runtime/core/pin_decl.hpp"

namespace syncplc {

int BlockTypeInfo::pin_index(std::string_view pin) const {
  for (std::size_t i = 0; i < pins.size(); ++i)
    if (pins[i].name == pin) return static_cast<int>(i);
  return -1;
}

int BlockTypeInfo::param_index(std::string_view param) const {
  for (std::size_t i = 0; i < params.size(); ++i)
    if (params[i].name == param) return static_cast<int>(i);
  return -1;
}

int BlockTypeInfo::link_index(std::string_view link) const {
  for (std::size_t i = 0; i < links.size(); ++i)
    if (links[i].name == link) return static_cast<int>(i);
  return -1;
}

bool BlockTypeInfo::is_generic() const {
  return std::any_of(pins.begin(), pins.end(), [](const PinDecl& p) { return p.cls != TypeClass::Exact; });
}

std::string_view event_kind_name(EventKind k) {
  switch (k) {
    case EventKind::WatchdogTrip: return "watchdog";
    case EventKind::TaskStopped: return "task-stopped";
    case EventKind::SafeStateApplied: return "safe-state";
    case EventKind::BlockFault: return "block-fault";
    case EventKind::ScanOverrun: return "overrun";
    case EventKind::QueueOverflow: return "queue-overflow";
    case EventKind::DriverFault: return "driver-fault";
    case EventKind::Info: return "info";
    case EventKind::ScanHung: return "scan-hung";
    case EventKind::ScanLate: return "overrun";
  }
  return "?";
}

namespace {

// The pins every type gets: a tuning input per tunable parameter, then ENO.
void add_implicit_pins(BlockTypeInfo& info) {
  for (const auto& p : info.pins)
    if (p.name == kEnoPin || !p.tunes.empty())
      throw std::logic_error("block type " + info.name + " declares " + p.name + ", which the registry adds");
  for (const auto& prm : info.params) {
    if (!prm.tunable) continue;
    if (prm.type != IecType::LREAL && prm.type != IecType::REAL && !is_integer(prm.type))
      throw std::logic_error("block type " + info.name + ": tunable parameter " + prm.name + " must be a number");
    PinDecl t = input(prm.name + kTuningSuffix, prm.type)
                    .unit(prm.unit)
                    .doc("tuning input of " + prm.name + ": when connected, read every scan; a changed value within "
                         "the parameter's range takes effect bumplessly, an invalid one keeps the last valid value "
                         "and sets ENO FALSE. Unconnected: the parameter applies");
    t.tunes = prm.name;  // the registry's own field: no builder step, so no block type can set it
    info.pins.push_back(std::move(t));
  }
  info.pins.push_back(output(kEnoPin, IecType::BOOL)
                          .doc("FALSE while an input is NaN or infinite (the block then does not execute and its "
                               "outputs hold their last valid values) or a tuning input is invalid; TRUE otherwise"));
}

// What finite_guard.hpp checks for the instance `setup` describes.
BlockGuard make_guard(const BlockSetup& s) {
  const BlockTypeInfo& t = s.type();
  BlockGuard g;
  g.unit_delay = t.unit_delay;
  for (std::size_t i = 0; i < t.pins.size(); ++i) {
    const PinDecl& p = t.pins[i];
    const int pin = static_cast<int>(i);
    if (p.name == kEnoPin) g.eno = pin;
    if (p.dir != PinDir::In) continue;
    if (!p.tunes.empty()) {
      if (!s.connected(pin)) continue;
      const int k = t.param_index(p.tunes);
      const ParamDecl& d = t.params[static_cast<std::size_t>(k)];
      BlockGuard::Tuning tu;
      tu.pin = pin;
      tu.param = k;
      tu.type = d.type;
      tu.min = d.min.value_or(-std::numeric_limits<double>::infinity());
      tu.max = d.max.value_or(std::numeric_limits<double>::infinity());
      tu.seen = cell_as_double(d.type, s.param_cell(k));
      g.tuning.push_back(tu);
      continue;
    }
    const IecType type = p.cls == TypeClass::Exact ? p.type : s.datatype();
    if (is_real(type)) g.reals.push_back({pin, s.pin_length(pin), type == IecType::REAL});
  }
  return g;
}

}  // namespace

void BlockRegistry::add(BlockTypeInfo info) {
  if (info.name.empty()) throw std::logic_error("block type without a name");
  if (find(info.name)) throw std::logic_error("block type " + info.name + " registered twice");
  if (!info.create) throw std::logic_error("block type " + info.name + " has no factory");
  add_implicit_pins(info);
  info.create = [create = std::move(info.create)](BlockSetup& s) -> std::unique_ptr<Block> {
    std::unique_ptr<Block> b = create(s);
    if (b) b->guard() = make_guard(s);
    return b;
  };
  for (std::size_t i = 0; i < info.pins.size(); ++i)
    for (std::size_t j = i + 1; j < info.pins.size(); ++j)
      if (info.pins[i].name == info.pins[j].name)
        throw std::logic_error("block type " + info.name + " declares pin " + info.pins[i].name + " twice");
  for (const auto& l : info.links) {
    if (info.pin_index(l.name) >= 0 || info.param_index(l.name) >= 0 || info.link_index(l.name) != &l - info.links.data())
      throw std::logic_error("block type " + info.name + ": link " + l.name + " shadows a pin, a parameter or a link");
    if (!l.length_param.empty()) {
      const int k = info.param_index(l.length_param);
      if (k < 0 || info.params[static_cast<std::size_t>(k)].type != IecType::DINT)
        throw std::logic_error("block type " + info.name + ": list link " + l.name + " needs DINT parameter " + l.length_param);
    }
  }
  for (const auto& p : info.params) {
    if (info.pin_index(p.name) >= 0)
      throw std::logic_error("block type " + info.name + ": parameter " + p.name + " shadows a pin");
    if (!p.default_value.empty()) {
      std::string err;
      if (!parse_value(p.type, p.default_value, &err))
        throw std::logic_error("block type " + info.name + ": default of " + p.name + ": " + err);
    }
  }
  for (const auto& p : info.pins) {
    if (p.is_array()) {
      int k = info.param_index(p.length_param);
      if (k < 0 || !is_integer(info.params[static_cast<std::size_t>(k)].type))
        throw std::logic_error("block type " + info.name + ": array pin " + p.name + " needs integer parameter " +
                               p.length_param);
    }
    if (!p.init.empty()) {
      std::string err;
      if (p.cls == TypeClass::Exact && !parse_value(p.type, p.init, &err))
        throw std::logic_error("block type " + info.name + ": init of pin " + p.name + ": " + err);
    }
  }
  types_.push_back(std::make_unique<BlockTypeInfo>(std::move(info)));
}

const BlockTypeInfo* BlockRegistry::find(std::string_view name) const {
  for (const auto& t : types_)
    if (t->name == name) return t.get();
  return base_ ? base_->find(name) : nullptr;
}

std::vector<const BlockTypeInfo*> BlockRegistry::all() const {
  std::vector<const BlockTypeInfo*> v = base_ ? base_->all() : std::vector<const BlockTypeInfo*>{};
  for (const auto& t : types_) v.push_back(t.get());
  std::stable_sort(v.begin(), v.end(), [](auto* a, auto* b) {
    return a->category != b->category ? a->category < b->category : a->name < b->name;
  });
  return v;
}

}  // namespace syncplc
