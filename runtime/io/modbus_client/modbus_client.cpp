#include "runtime/io/modbus_client/modbus_client.hpp"

#include <time.h>

#include <algorithm>
#include <utility>

#include "runtime/core/monotonic_clock.hpp"

namespace syncplc {
namespace {

std::int64_t default_clock() { return monotonic_ns(); }

std::uint32_t saturate32(std::uint64_t v) { return v > 0xFFFFFFFFu ? 0xFFFFFFFFu : static_cast<std::uint32_t>(v); }

}  // namespace

ModbusClientDriver::ModbusClientDriver(ModbusClientConfig cfg) : cfg_(std::move(cfg)), clock_(&default_clock) {
  auto add = [this](std::string name, PinDir dir, IecType t, std::uint32_t n, std::string unit, std::string doc) {
    channels_.push_back(DriverChannel{std::move(name), dir, t, n, std::move(unit), std::move(doc)});
    return static_cast<int>(channels_.size() - 1);
  };
  for (const auto& g : cfg_.groups) {
    GroupChannels c;
    const IecType t = g.format.channel();
    const std::string dev = cfg_.devices[g.device].name;
    if (g.reads()) c.values = add(g.name, PinDir::In, t, g.count, g.unit, "values read from " + dev);
    else c.values = add(g.name, PinDir::Out, t, g.count, g.unit, "values written to " + dev);
    if (g.function == ModbusFunction::ReadWriteMultipleRegisters)
      c.write = add(g.name + "_write", PinDir::Out, t, g.write_count, g.unit, "values written to " + dev + " (FC 23)");
    c.ok = add(g.name + "_ok", PinDir::In, IecType::BOOL, 1, "", "the last exchange succeeded");
    c.age = add(g.name + "_age", PinDir::In, IecType::LREAL, 1, "ms", "time since the last successful exchange");
    c.cycles = add(g.name + "_cycles", PinDir::In, IecType::UDINT, 1, "",
                   "scans since the request of the values shown was handed over (0: this cycle's)");
    c.error = add(g.name + "_error", PinDir::In, IecType::UINT, 1, "", "last error code, 0 when ok");
    c.reaction = add(g.name + "_reaction", PinDir::In, IecType::BOOL, 1, "", "stale past stale_after: the reaction applies");
    c.requests = add(g.name + "_requests", PinDir::In, IecType::UDINT, 1, "", "requests sent");
    c.errors = add(g.name + "_errors", PinDir::In, IecType::UDINT, 1, "", "failed exchanges and connection attempts (not: not connected)");
    c.timeouts = add(g.name + "_timeouts", PinDir::In, IecType::UDINT, 1, "", "requests without a reply in time");
    c.reconnects = add(g.name + "_reconnects", PinDir::In, IecType::UDINT, 1, "", "the device's reconnections");
    gch_.push_back(c);
  }
  bound_.assign(channels_.size(), nullptr);
  closed_reconnects_.assign(cfg_.devices.size(), 0);
  at_stop_.assign(cfg_.groups.size(), -1);
  inherit_.assign(cfg_.devices.size(), false);
  device_reads_.assign(cfg_.devices.size(), false);
  for (const auto& g : cfg_.groups)
    if (g.reads()) device_reads_[g.device] = true;
  device_epoch_.assign(cfg_.devices.size(), 0);
  channel_group_.assign(channels_.size(), -1);
  for (std::size_t i = 0; i < cfg_.groups.size(); ++i)
    if (cfg_.groups[i].reads()) channel_group_[static_cast<std::size_t>(gch_[i].values)] = static_cast<int>(i);
  group_ok_ = std::make_unique<std::atomic<bool>[]>(cfg_.groups.size());  // value-initialised: not ok before the first reply
  reset_exchange();
}

bool ModbusClientDriver::input_ok(int channel) const noexcept {
  if (channel < 0 || static_cast<std::size_t>(channel) >= channel_group_.size()) return true;
  const int g = channel_group_[static_cast<std::size_t>(channel)];
  return g < 0 || group_ok_[static_cast<std::size_t>(g)].load(std::memory_order_relaxed);
}

void ModbusClientDriver::reset_exchange() {
  handover_.clear();
  for (std::size_t i = 0; group_ok_ && i < cfg_.groups.size(); ++i) group_ok_[i].store(false, std::memory_order_relaxed);
  values_.clear();
  out_.clear();
  out_seq_.clear();
  for (const auto& g : cfg_.groups) {
    handover_.push_back(std::make_unique<GroupHandover>(g));
    // Before the first good reply the inputs show the safe values (reaction safe) or zeros.
    values_.push_back(g.reaction == StaleReaction::Safe ? g.safe : std::vector<Cell>(g.read_values()));
    out_.emplace_back(g.written_values());
    out_seq_.push_back(0);
  }
}

int ModbusClientDriver::channel_index(const std::string& name) const {
  for (std::size_t i = 0; i < channels_.size(); ++i)
    if (channels_[i].name == name) return static_cast<int>(i);
  return -1;
}

bool ModbusClientDriver::open(std::string* error) {
  // will_take_over's marks are for this open only: a reopened driver connects itself.
  const std::vector<bool> inherit = std::exchange(inherit_, std::vector<bool>(cfg_.devices.size(), false));
  close();
  // A reopened driver starts as a new one: nothing of the previous run's
  // replies is latched as fresh, nothing of its outputs is written.
  reset_exchange();
  group_link_.assign(cfg_.groups.size(), nullptr);
  // FC 23 reads only together with its write: an unbound write side would
  // leave the group without a request, never stale and never reacting.
  for (std::size_t i = 0; i < cfg_.groups.size(); ++i)
    if (cfg_.groups[i].function == ModbusFunction::ReadWriteMultipleRegisters && !bound_[static_cast<std::size_t>(gch_[i].write)]) {
      *error = "request group " + cfg_.groups[i].name + " (function 23) reads only with its write: bind " +
               cfg_.groups[i].name + "_write to the tag whose values it writes";
      return false;
    }
  safe_.reset();
  std::fill(at_stop_.begin(), at_stop_.end(), std::int8_t{-1});
  latch_.clear();
  std::fill(device_epoch_.begin(), device_epoch_.end(), 0);
  const std::int64_t now = clock_();
  for (const auto& g : cfg_.groups) {
    latch_.emplace_back(g, make_group_texts(name(), g));
    latch_.back().reset(now, cycle_.count());
  }
  for (auto& h : handover_) {
    h->reply.reset();
    h->latched.reset();
  }
  opened_ns_ = closed_ns_ = now;
  open_ = true;
  if (!network_) return true;
  for (std::size_t d = 0; d < cfg_.devices.size(); ++d) {
    std::vector<GroupHandover*> mine;
    for (std::size_t i = 0; i < cfg_.groups.size(); ++i)
      if (cfg_.groups[i].device == d) mine.push_back(handover_[i].get());
    if (mine.empty()) continue;  // a device no group uses: no connection
    ClientDevice& dev = cfg_.devices[d];
    if (!resolve_ipv4(dev.host, &dev.address)) {
      *error = "device " + dev.name + ": cannot resolve host '" + dev.host + "' to an IPv4 address";
      close();
      return false;
    }
    links_.push_back(std::make_unique<DeviceLink>(dev, std::move(mine), clock_, &cycle_));
    if (inherit[d]) links_.back()->set_inherit();
    for (std::size_t i = 0; i < cfg_.groups.size(); ++i)
      if (cfg_.groups[i].device == d) group_link_[i] = links_.back().get();
    if (!links_.back()->start(error)) {
      close();
      return false;
    }
  }
  return true;
}

void ModbusClientDriver::close() noexcept {
  for (auto& l : links_) l->stop();
  // Kept for counters() after the close (run prints them at exit).
  for (const auto& l : links_)
    for (std::size_t d = 0; d < cfg_.devices.size(); ++d)
      if (&l->device() == &cfg_.devices[d]) closed_reconnects_[d] = l->reconnects.load(std::memory_order_relaxed);
  for (auto& p : group_link_) p = nullptr;
  links_.clear();
  if (open_) closed_ns_ = clock_();
  open_ = false;
}

void ModbusClientDriver::latch_inputs(const ScanContext& ctx) noexcept {
  if (latch_.empty()) return;  // never opened
  const std::int64_t now = clock_();
  const std::uint32_t cycle = cycle_.count();
  for (std::size_t i = 0; i < cfg_.groups.size(); ++i) {
    const RequestGroup& g = cfg_.groups[i];
    GroupHandover& h = *handover_[i];
    const GroupStatus& st = latch_[i].latch(h.results.acquire(), now, ctx, values_[i].data(), cycle);
    if (st.fresh) h.latched.record(now - st.sent);  // O(1), relaxed atomics, no allocation
    const GroupChannels& c = gch_[i];
    if (g.reads()) {
      if (Cell* v = bound_[static_cast<std::size_t>(c.values)]) {
        const bool safe = g.reaction == StaleReaction::Safe && st.reacting;
        const auto& src = safe ? g.safe : values_[i];
        std::copy(src.begin(), src.end(), v);
      }
    }
    auto set = [this](int ch, auto value) {
      if (Cell* p = bound_[static_cast<std::size_t>(ch)]) p->set(value);
    };
    set(c.ok, st.ok);
    group_ok_[i].store(st.ok, std::memory_order_relaxed);  // input_ok: the quality readers show
    set(c.age, st.age_ms);
    set(c.cycles, st.cycles);
    set(c.error, st.error);
    set(c.reaction, st.reacting);
    set(c.requests, saturate32(h.requests.load(std::memory_order_relaxed)));
    set(c.errors, saturate32(h.errors.load(std::memory_order_relaxed)));
    set(c.timeouts, saturate32(h.timeouts.load(std::memory_order_relaxed)));
    const DeviceLink* link = i < group_link_.size() ? group_link_[i] : nullptr;
    set(c.reconnects, saturate32(link ? link->reconnects.load(std::memory_order_relaxed) : 0));
  }
  // The write gate's epoch per device: the connection on which every reading
  // group of the device has good values latched now (0: not all of them).
  for (std::size_t d = 0; d < cfg_.devices.size(); ++d) {
    std::uint64_t e = 0;
    bool all = true;
    for (std::size_t i = 0; i < cfg_.groups.size() && all; ++i) {
      if (cfg_.groups[i].device != d || !cfg_.groups[i].reads()) continue;
      const GroupStatus& st = latch_[i].status();
      if (!st.ok || st.epoch == 0 || (e != 0 && st.epoch != e)) all = false;
      else e = st.epoch;
    }
    device_epoch_[d] = all ? e : 0;
  }
}

void ModbusClientDriver::write_outputs(const ScanContext&) noexcept {
  if (!safe_.begin_write()) {  // held in the safe state by the supervisor: the reads still follow the scan
    hand_over_to_devices();
    return;
  }
  for (std::size_t i = 0; i < cfg_.groups.size(); ++i) {
    const RequestGroup& g = cfg_.groups[i];
    if (!g.writes()) continue;
    const int ch = g.function == ModbusFunction::ReadWriteMultipleRegisters ? gch_[i].write : gch_[i].values;
    const Cell* v = bound_[static_cast<std::size_t>(ch)];
    if (!v) continue;  // an unbound output channel: nothing to write
    std::copy(v, v + out_[i].size(), out_[i].begin());
    Cell* b = handover_[i]->outputs.back();
    b[GroupHandover::kSeq].set<std::uint64_t>(++out_seq_[i]);
    // Computed from the reads this scan latched: sent on that connection only.
    b[GroupHandover::kOutEpoch].set<std::uint64_t>(device_reads_[g.device] ? device_epoch_[g.device]
                                                                           : GroupHandover::kAnyEpoch);
    std::copy(out_[i].begin(), out_[i].end(), b + GroupHandover::kOutValues);
    handover_[i]->outputs.publish();
  }
  safe_.end_write();
  hand_over_to_devices();
}

void ModbusClientDriver::hand_over_to_devices() noexcept {
  // timing cycle: the device threads run this scan's exchanges now (one
  // atomic increment; one futex wake for all when any sleeps; cycle_signal.hpp).
  // Free-running devices never wait on it.
  cycle_.hand_over();
}

bool ModbusClientDriver::write_safe_outputs(const SafeOutput* outputs, std::size_t n) noexcept {
  // After engage() no write_outputs runs: this thread is the outputs' only
  // producer. Not reached (a scan stuck inside write_outputs): the outputs
  // are held, but the hand-over belongs to that scan; touch nothing.
  if (!safe_.engage()) return false;
  for (std::size_t i = 0; i < cfg_.groups.size(); ++i) {
    const RequestGroup& g = cfg_.groups[i];
    if (!g.writes()) continue;
    const int ch = g.function == ModbusFunction::ReadWriteMultipleRegisters ? gch_[i].write : gch_[i].values;
    bool any = false;
    for (std::size_t k = 0; k < n; ++k)
      if (outputs[k].channel == ch && outputs[k].element < out_[i].size()) {
        out_[i][outputs[k].element] = outputs[k].value;
        any = true;
      }
    if (!any && out_seq_[i] == 0) continue;  // nothing ever written and no safe value: leave the device alone
    Cell* b = handover_[i]->outputs.back();
    b[GroupHandover::kSeq].set<std::uint64_t>(++out_seq_[i]);
    b[GroupHandover::kOutEpoch].set<std::uint64_t>(GroupHandover::kAnyEpoch);  // safe values need no reads
    std::copy(out_[i].begin(), out_[i].end(), b + GroupHandover::kOutValues);
    handover_[i]->outputs.publish();
  }
  hand_over_to_devices();  // the safe values go out now, not at the fallback's next exchange
  return true;
}

void ModbusClientDriver::stop_outputs(const SafeOutput* outputs, std::size_t n) noexcept {
  if (!cfg_.safe_at_stop || !open_) return;
  // After the last scan: engage() finds no write_outputs under way.
  std::vector<std::uint64_t> before(out_seq_);
  if (!write_safe_outputs(outputs, n)) return;
  for (const auto& l : links_) l->flush();
  // The groups write_safe_outputs handed values over to (those with a safe
  // value, or written before), until their devices have them or the time is
  // up: each group's own device's bound, so a dead device costs the stop its
  // own bound, never another device's longer one.
  auto acknowledged = [&](std::size_t i) {
    return handover_[i]->acked.load(std::memory_order_acquire) >= out_seq_[i];
  };
  const std::int64_t start = monotonic_ns();
  for (;;) {
    bool all = true;
    const std::int64_t now = monotonic_ns();
    for (std::size_t i = 0; i < cfg_.groups.size(); ++i)
      if (out_seq_[i] != before[i] && group_link_[i] && !acknowledged(i) &&
          now < start + stop_bound_ns(cfg_.groups[i].device))
        all = false;
    if (all) break;
    timespec ts{0, 1'000'000};
    nanosleep(&ts, nullptr);
  }
  for (std::size_t i = 0; i < cfg_.groups.size(); ++i)
    if (out_seq_[i] != before[i]) at_stop_[i] = acknowledged(i) ? 1 : 0;
}

namespace {

// The endpoint a device connects to: its address (resolved when the
// driver opened) and port.
bool same_endpoint(const ClientDevice& a, const ClientDevice& b) {
  std::string ea = a.address, eb = b.address;
  if (ea.empty() && !resolve_ipv4(a.host, &ea)) return false;
  if (eb.empty() && !resolve_ipv4(b.host, &eb)) return false;
  return ea == eb && a.port == b.port;
}

}  // namespace

void ModbusClientDriver::will_take_over(IoDriver& previous) {
  auto* prev = dynamic_cast<ModbusClientDriver*>(&previous);
  if (!prev || !network_) return;
  for (std::size_t d = 0; d < cfg_.devices.size(); ++d)
    for (const auto& l : prev->links_)
      if (same_endpoint(cfg_.devices[d], l->device())) inherit_[d] = true;
}

void ModbusClientDriver::take_over(IoDriver& previous) noexcept {
  auto* prev = dynamic_cast<ModbusClientDriver*>(&previous);
  for (auto& mine : links_) {
    if (!mine->inherits()) continue;
    int fd = -1;
    if (prev)
      for (auto& old : prev->links_)
        if (same_endpoint(mine->device(), old->device())) {
          fd = old->release();  // -1 when it was not connected (or already given away)
          break;
        }
    mine->adopt(fd);  // -1: it connects itself (the old link's socket closes with prev)
  }
}

bool ModbusClientDriver::read_output(int channel, Cell* values) const {
  for (std::size_t i = 0; i < cfg_.groups.size(); ++i) {
    const RequestGroup& g = cfg_.groups[i];
    const int ch = g.function == ModbusFunction::ReadWriteMultipleRegisters ? gch_[i].write : gch_[i].values;
    if (g.writes() && ch == channel) {
      std::copy(out_[i].begin(), out_[i].end(), values);
      return true;
    }
  }
  return false;
}

std::int64_t ModbusClientDriver::stop_bound_ns(std::size_t d) const {
  std::int64_t groups = 1;  // the exchange under way
  for (const auto& g : cfg_.groups)
    if (g.device == d) ++groups;
  const ClientDevice& dev = cfg_.devices[d];
  return dev.connect_timeout_ns + groups * dev.response_timeout_ns;
}

void ModbusClientDriver::inject(std::size_t g, std::uint16_t error, std::int64_t stamp, const Cell* values,
                                std::int64_t sent, std::uint64_t epoch, std::int64_t cycle) {
  handover_[g]->publish(error, stamp, values, sent < 0 ? stamp : sent, epoch,
                        cycle < 0 ? cycle_.count() : static_cast<std::uint32_t>(cycle));
}

std::uint64_t ModbusClientDriver::handed_over_epoch(std::size_t g) {
  return handover_[g]->outputs.acquire()[GroupHandover::kOutEpoch].get<std::uint64_t>();
}

const Cell* ModbusClientDriver::handed_over(std::size_t g) {
  const Cell* c = handover_[g]->outputs.acquire();
  return c[GroupHandover::kSeq].get<std::uint64_t>() == 0 ? nullptr : c + GroupHandover::kOutValues;
}

std::string ModbusClientDriver::summary() const {
  std::string s = std::to_string(cfg_.devices.size()) + (cfg_.devices.size() == 1 ? " device, " : " devices, ") +
                  std::to_string(cfg_.groups.size()) + (cfg_.groups.size() == 1 ? " request group:" : " request groups:");
  for (std::size_t d = 0; d < cfg_.devices.size(); ++d) {
    const auto& dev = cfg_.devices[d];
    s += (d ? "; " : " ") + dev.name + " " + dev.host + ":" + std::to_string(dev.port) + " unit " + std::to_string(dev.unit);
    for (const auto& g : cfg_.groups)
      if (g.device == d)
        s += ", " + g.name + " FC" + std::to_string(static_cast<int>(g.function)) + "@" + std::to_string(g.address);
  }
  return s;
}

std::vector<std::pair<std::string, double>> ModbusClientDriver::counters() const {
  std::vector<std::pair<std::string, double>> out;
  // Requests/s over the time open (until close() once closed).
  const double open_s = static_cast<double>((open_ ? clock_() : closed_ns_) - opened_ns_) * 1e-9;
  auto rate = [open_s](std::uint64_t n) { return open_s > 0 ? static_cast<double>(n) / open_s : 0.0; };
  auto us = [](std::int64_t ns) { return static_cast<double>(ns) * 1e-3; };
  std::vector<std::uint64_t> device_requests(cfg_.devices.size(), 0);
  for (std::size_t i = 0; i < cfg_.groups.size(); ++i) {
    const auto& h = *handover_[i];
    const std::string& g = cfg_.groups[i].name;
    const std::uint64_t requests = h.requests.load(std::memory_order_relaxed);
    device_requests[cfg_.groups[i].device] += requests;
    out.emplace_back(g + ".requests", static_cast<double>(requests));
    out.emplace_back(g + ".errors", static_cast<double>(h.errors.load(std::memory_order_relaxed)));
    out.emplace_back(g + ".timeouts", static_cast<double>(h.timeouts.load(std::memory_order_relaxed)));
    out.emplace_back(g + ".not_connected", static_cast<double>(h.not_connected.load(std::memory_order_relaxed)));
    out.emplace_back(g + ".requests_per_s", rate(requests));
    if (at_stop_[i] >= 0) out.emplace_back(g + ".safe_at_stop", at_stop_[i]);
    for (const auto& [what, hist] : {std::pair{"reply", &h.reply}, std::pair{"latched", &h.latched}}) {
      const Histogram::Summary s = hist->summary();
      if (s.count == 0) continue;
      out.emplace_back(g + "." + what + "_p50_us", us(s.p50));
      out.emplace_back(g + "." + what + "_p99_us", us(s.p99));
      out.emplace_back(g + "." + what + "_max_us", us(s.max));
    }
  }
  for (std::size_t d = 0; d < cfg_.devices.size(); ++d)
    if (device_requests[d]) out.emplace_back(cfg_.devices[d].name + ".requests_per_s", rate(device_requests[d]));
  for (std::size_t d = 0; d < cfg_.devices.size(); ++d) {
    std::uint64_t n = closed_reconnects_[d];
    for (const auto& l : links_)
      if (&l->device() == &cfg_.devices[d]) n = l->reconnects.load(std::memory_order_relaxed);
    if (device_requests[d]) out.emplace_back(cfg_.devices[d].name + ".reconnects", static_cast<double>(n));
  }
  return out;
}

DriverTypeInfo modbus_client_driver_type() {
  DriverTypeInfo t;
  t.name = "modbus_client";
  t.doc =
      "Modbus TCP client: at_stop (keep, safe); remote devices {name, host (default 127.0.0.1), port, unit, response_timeout, "
      "connect_timeout, reconnect_min, reconnect_max, word_order, reaction, stale_after, timing (cycle, free)} and cyclic request groups "
      "{name, device, function (1, 2, 3, 4, 5, 6, 15, 16, 23), address, count, write_address, write_count (23), "
      "type, word_order, scale, offset, unit, every (scan or a duration), on_change, alive_every, reaction (hold, safe, stop), "
      "stale_after, safe}. Channels per group g: g (values), g_write (FC 23), g_ok, g_age (ms), g_cycles, g_error, "
      "g_reaction, g_requests, g_errors, g_timeouts, g_reconnects. One thread per device; docs/modbus-client.md.";
  t.create = [](const ConfigNode& node, DriverSetup& setup) -> std::unique_ptr<IoDriver> {
    auto cfg = read_modbus_client_config(node, setup);
    if (!cfg) return nullptr;
    return std::make_unique<ModbusClientDriver>(std::move(*cfg));
  };
  return t;
}

}  // namespace syncplc
