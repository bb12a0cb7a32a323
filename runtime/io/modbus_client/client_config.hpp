// What a `modbus_client` driver entry says, as plain data: the remote
// devices and the cyclic request groups bound to the driver's channels
// (docs/modbus-client.md). read_modbus_client_config reports every problem
// with its file:line:col through DriverSetup::error and returns nullopt when
// there was one.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "runtime/core/io_driver.hpp"
#include "runtime/io/modbus_client/client_frame.hpp"
#include "runtime/modbus/modbus_config.hpp"
#include "runtime/modbus/register_codec.hpp"

namespace syncplc {

// What a group does once its data has been stale for `stale_after`.
enum class StaleReaction : std::uint8_t {
  Hold,  // inputs keep their last value (flagged: ok FALSE, reaction TRUE)
  Safe,  // inputs take the group's safe values
  Stop,  // the task stops with its safe outputs (ScanContext::request_stop)
};
std::string_view stale_reaction_key(StaleReaction r);  // hold, safe, stop

// When a device's exchanges run (docs/modbus-client.md, "Threads and timing").
enum class ExchangeTiming : std::uint8_t {
  Cycle,  // right after each scan's hand-over of its outputs: writes, then reads, in one burst
  Free,   // on the device thread's own grid, free-running against the task's scans
};

struct ClientDevice {
  std::string name;
  std::string host = "127.0.0.1";
  std::string address;            // host as a numeric IPv4 address, resolved once by open() (never on the device thread)
  std::uint16_t port = 502;
  std::uint8_t unit = 1;
  std::int64_t response_timeout_ns = 200'000'000;
  std::int64_t connect_timeout_ns = 1'000'000'000;
  std::int64_t reconnect_min_ns = 100'000'000;  // back-off after the first failure, doubled up to reconnect_max
  std::int64_t reconnect_max_ns = 5'000'000'000;
  WordOrder word_order = WordOrder::HighFirst;
  StaleReaction reaction = StaleReaction::Hold;
  std::int64_t stale_after_ns = 0;
  ExchangeTiming timing = ExchangeTiming::Cycle;
  std::int64_t task_period_ns = 0;  // the driver's task's period (timing cycle: the hand-overs' rate)
};

// How a group's values map to registers or coils.
struct ValueFormat {
  IecType wire = IecType::INT;     // the type in the device's registers (BOOL for coils)
  WordOrder order = WordOrder::HighFirst;
  bool scaled = false;             // scale/offset given: the channel is LREAL, value = raw * scale + offset
  double scale = 1, offset = 0;
  IecType channel() const { return scaled ? IecType::LREAL : wire; }
  std::uint32_t width() const { return wire == IecType::BOOL ? 1 : register_width(wire); }  // registers (or coils) a value takes
};

struct RequestGroup {
  std::string name;
  std::size_t device = 0;
  ModbusFunction function = ModbusFunction::ReadHoldingRegisters;
  std::uint16_t address = 0;       // first coil/register: the read side, or the write side for 5, 6, 15, 16
  std::uint32_t count = 1;         // values (elements of the channel)
  std::uint16_t write_address = 0; // 23 only: the write side
  std::uint32_t write_count = 0;   // 23 only: values written
  ValueFormat format;
  std::string unit;
  std::int64_t interval_ns = 0;    // every: scan (the task's period) or a duration
  bool every_scan = true;          // every: scan (timing cycle: at every hand-over)
  bool on_change = false;          // writes: only when the values differ from the last acknowledged write
  std::int64_t alive_every_ns = 1'000'000'000;  // on_change: the same values again after this long without a write (0: never)
  StaleReaction reaction = StaleReaction::Hold;
  std::int64_t stale_after_ns = 0;
  std::vector<Cell> safe;          // read values on reaction safe, one per element (channel type)

  bool reads() const { return function_reads(function); }
  bool writes() const { return function_writes(function); }
  std::uint32_t read_values() const { return reads() ? count : 0; }
  std::uint32_t written_values() const {
    return function == ModbusFunction::ReadWriteMultipleRegisters ? write_count : (writes() ? count : 0);
  }
};

struct ModbusClientConfig {
  std::vector<ClientDevice> devices;
  std::vector<RequestGroup> groups;
  // at_stop: at a clean stop of the PLC the write groups send their outputs'
  // safe values once more and the driver waits for the devices to take them
  // (true, `safe`), or the devices keep the last values written (`keep`).
  bool safe_at_stop = false;
};

std::optional<ModbusClientConfig> read_modbus_client_config(const ConfigNode& entry, DriverSetup& setup);

}  // namespace syncplc
