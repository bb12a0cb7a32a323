// The I/O driver interface. A driver owns a set of channels (inputs to the
// PLC, outputs from it); the project binds channels to tags, and the driver's
// task calls latch_inputs() at the start and write_outputs() at the end of
// every scan. Both run on the scan path: they copy between the process image
// and the driver's own buffers and never block. A driver may run its own
// threads for the real exchange (fieldbus, network), handing data over
// through lock-free buffers.
#pragma once

#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "runtime/core/block.hpp"
#include "runtime/core/config_node.hpp"

namespace syncplc {

// The in-process network the nodes of one simulated system share in virtual
// time (runtime/io/dds/virtual_bus.hpp); the core only passes it along.
class VirtualBus;

// One element of an output channel and the value it takes in the safe state
// (the `safe:` value of the tag bound to the channel).
struct SafeOutput {
  int channel = 0;
  std::uint32_t element = 0;
  Cell value;
};

struct DriverChannel {
  std::string name;
  PinDir dir = PinDir::In;  // In: read by the PLC (sensor); Out: written by the PLC (actuator)
  IecType type = IecType::LREAL;
  std::uint32_t length = 1;  // cells
  std::string unit;
  std::string doc;
};

class IoDriver {
 public:
  virtual ~IoDriver() = default;
  const std::string& name() const { return name_; }
  void set_name(std::string n) { name_ = std::move(n); }

  virtual const std::vector<DriverChannel>& channels() const = 0;
  // At load: cells[i] is the process-image cell bound to channel i (first of
  // `length` cells), or nullptr when the project leaves the channel unbound.
  virtual void bind(const std::vector<Cell*>& cells) = 0;
  // Before the first scan; may start threads. False with *error on failure.
  virtual bool open(std::string* error) = 0;
  virtual void latch_inputs(const ScanContext& ctx) noexcept = 0;
  virtual void write_outputs(const ScanContext& ctx) noexcept = 0;
  // After the last scan; joins the driver's threads.
  virtual void close() noexcept = 0;
  // The supervisor's path to the outputs when the task's scan does not end
  // (runtime/core/supervisor.hpp). Called from a non-real-time thread while
  // the task's thread may be inside latch_inputs, write_outputs or a block,
  // or stuck there for good. Drives the listed output elements to their
  // values (the others keep the last value written) and holds the outputs:
  // write_outputs changes nothing after it until the driver is opened again,
  // so a scan that ends late cannot undo the safe state. It may wait for a
  // write_outputs already under way (bounded, never for the scan itself) and
  // never blocks the scan thread. False when the outputs could not be reached.
  virtual bool write_safe_outputs(const SafeOutput* outputs, std::size_t n) noexcept = 0;
  // A clean stop of the PLC (a signal, --duration's end; not an online
  // change), after the last scan and before close(): `outputs` are the
  // `safe:` values of the tags bound to the driver's outputs, as for
  // write_safe_outputs. A driver whose settings ask for it (modbus_client's
  // `at_stop: safe`) drives its outputs to them and waits, bounded, until its
  // devices have taken them. The default keeps the outputs at their last
  // values (CODESYS's "keep current values").
  virtual void stop_outputs(const SafeOutput* /*outputs*/, std::size_t /*n*/) noexcept {}
  // Online change (runtime/cli/reload.cpp): this driver replaces `previous`
  // (a driver of the running program, closed after the switch). Before
  // open(), will_take_over says so: a driver that can take over what
  // `previous` holds open (modbus_client: the TCP connection of a device at
  // the same address and port) waits for it instead of opening its own;
  // after the switch and before previous.close(), take_over hands it over.
  virtual void will_take_over(IoDriver& /*previous*/) {}
  virtual void take_over(IoDriver& /*previous*/) noexcept {}

  // Tests and simulations: set an input channel from outside the scan (taken
  // at the next latch). Returns false when the driver does not support it.
  virtual bool force_input(int /*channel*/, const Cell* /*values*/) { return false; }
  // Readers of live values (the HTTP API's quality, not the scan): whether
  // the values the newest latch_inputs put into input channel `channel` came
  // from a good exchange with the device. A driver with a link to lose
  // (modbus_client: the channel's read group, ok as its `ok` status channel
  // says) answers for it; a status channel reports and is always ok. The
  // default: a driver without a link (memory, simulations) is always ok.
  virtual bool input_ok(int /*channel*/) const noexcept { return true; }
  // Tests and status display: the value last written to an output channel.
  virtual bool read_output(int /*channel*/, Cell* /*values*/) const { return false; }
  // One line for `syncplc check` (bus time, model, ...); "" for nothing. Not on the scan path.
  virtual std::string summary() const { return {}; }
  // Named counters for reports and metrics (frames sent, lost ...). Not on the scan path.
  virtual std::vector<std::pair<std::string, double>> counters() const { return {}; }

 private:
  std::string name_;
};

// What a driver factory gets at load time.
class DriverSetup {
 public:
  virtual ~DriverSetup() = default;
  virtual std::int64_t task_period_ns() const = 0;
  virtual std::uint64_t seed() const = 0;
  virtual void error(const SourceLoc& where, const std::string& message) = 0;
  // Virtual time (`syncplc sim`, `syncplc test`): a driver whose link goes
  // to other nodes (dds) uses its simulated counterpart instead, on bus()
  // when the nodes of a system share one (nullptr: a bus of its own).
  virtual bool virtual_time() const { return false; }
  virtual std::shared_ptr<VirtualBus> bus() const { return nullptr; }
};

struct DriverTypeInfo {
  std::string name;
  std::string doc;
  // `config` is the driver's whole entry of the project file.
  std::function<std::unique_ptr<IoDriver>(const ConfigNode& config, DriverSetup& setup)> create;
};

class DriverRegistry {
 public:
  void add(DriverTypeInfo info) { types_[info.name] = std::move(info); }
  const DriverTypeInfo* find(const std::string& name) const {
    auto it = types_.find(name);
    return it == types_.end() ? nullptr : &it->second;
  }
  std::vector<std::string> names() const {
    std::vector<std::string> v;
    for (const auto& [k, _] : types_) v.push_back(k);
    return v;
  }

 private:
  std::map<std::string, DriverTypeInfo> types_;
};

}  // namespace syncplc
