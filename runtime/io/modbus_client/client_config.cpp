#include "runtime/io/modbus_client/client_config.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <set>

#include "runtime/io/driver_config.hpp"
#include "runtime/modbus/register_codec.hpp"

namespace syncplc {
namespace {

constexpr std::int64_t kMs = 1'000'000;
constexpr std::int64_t kS = 1'000'000'000;

bool identifier(const std::string& s) {
  if (s.empty() || !(std::isalpha(static_cast<unsigned char>(s[0])) || s[0] == '_')) return false;
  return std::all_of(s.begin(), s.end(), [](unsigned char c) { return std::isalnum(c) || c == '_'; });
}

bool host_text(const std::string& s) {
  // An IPv4 address or a host name (RFC 1123 letters, digits, '-', '.').
  return !s.empty() && s.size() <= 253 &&
         std::all_of(s.begin(), s.end(), [](unsigned char c) { return std::isalnum(c) || c == '-' || c == '.'; });
}

struct FunctionName {
  const char* key;
  ModbusFunction f;
};
constexpr FunctionName kFunctions[] = {
    {"read_coils", ModbusFunction::ReadCoils},
    {"read_discrete_inputs", ModbusFunction::ReadDiscreteInputs},
    {"read_holding_registers", ModbusFunction::ReadHoldingRegisters},
    {"read_input_registers", ModbusFunction::ReadInputRegisters},
    {"write_single_coil", ModbusFunction::WriteSingleCoil},
    {"write_single_register", ModbusFunction::WriteSingleRegister},
    {"write_multiple_coils", ModbusFunction::WriteMultipleCoils},
    {"write_multiple_registers", ModbusFunction::WriteMultipleRegisters},
    {"read_write_multiple_registers", ModbusFunction::ReadWriteMultipleRegisters},
};

std::optional<ModbusFunction> parse_function(const std::string& s) {
  for (const auto& f : kFunctions)
    if (s == f.key || s == std::to_string(static_cast<int>(f.f))) return f.f;
  return std::nullopt;
}

std::optional<StaleReaction> parse_reaction(const std::string& s) {
  if (s == "hold") return StaleReaction::Hold;
  if (s == "safe") return StaleReaction::Safe;
  if (s == "stop") return StaleReaction::Stop;
  return std::nullopt;
}

const std::vector<std::string> kDeviceKeys = {"name",          "host",          "port",         "unit",
                                              "response_timeout", "connect_timeout", "reconnect_min", "reconnect_max",
                                              "word_order",    "reaction",      "stale_after",   "timing"};
const std::vector<std::string> kGroupKeys = {"name",  "device",    "function", "address",  "count",  "write_address",
                                             "write_count", "type", "word_order", "scale", "offset", "unit",
                                             "every", "on_change", "alive_every", "reaction", "stale_after", "safe"};

WordOrder word_order(DriverConfig& c, WordOrder def) {
  const std::string d = def == WordOrder::HighFirst ? "high_first" : "low_first";
  return c.choice("word_order", {"high_first", "low_first"}, d) == "high_first" ? WordOrder::HighFirst
                                                                                : WordOrder::LowFirst;
}

StaleReaction reaction(DriverConfig& c, StaleReaction def) {
  return *parse_reaction(c.choice("reaction", {"hold", "safe", "stop"}, std::string(stale_reaction_key(def))));
}

ClientDevice read_device(const ConfigNode& n, DriverSetup& setup, bool& ok) {
  DriverConfig c = DriverConfig::section(n, setup, "a device", kDeviceKeys);
  ClientDevice d;
  if (const ConfigNode* nm = n.find("name"); !nm || !nm->is_scalar() || !identifier(nm->scalar))
    c.error(nm ? nm->loc : n.loc, "a device needs a name (an identifier)");
  else
    d.name = nm->scalar;
  if (const ConfigNode* h = n.find("host")) {
    if (!h->is_scalar() || !host_text(h->scalar)) c.error(h->loc, "host: expected an IPv4 address or a host name");
    else d.host = h->scalar;
  }
  if (!n.find("port")) c.error(n.loc, "device " + d.name + " needs a port (1..65535)");
  d.port = static_cast<std::uint16_t>(c.integer("port", 502, 1, 65535));
  d.unit = static_cast<std::uint8_t>(c.integer("unit", 1, 0, 255));
  d.response_timeout_ns = c.duration_ns("response_timeout", d.response_timeout_ns, kMs, 60 * kS);
  d.connect_timeout_ns = c.duration_ns("connect_timeout", d.connect_timeout_ns, kMs, 60 * kS);
  d.reconnect_min_ns = c.duration_ns("reconnect_min", d.reconnect_min_ns, kMs, 3600 * kS);
  d.reconnect_max_ns = c.duration_ns("reconnect_max", std::max(d.reconnect_max_ns, d.reconnect_min_ns), kMs, 3600 * kS);
  if (d.reconnect_max_ns < d.reconnect_min_ns)
    c.error(n.find("reconnect_max") ? n.find("reconnect_max")->loc : n.loc,
            "reconnect_max must be at least reconnect_min (" + format_duration(d.reconnect_min_ns) + ")");
  d.word_order = word_order(c, WordOrder::HighFirst);
  d.reaction = reaction(c, StaleReaction::Hold);
  d.stale_after_ns = c.duration_ns("stale_after", 0, 0, 3600 * kS);
  d.timing = c.choice("timing", {"cycle", "free"}, "cycle") == "free" ? ExchangeTiming::Free : ExchangeTiming::Cycle;
  d.task_period_ns = setup.task_period_ns();
  if (!c.ok()) ok = false;
  return d;
}

void read_safe(DriverConfig& c, const ConfigNode& n, RequestGroup& g) {
  const IecType t = g.format.channel();
  g.safe.assign(g.read_values(), Cell{});
  auto one = [&](const ConfigNode& v, Cell& out) {
    std::string err;
    auto cell = v.is_scalar() ? parse_value(t, v.scalar, &err) : std::nullopt;
    if (!cell) c.error(v.loc, "safe: '" + v.scalar + "' is not a " + std::string(type_name(t)) + (err.empty() ? "" : " (" + err + ")"));
    else out = *cell;
  };
  if (n.is_scalar()) {
    Cell v;
    one(n, v);
    std::fill(g.safe.begin(), g.safe.end(), v);
  } else if (n.is_list() && n.items.size() == g.safe.size()) {
    for (std::size_t i = 0; i < n.items.size(); ++i) one(n.items[i], g.safe[i]);
  } else {
    c.error(n.loc, "safe: expected one value for every element or a list of " + std::to_string(g.safe.size()));
  }
}

std::optional<RequestGroup> read_group(const ConfigNode& n, const std::vector<ClientDevice>& devices,
                                       std::int64_t period_ns, DriverSetup& setup) {
  DriverConfig c = DriverConfig::section(n, setup, "a request group", kGroupKeys);
  RequestGroup g;
  const ConfigNode* nm = n.find("name");
  if (!nm || !nm->is_scalar() || !identifier(nm->scalar)) {
    c.error(nm ? nm->loc : n.loc, "a request group needs a name (an identifier; its channels are named after it)");
  } else {
    g.name = nm->scalar;
  }
  // The device: by name, or the only one.
  if (const ConfigNode* dv = n.find("device")) {
    auto it = std::find_if(devices.begin(), devices.end(), [&](const ClientDevice& d) { return d.name == dv->scalar; });
    if (it == devices.end()) c.error(dv->loc, "unknown device '" + dv->scalar + "'");
    else g.device = static_cast<std::size_t>(it - devices.begin());
  } else if (devices.size() != 1) {
    c.error(n.loc, "request group " + g.name + " needs device: (the driver has " + std::to_string(devices.size()) + " devices)");
  }
  const ClientDevice dev = g.device < devices.size() ? devices[g.device] : ClientDevice{};

  const ConfigNode* fn = n.find("function");
  if (!fn) {
    c.error(n.loc, "request group " + g.name + " needs function: 1, 2, 3, 4, 5, 6, 15, 16 or 23 (or its name, e.g. read_holding_registers)");
  } else if (auto f = fn->is_scalar() ? parse_function(fn->scalar) : std::nullopt) {
    g.function = *f;
  } else {
    std::string names;
    for (const auto& x : kFunctions) names += std::string(names.empty() ? "" : ", ") + x.key;
    c.error(fn->loc, "function: '" + fn->scalar + "' is not 1, 2, 3, 4, 5, 6, 15, 16 or 23 (" + names + ")");
  }
  const bool bits = is_bit_function(g.function);

  // The values' type and encoding.
  g.format.wire = bits ? IecType::BOOL : IecType::INT;
  if (const ConfigNode* ty = n.find("type")) {
    auto t = ty->is_scalar() ? parse_type_name(ty->scalar) : std::nullopt;
    if (!t) c.error(ty->loc, "type: '" + ty->scalar + "' is not an IEC elementary type");
    else if (bits && *t != IecType::BOOL) c.error(ty->loc, "type: coils and discrete inputs are BOOL");
    else if (!bits && (*t == IecType::BOOL || *t == IecType::TIME))
      c.error(ty->loc, "type: registers hold integers, bit strings and reals, not " + ty->scalar);
    else g.format.wire = *t;
  }
  g.format.order = word_order(c, dev.word_order);
  if (n.find("scale") || n.find("offset")) {
    if (g.format.wire == IecType::BOOL) c.error((n.find("scale") ? n.find("scale") : n.find("offset"))->loc, "scale and offset are for register values, not BOOL");
    g.format.scaled = true;
    g.format.scale = c.number("scale", "", 1.0);
    g.format.offset = c.number("offset", "", 0.0);
    if (g.format.scale == 0) c.error(n.find("scale")->loc, "scale must not be 0");
  }
  if (const ConfigNode* u = n.find("unit")) g.unit = u->scalar;

  // Addresses and quantities: values times registers per value, within the function's limit (App. Protocol §6).
  const std::uint32_t width = g.format.width();
  const bool single = g.function == ModbusFunction::WriteSingleCoil || g.function == ModbusFunction::WriteSingleRegister;
  g.address = static_cast<std::uint16_t>(c.integer("address", 0, 0, 65535));
  if (!n.find("address")) c.error(n.loc, "request group " + g.name + " needs address: (the first coil or register, 0-based)");
  g.count = static_cast<std::uint32_t>(c.integer("count", 1, 1, 65535));
  if (single && g.count * width != 1)
    c.error(n.find("count") ? n.find("count")->loc : (n.find("type") ? n.find("type")->loc : n.loc),
            "function " + std::to_string(static_cast<int>(g.function)) + " writes one " + (bits ? "coil" : "16-bit register") +
                ": count 1" + (bits ? "" : " of a 16-bit type"));
  else if (g.count * width > max_quantity(g.function))
    c.error(n.find("count") ? n.find("count")->loc : n.loc,
            "count " + std::to_string(g.count) + " takes " + std::to_string(g.count * width) + (bits ? " coils" : " registers") +
                "; function " + std::to_string(static_cast<int>(g.function)) + " carries at most " + std::to_string(max_quantity(g.function)));
  if (std::uint64_t{g.address} + std::uint64_t{g.count} * width > 65536)
    c.error(n.find("address") ? n.find("address")->loc : n.loc, "address + count runs past 65535");
  if (g.function == ModbusFunction::ReadWriteMultipleRegisters) {
    if (!n.find("write_address")) c.error(n.loc, "function 23 needs write_address: (count and address are its read side)");
    g.write_address = static_cast<std::uint16_t>(c.integer("write_address", 0, 0, 65535));
    g.write_count = static_cast<std::uint32_t>(c.integer("write_count", g.count, 1, 65535));
    if (g.write_count * width > max_write_quantity(g.function))
      c.error(n.find("write_count") ? n.find("write_count")->loc : n.loc,
              "write_count " + std::to_string(g.write_count) + " takes " + std::to_string(g.write_count * width) +
                  " registers; function 23 writes at most 121");
    if (std::uint64_t{g.write_address} + std::uint64_t{g.write_count} * width > 65536)
      c.error(n.find("write_address") ? n.find("write_address")->loc : n.loc, "write_address + write_count runs past 65535");
  } else {
    for (const char* k : {"write_address", "write_count"})
      if (const ConfigNode* x = n.find(k)) c.error(x->loc, std::string(k) + " is for function 23 only");
  }

  // When: every scan (the task's period) or every n ms.
  g.interval_ns = period_ns;
  if (const ConfigNode* ev = n.find("every"); ev && ev->scalar != "scan") {
    g.every_scan = false;
    g.interval_ns = c.duration_ns("every", period_ns, 100'000, 3600 * kS);
  }
  g.on_change = c.boolean("on_change", false);
  if (g.on_change && !g.writes()) c.error(n.find("on_change")->loc, "on_change is for groups that write");
  // A group that writes only on change would never find out that its device
  // died: it writes its values again after alive_every without a write.
  g.alive_every_ns = c.duration_ns("alive_every", g.alive_every_ns, 0, 3600 * kS);
  if (n.find("alive_every") && !g.on_change) c.error(n.find("alive_every")->loc, "alive_every is for on_change groups (the others exchange every `every`)");

  // A device's reaction safe is its read groups' (safe values are inputs); its write groups hold.
  g.reaction = reaction(c, dev.reaction == StaleReaction::Safe && !g.reads() ? StaleReaction::Hold : dev.reaction);
  g.stale_after_ns = c.duration_ns("stale_after", dev.stale_after_ns, 0, 3600 * kS);
  if (g.reaction == StaleReaction::Safe && !g.reads())
    c.error(n.find("reaction") ? n.find("reaction")->loc : n.loc,
            "reaction safe sets inputs; a write group's outputs take their tags' safe: values when the task stops (reaction stop)");
  g.safe.assign(g.read_values(), Cell{});
  if (const ConfigNode* s = n.find("safe")) {
    if (g.reaction != StaleReaction::Safe) c.error(s->loc, "safe: values are used by reaction safe only (this group's reaction is " + std::string(stale_reaction_key(g.reaction)) + ")");
    else read_safe(c, *s, g);
  }
  if (!c.ok()) return std::nullopt;
  return g;
}

}  // namespace

std::string_view stale_reaction_key(StaleReaction r) {
  switch (r) {
    case StaleReaction::Hold: return "hold";
    case StaleReaction::Safe: return "safe";
    case StaleReaction::Stop: return "stop";
  }
  return "hold";
}

std::optional<ModbusClientConfig> read_modbus_client_config(const ConfigNode& entry, DriverSetup& setup) {
  DriverConfig c(entry, setup, "modbus_client", {"devices", "groups", "at_stop"});
  ModbusClientConfig cfg;
  cfg.safe_at_stop = c.choice("at_stop", {"keep", "safe"}, "keep") == "safe";
  bool ok = c.ok();
  const ConfigNode* devs = entry.find("devices");
  if (!devs || !devs->is_list() || devs->items.empty()) {
    c.error(devs ? devs->loc : entry.loc, "devices: expected a list of {name, host, port, unit, ...}");
    return std::nullopt;
  }
  std::set<std::string> names;
  for (const auto& d : devs->items) {
    if (!d.is_map()) { c.error(d.loc, "a device is a map {name, host, port, unit, ...}"); continue; }
    ClientDevice dev = read_device(d, setup, ok);
    if (!dev.name.empty() && !names.insert(dev.name).second) c.error(d.find("name")->loc, "duplicate device '" + dev.name + "'");
    cfg.devices.push_back(std::move(dev));
  }
  const ConfigNode* groups = entry.find("groups");
  if (!groups || !groups->is_list() || groups->items.empty()) {
    c.error(groups ? groups->loc : entry.loc, "groups: expected a list of request groups {name, device, function, address, ...}");
    return std::nullopt;
  }
  std::set<std::string> channels;
  for (const auto& gn : groups->items) {
    if (!gn.is_map()) { c.error(gn.loc, "a request group is a map {name, device, function, address, ...}"); continue; }
    auto g = read_group(gn, cfg.devices, setup.task_period_ns(), setup);
    if (!g) { ok = false; continue; }
    // The group's channels are named after it: two groups must not produce one name.
    std::vector<std::string> mine = {g->name, g->name + "_write", g->name + "_ok", g->name + "_age", g->name + "_cycles", g->name + "_error",
                                     g->name + "_reaction", g->name + "_requests", g->name + "_errors",
                                     g->name + "_timeouts", g->name + "_reconnects"};
    bool clash = false;
    for (const auto& m : mine) clash = clash || channels.count(m);
    if (clash) c.error(gn.find("name")->loc, "request group " + g->name + ": its channel names clash with another group's");
    channels.insert(mine.begin(), mine.end());
    cfg.groups.push_back(std::move(*g));
  }
  if (!ok || !c.ok()) return std::nullopt;
  return cfg;
}

}  // namespace syncplc
