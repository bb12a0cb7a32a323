#include "runtime/project/modbus_settings.hpp"

#include <arpa/inet.h>

#include <algorithm>

#include "runtime/modbus/register_map.hpp"

namespace syncplc {
namespace {

const char* const kSectionKeys =
    "enabled, port, bind, unit_id, max_clients, idle_timeout, word_order, allowed_clients, read_only, cpus, task_status, store_status";

// A BOOL setting; false (and `out` unchanged) after reporting a bad value.
bool read_flag(const ConfigNode& v, const std::string& what, bool& out, Diagnostics& d) {
  std::string err;
  auto c = v.is_scalar() ? parse_value(IecType::BOOL, v.scalar, &err) : std::nullopt;
  if (!c) {
    d.error(v.loc, what + ": " + (err.empty() ? "expected TRUE or FALSE" : err));
    return false;
  }
  out = c->get<bool>();
  return true;
}

// An integer setting in lo..hi.
std::optional<std::int64_t> read_integer(const ConfigNode& v, const std::string& what, std::int64_t lo, std::int64_t hi,
                                         Diagnostics& d) {
  std::string err;
  auto c = v.is_scalar() ? parse_value(IecType::LINT, v.scalar, &err) : std::nullopt;
  if (c && c->get<std::int64_t>() >= lo && c->get<std::int64_t>() <= hi) return c->get<std::int64_t>();
  d.error(v.loc, what + " must be an integer " + std::to_string(lo) + ".." + std::to_string(hi) +
                     (v.is_scalar() ? ", not '" + v.scalar + "'" : ""));
  return std::nullopt;
}

void read_int_setting(const ConfigNode& v, const std::string& what, std::int64_t lo, std::int64_t hi, int& out,
                      Diagnostics& d) {
  if (auto i = read_integer(v, what, lo, hi, d)) out = static_cast<int>(*i);
}

void read_bind(const ConfigNode& v, ModbusConfig& out, Diagnostics& d) {
  in_addr a{};
  if (!v.is_scalar() || inet_pton(AF_INET, v.scalar.c_str(), &a) != 1) {
    d.error(v.loc, "modbus bind: '" + v.scalar + "' is not an IPv4 address (write e.g. 127.0.0.1, or 0.0.0.0 for every interface)");
    return;
  }
  out.bind = v.scalar;
}

// A duration; 0 (written 0 or 0s) keeps idle connections open for ever.
void read_idle_timeout(const ConfigNode& v, ModbusConfig& out, Diagnostics& d) {
  if (v.is_scalar() && v.scalar == "0") {  // a bare 0 needs no unit here: it means never
    out.idle_timeout_ns = 0;
    return;
  }
  std::string err;
  auto ns = v.is_scalar() ? parse_duration_ns(v.scalar, &err) : std::nullopt;
  if (!ns) d.error(v.loc, "modbus idle_timeout: " + (err.empty() ? "expected a duration such as 60s" : err));
  else if (*ns < 0) d.error(v.loc, "modbus idle_timeout " + v.scalar + " is negative (0 means never)");
  else out.idle_timeout_ns = *ns;
}

void read_word_order(const ConfigNode& v, ModbusConfig& out, Diagnostics& d) {
  if (v.scalar == "high_first") out.word_order = WordOrder::HighFirst;
  else if (v.scalar == "low_first") out.word_order = WordOrder::LowFirst;
  else d.error(v.loc, "modbus word_order must be high_first or low_first, not '" + v.scalar + "'");
}

void read_allowed_clients(const ConfigNode& v, ModbusConfig& out, Diagnostics& d) {
  if (!v.is_list()) {
    d.error(v.loc, "modbus allowed_clients: expected a list of a.b.c.d or a.b.c.d/n");
    return;
  }
  // An empty list in ModbusConfig means "any client"; written in a file it
  // more likely means "nobody", so it is refused rather than guessed.
  if (v.items.empty()) {
    d.error(v.loc, "modbus allowed_clients: the list is empty (leave the key out to let any client in)");
    return;
  }
  for (const auto& i : v.items) {
    auto n = i.is_scalar() ? parse_client_network(i.scalar) : std::nullopt;
    if (!n)
      d.error(i.loc, "modbus allowed_clients: '" + i.scalar + "' is not an IPv4 address or network (a.b.c.d or a.b.c.d/n, n 0..32)");
    else out.allowed_clients.push_back(*n);
  }
}

// A list of CPU numbers (or one number) the server thread may run on.
void read_cpus(const ConfigNode& v, ModbusConfig& out, Diagnostics& d) {
  if (v.is_scalar()) {
    if (auto c = read_integer(v, "modbus cpus", 0, 1023, d)) out.cpus = {static_cast<int>(*c)};
    return;
  }
  if (!v.is_list() || v.items.empty()) {
    d.error(v.loc, "modbus cpus: expected a CPU number or a non-empty list of them, e.g. [0, 1]");
    return;
  }
  for (const auto& i : v.items)
    if (auto c = read_integer(i, "modbus cpus", 0, 1023, d)) out.cpus.push_back(static_cast<int>(*c));
}

std::optional<ModbusTable> table_by_key(const std::string& key) {
  for (auto t : {ModbusTable::Coils, ModbusTable::DiscreteInputs, ModbusTable::InputRegisters, ModbusTable::HoldingRegisters})
    if (modbus_table_key(t) == key) return t;
  return std::nullopt;
}

bool bit_table(ModbusTable t) { return t == ModbusTable::Coils || t == ModbusTable::DiscreteInputs; }

// BOOLs are coils or discrete inputs, everything else registers.
bool table_suits_type(const ConfigNode& v, ModbusTable t, const Tag& tag, Diagnostics& d) {
  const bool is_bool = tag.type == IecType::BOOL;
  if (bit_table(t) == is_bool) return true;
  d.error(v.loc, "tag " + tag.name + " is " + std::string(type_name(tag.type)) + ": its Modbus table must be " +
                     (is_bool ? "coil or discrete_input" : "input_register or holding_register") + ", not " + v.scalar);
  return false;
}

// Every element must fit below 65536: an array of n values of w registers takes n*w.
bool place_fits(const ConfigNode& v, const ModbusPlace& place, const Tag& tag, Diagnostics& d) {
  const std::uint64_t count = std::uint64_t{tag.length} * register_width(tag.type);
  if (place.address + count <= 65536) return true;
  const ModbusSpan span{place.table, place.address, static_cast<std::uint32_t>(count), true};
  d.error(v.loc, "modbus place of " + tag.name + ": " + modbus_span_text(span) + " run past 65535");
  return false;
}

std::string span_of(const Tag& tag, const ModbusSpan& span) {
  return modbus_span_text(span) + (span.explicit_place || !tag.address ? "" : " by " + tag.address->text());
}

}  // namespace

void read_modbus_section(const ConfigNode& n, ModbusConfig& out, Diagnostics& d) {
  out.declared = true;
  out.enabled = true;  // a modbus: section turns the server on unless it says enabled: false
  if (n.kind == ConfigNode::Kind::Null) return;  // `modbus:` alone: every default
  if (!n.is_map()) {
    d.error(n.loc, std::string("modbus: expected a map {") + kSectionKeys + "}");
    return;
  }
  for (const auto& [k, v] : n.map) {
    if (k == "enabled") read_flag(v, "modbus enabled", out.enabled, d);
    else if (k == "port") read_int_setting(v, "modbus port", 0, 65535, out.port, d);
    else if (k == "bind") read_bind(v, out, d);
    else if (k == "unit_id") read_int_setting(v, "modbus unit_id", 1, 247, out.unit_id, d);
    else if (k == "max_clients") read_int_setting(v, "modbus max_clients", 1, 4096, out.max_clients, d);
    else if (k == "idle_timeout") read_idle_timeout(v, out, d);
    else if (k == "word_order") read_word_order(v, out, d);
    else if (k == "allowed_clients") read_allowed_clients(v, out, d);
    else if (k == "read_only") read_flag(v, "modbus read_only", out.read_only, d);
    else if (k == "cpus") read_cpus(v, out, d);
    else if (k == "task_status") {
      if (v.is_scalar() && v.scalar == "none") out.task_status.reset();
      else if (auto c = read_integer(v, "modbus task_status", 0, 65535 - 8 * 64, d)) out.task_status = static_cast<std::uint32_t>(*c);
    }
    else if (k == "store_status") {
      if (v.is_scalar() && v.scalar == "none") out.store_status.reset();
      else if (auto c = read_integer(v, "modbus store_status", 0, 65535 - 8, d)) out.store_status = static_cast<std::uint32_t>(*c);
    }
    else d.error(v.loc, "unknown key '" + k + "' in modbus (" + kSectionKeys + ")");
  }
}

std::optional<ModbusPlace> read_modbus_place(const ConfigNode& n, const Tag& tag, Diagnostics& d) {
  if (!n.is_map()) {
    d.error(n.loc, "modbus of " + tag.name + ": expected a map {table, address}");
    return std::nullopt;
  }
  ModbusPlace place;
  const ConfigNode *table = nullptr, *address = nullptr;
  bool ok = true;
  for (const auto& [k, v] : n.map) {
    if (k == "table") table = &v;
    else if (k == "address") address = &v;
    else { d.error(v.loc, "unknown key '" + k + "' in a tag's modbus (table, address)"); ok = false; }
  }
  if (!table) { d.error(n.loc, "modbus of " + tag.name + " has no table (coil, discrete_input, input_register, holding_register)"); ok = false; }
  else if (auto t = table_by_key(table->scalar)) place.table = *t;
  else {
    d.error(table->loc, "modbus table must be coil, discrete_input, input_register or holding_register, not '" + table->scalar + "'");
    ok = false;
    table = nullptr;
  }
  if (!address) { d.error(n.loc, "modbus of " + tag.name + " has no address"); ok = false; }
  else if (auto a = read_integer(*address, "modbus address", 0, 65535, d)) place.address = static_cast<std::uint32_t>(*a);
  else { ok = false; address = nullptr; }
  if (tag.hmi == HmiAccess::None) {
    d.error(n.loc, "tag " + tag.name + " has a Modbus place but hmi none: give it hmi: read or readwrite");
    ok = false;
  }
  if (table && !table_suits_type(*table, place.table, tag, d)) ok = false;
  else if (table && address && !place_fits(*address, place, tag, d)) ok = false;
  if (!ok) return std::nullopt;
  return place;
}

void check_modbus_overlaps(const std::vector<Tag>& tags, const ModbusPlaces& places, const std::vector<SourceLoc>& place_loc,
                           Diagnostics& d) {
  std::vector<ModbusOverlap> overlaps;
  ModbusMap::build(tags, places, nullptr, &overlaps);
  for (const auto& o : overlaps) {
    // Two places by the convention overlap only where the tags' direct
    // addresses do, and that is reported at the address already.
    if (!o.span.explicit_place && !o.other_span.explicit_place) continue;
    // Blame the explicit place (the later one if both are): that is what the author chose.
    const bool blame_tag = o.span.explicit_place;
    const std::uint32_t blamed = blame_tag ? o.tag : o.other, named = blame_tag ? o.other : o.tag;
    const ModbusSpan& blamed_span = blame_tag ? o.span : o.other_span;
    const ModbusSpan& named_span = blame_tag ? o.other_span : o.span;
    const Tag& b = tags[blamed];
    const Tag& n = tags[named];
    d.error(place_loc[blamed], "modbus place of " + b.name + " (" + span_of(b, blamed_span) + ") overlaps " + n.name + " (" +
                                   span_of(n, named_span) + ", defined at " + n.loc.text() + ")");
  }
}

std::vector<std::size_t> largest_modbus_writes(const std::vector<Tag>& tags, const ModbusPlaces& places, std::size_t tasks) {
  constexpr std::size_t kMaxWriteCoils = 1968, kMaxWriteRegisters = 123;  // FC 15, FC 16 (Modbus V1.1b3 §6.11, §6.12)
  const ModbusMap map = ModbusMap::build(tags, places);
  std::vector<std::size_t> coils(tasks, 0), registers(tasks, 0);
  for (const auto& pt : map.points(ModbusTable::Coils))
    if (pt.writable && pt.owner < tasks) ++coils[pt.owner];  // no owner when the tasks failed to load
  for (const auto& pt : map.points(ModbusTable::HoldingRegisters))
    if (pt.writable && pt.owner < tasks) ++registers[pt.owner];
  std::vector<std::size_t> most(tasks);
  for (std::size_t t = 0; t < tasks; ++t)
    most[t] = std::max(std::min(coils[t], kMaxWriteCoils), std::min(registers[t], kMaxWriteRegisters));
  return most;
}

}  // namespace syncplc
