// What a project says about its Modbus TCP server (the `modbus:` section and
// a tag's `modbus:` key): plain data, filled by the loader (runtime/project),
// read by the server. The core's Program knows nothing of Modbus.
// docs/modbus.md describes every field.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace syncplc {

enum class ModbusTable : std::uint8_t { Coils, DiscreteInputs, InputRegisters, HoldingRegisters };
std::string_view modbus_table_name(ModbusTable t);  // "coil", "discrete input", ...
std::string_view modbus_table_key(ModbusTable t);   // the project-file spelling: coil, discrete_input, ...

// Word order of 32- and 64-bit values: high word first (big-endian words, the
// default) or low word first (swapped). Each register is big-endian on the wire.
enum class WordOrder : std::uint8_t { HighFirst, LowFirst };
std::string_view word_order_key(WordOrder o);  // high_first, low_first

// An IPv4 network a client must come from: address and prefix length (32 for one host).
struct ClientNetwork {
  std::uint32_t address = 0;  // host byte order
  int prefix = 32;
  bool contains(std::uint32_t host_order_address) const {
    if (prefix <= 0) return true;
    const std::uint32_t mask = prefix >= 32 ? 0xFFFFFFFFu : ~(0xFFFFFFFFu >> prefix);
    return (host_order_address & mask) == (address & mask);
  }
};

// "a.b.c.d" (one host, prefix 32) or "a.b.c.d/n" with n 0..32; nullopt otherwise.
std::optional<ClientNetwork> parse_client_network(std::string_view text);
std::string client_network_text(const ClientNetwork& n);  // a.b.c.d or a.b.c.d/n

struct ModbusConfig {
  bool enabled = false;            // a project without a `modbus:` section runs no server
  bool declared = false;           // the project has a `modbus:` section (so check can say why the server is off)
  int port = 5020;                 // 0: any free port (the chosen one is printed at start)
  std::string bind = "127.0.0.1";  // IPv4 address to listen on; 0.0.0.0 for every interface
  int unit_id = 1;                 // 1..247; requests to unit 0 or 255 are also answered
  int max_clients = 64;            // connections at once; more are accepted and closed at once
  std::int64_t idle_timeout_ns = 60'000'000'000;  // a connection silent this long is closed; 0: never
  WordOrder word_order = WordOrder::HighFirst;
  std::vector<ClientNetwork> allowed_clients;  // empty: any client
  bool read_only = false;          // every write answers exception 02
  // CPUs the server thread may run on (empty: any). Keeping it, and the NIC's
  // interrupts, off the CPUs of the real-time tasks keeps its work out of their
  // start jitter (docs/benchmarks.md, section 5).
  std::vector<int> cpus;
  // First input register of the task status block (docs/modbus.md, "Task
  // status"): eight registers per task, in task order. nullopt: not served.
  std::optional<std::uint32_t> task_status = 9000;
  // First input register of the store status block (docs/modbus.md, "Store
  // status"): eight registers. nullopt: not served.
  std::optional<std::uint32_t> store_status = 8990;
};

// The settings on one line, as `syncplc check` prints them:
// "127.0.0.1:5020, unit 1, max 64 clients, idle timeout 60s, high word first, read/write, clients: any".
std::string modbus_settings_text(const ModbusConfig& c);

// A tag's explicit place on Modbus (`modbus: {table: holding_register, address: 3000}`),
// which takes precedence over the place its direct address gives.
struct ModbusPlace {
  ModbusTable table = ModbusTable::HoldingRegisters;
  std::uint32_t address = 0;  // 0..65535: the first coil or register
};

// Each tag's explicit place, indexed like Program::tags (nullopt, or an index
// past the end: the place its direct address gives, if any).
using ModbusPlaces = std::vector<std::optional<ModbusPlace>>;
inline const ModbusPlace* explicit_place(const ModbusPlaces& places, std::size_t tag) {
  return tag < places.size() && places[tag] ? &*places[tag] : nullptr;
}

// Everything a project says about Modbus.
struct ModbusSettings {
  ModbusConfig server;
  ModbusPlaces places;
};

}  // namespace syncplc
