#include "runtime/io/memory_driver.hpp"

namespace syncplc {

MemoryDriver::MemoryDriver(std::vector<DriverChannel> channels) : channels_(std::move(channels)) {
  std::uint32_t n = 0;
  for (const auto& c : channels_) {
    offset_.push_back(n);
    n += c.length;
  }
  store_ = std::make_unique<std::atomic<std::uint64_t>[]>(n);
  for (std::uint32_t i = 0; i < n; ++i) store_[i].store(0, std::memory_order_relaxed);
  bound_.assign(channels_.size(), nullptr);
}

void MemoryDriver::latch_inputs(const ScanContext&) noexcept {
  for (std::size_t i = 0; i < channels_.size(); ++i) {
    if (channels_[i].dir != PinDir::In || !bound_[i]) continue;
    for (std::uint32_t k = 0; k < channels_[i].length; ++k)
      bound_[i][k].raw = store_[offset_[i] + k].load(std::memory_order_acquire);
  }
  latches_.fetch_add(1, std::memory_order_relaxed);
}

void MemoryDriver::write_outputs(const ScanContext&) noexcept {
  writes_.fetch_add(1, std::memory_order_relaxed);
  if (!safe_.begin_write()) return;  // held in the safe state
  for (std::size_t i = 0; i < channels_.size(); ++i) {
    if (channels_[i].dir != PinDir::Out || !bound_[i]) continue;
    for (std::uint32_t k = 0; k < channels_[i].length; ++k)
      store_[offset_[i] + k].store(bound_[i][k].raw, std::memory_order_release);
  }
  safe_.end_write();
}

bool MemoryDriver::write_safe_outputs(const SafeOutput* outputs, std::size_t n) noexcept {
  const bool reached = safe_.engage();
  for (std::size_t i = 0; i < n; ++i) {
    const auto ch = static_cast<std::size_t>(outputs[i].channel);
    if (outputs[i].channel < 0 || ch >= channels_.size() || channels_[ch].dir != PinDir::Out ||
        outputs[i].element >= channels_[ch].length)
      continue;
    store_[offset_[ch] + outputs[i].element].store(outputs[i].value.raw, std::memory_order_release);
  }
  return reached;
}

bool MemoryDriver::force_input(int channel, const Cell* values) {
  if (channel < 0 || static_cast<std::size_t>(channel) >= channels_.size()) return false;
  const auto& c = channels_[static_cast<std::size_t>(channel)];
  if (c.dir != PinDir::In) return false;
  for (std::uint32_t k = 0; k < c.length; ++k)
    store_[offset_[static_cast<std::size_t>(channel)] + k].store(values[k].raw, std::memory_order_release);
  return true;
}

bool MemoryDriver::read_output(int channel, Cell* values) const {
  if (channel < 0 || static_cast<std::size_t>(channel) >= channels_.size()) return false;
  const auto& c = channels_[static_cast<std::size_t>(channel)];
  for (std::uint32_t k = 0; k < c.length; ++k)
    values[k].raw = store_[offset_[static_cast<std::size_t>(channel)] + k].load(std::memory_order_acquire);
  return true;
}

int MemoryDriver::channel_index(const std::string& name) const {
  for (std::size_t i = 0; i < channels_.size(); ++i)
    if (channels_[i].name == name) return static_cast<int>(i);
  return -1;
}

DriverTypeInfo memory_driver_type() {
  DriverTypeInfo t;
  t.name = "memory";
  t.doc =
      "Channels backed by memory, for tests and for programs without hardware. "
      "Keys: channels: list of {name, dir: in|out, type: IEC type, length: cells (default 1), unit}. "
      "Inputs are set by `syncplc test` steps (driver.channel) or by a test through force_input().";
  t.create = [](const ConfigNode& cfg, DriverSetup& setup) -> std::unique_ptr<IoDriver> {
    std::vector<DriverChannel> chans;
    const ConfigNode* list = cfg.find("channels");
    if (!list || !list->is_list()) {
      setup.error(list ? list->loc : cfg.loc, "memory driver needs a list 'channels'");
      return nullptr;
    }
    bool ok = true;
    for (const auto& item : list->items) {
      if (!item.is_map()) {
        setup.error(item.loc, "a channel is a map {name, dir, type}");
        ok = false;
        continue;
      }
      DriverChannel c;
      for (const auto& [k, v] : item.map) {
        if (k == "name") c.name = v.scalar;
        else if (k == "dir") {
          if (v.scalar == "in") c.dir = PinDir::In;
          else if (v.scalar == "out") c.dir = PinDir::Out;
          else { setup.error(v.loc, "dir must be 'in' or 'out', not '" + v.scalar + "'"); ok = false; }
        } else if (k == "type") {
          auto t = parse_type_name(v.scalar);
          if (!t) { setup.error(v.loc, "unknown IEC type '" + v.scalar + "'"); ok = false; }
          else c.type = *t;
        } else if (k == "length") {
          try {
            std::size_t used = 0;
            long n = std::stol(v.scalar, &used);
            if (used != v.scalar.size() || n < 1 || n > 65536) throw std::out_of_range("length");
            c.length = static_cast<std::uint32_t>(n);
          } catch (...) {
            setup.error(v.loc, "length must be 1..65536");
            ok = false;
          }
        } else if (k == "unit") c.unit = v.scalar;
        else if (k == "doc") c.doc = v.scalar;
        else { setup.error(v.loc, "unknown channel key '" + k + "' (name, dir, type, length, unit, doc)"); ok = false; }
      }
      if (c.name.empty()) { setup.error(item.loc, "channel without a name"); ok = false; }
      for (const auto& o : chans)
        if (o.name == c.name && !c.name.empty()) { setup.error(item.loc, "duplicate channel '" + c.name + "'"); ok = false; }
      chans.push_back(std::move(c));
    }
    for (const auto& [k, v] : cfg.map)
      if (k != "name" && k != "type" && k != "task" && k != "bind" && k != "channels") {
        setup.error(v.loc, "unknown key '" + k + "' for a memory driver (channels, bind)");
        ok = false;
      }
    if (!ok) return nullptr;
    return std::make_unique<MemoryDriver>(std::move(chans));
  };
  return t;
}

}  // namespace syncplc
