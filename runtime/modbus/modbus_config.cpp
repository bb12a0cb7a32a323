#include "runtime/modbus/modbus_config.hpp"

#include <arpa/inet.h>

#include "runtime/core/iec_type.hpp"

namespace syncplc {

std::string_view modbus_table_name(ModbusTable t) {
  switch (t) {
    case ModbusTable::Coils: return "coil";
    case ModbusTable::DiscreteInputs: return "discrete input";
    case ModbusTable::InputRegisters: return "input register";
    case ModbusTable::HoldingRegisters: return "holding register";
  }
  return "?";
}

std::string_view modbus_table_key(ModbusTable t) {
  switch (t) {
    case ModbusTable::Coils: return "coil";
    case ModbusTable::DiscreteInputs: return "discrete_input";
    case ModbusTable::InputRegisters: return "input_register";
    case ModbusTable::HoldingRegisters: return "holding_register";
  }
  return "?";
}

std::string_view word_order_key(WordOrder o) { return o == WordOrder::HighFirst ? "high_first" : "low_first"; }

std::optional<ClientNetwork> parse_client_network(std::string_view text) {
  const auto slash = text.find('/');
  const std::string host(text.substr(0, slash));
  in_addr a{};
  if (inet_pton(AF_INET, host.c_str(), &a) != 1) return std::nullopt;
  ClientNetwork n;
  n.address = ntohl(a.s_addr);
  if (slash == std::string_view::npos) return n;
  const std::string_view bits = text.substr(slash + 1);
  if (bits.empty() || bits.size() > 2) return std::nullopt;
  int prefix = 0;
  for (char c : bits) {
    if (c < '0' || c > '9') return std::nullopt;
    prefix = prefix * 10 + (c - '0');
  }
  if (prefix > 32) return std::nullopt;
  n.prefix = prefix;
  return n;
}

std::string client_network_text(const ClientNetwork& n) {
  std::string s;
  for (int shift = 24; shift >= 0; shift -= 8)
    s += std::to_string((n.address >> shift) & 0xFF) + (shift ? "." : "");
  return n.prefix == 32 ? s : s + "/" + std::to_string(n.prefix);
}

namespace {

// Idle timeouts are minutes at most in practice; whole seconds read best as
// seconds ("60s", not format_duration's "1m").
std::string idle_timeout_text(std::int64_t ns) {
  if (ns == 0) return "no idle timeout";
  if (ns % 1'000'000'000 == 0) return "idle timeout " + std::to_string(ns / 1'000'000'000) + "s";
  return "idle timeout " + format_duration(ns);
}

}  // namespace

std::string modbus_settings_text(const ModbusConfig& c) {
  std::string cpus;
  for (int cpu : c.cpus) cpus += (cpus.empty() ? ", on CPU " : ",") + std::to_string(cpu);
  std::string clients;
  for (const auto& n : c.allowed_clients) clients += (clients.empty() ? "" : ", ") + client_network_text(n);
  return c.bind + ":" + std::to_string(c.port) + (c.port == 0 ? " (any free port)" : "") + ", unit " +
         std::to_string(c.unit_id) + ", max " + std::to_string(c.max_clients) + (c.max_clients == 1 ? " client" : " clients") +
         ", " + idle_timeout_text(c.idle_timeout_ns) + ", " +
         (c.word_order == WordOrder::HighFirst ? "high word first" : "low word first") + ", " +
         (c.read_only ? "read only" : "read/write") + ", clients: " + (clients.empty() ? "any" : clients) + cpus;
}

}  // namespace syncplc
