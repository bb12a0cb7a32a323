// The Modbus TCP client driver (`type: modbus_client`): remote devices and
// cyclic request groups (reads FC 1-4, writes FC 5, 6, 15, 16, read/write
// FC 23) bound to tags through the driver's channels. docs/modbus-client.md
// describes the keys, the status channels, staleness and the reactions.
//
// Channels, per request group g:
//   g            in (reads) or out (writes): the values, ARRAY of count
//   g_write      out, FC 23 only: the values written (g is the read side)
//   g_ok         in BOOL    the last exchange succeeded
//   g_age        in LREAL ms since the last successful exchange completed
//   g_cycles     in UDINT   scans since the request of the values shown was
//                           handed over: 0 = the reply to this cycle's request
//   g_error      in UINT    the last error (client_error.hpp), 0 when ok
//   g_reaction   in BOOL    stale past stale_after: the reaction applies
//   g_requests, g_errors, g_timeouts, g_reconnects   in UDINT counters
//
// counters() adds, per group, requests/s over the time open and the round
// trip in µs (p50, p99, max): `reply` from sending the request to its reply,
// `latched` from sending it to the scan that latched the reply; per device
// its requests/s.
//
// Threads: one per device (device_link.hpp); the scan only copies from and
// to the hand-over buffers (group_handover.hpp) and reads atomics.
#pragma once

#include <atomic>
#include <cstdint>
#include <memory>
#include <vector>

#include "runtime/core/io_driver.hpp"
#include "runtime/io/modbus_client/client_config.hpp"
#include "runtime/io/modbus_client/device_link.hpp"
#include "runtime/io/modbus_client/group_handover.hpp"
#include "runtime/io/modbus_client/group_latch.hpp"
#include "runtime/io/safe_output_latch.hpp"

namespace syncplc {

class ModbusClientDriver final : public IoDriver {
 public:
  using Clock = DeviceLink::Clock;
  explicit ModbusClientDriver(ModbusClientConfig cfg);
  ~ModbusClientDriver() override { close(); }

  const std::vector<DriverChannel>& channels() const override { return channels_; }
  void bind(const std::vector<Cell*>& cells) override { bound_ = cells; }
  bool open(std::string* error) override;
  void latch_inputs(const ScanContext& ctx) noexcept override;
  void write_outputs(const ScanContext& ctx) noexcept override;
  void close() noexcept override;
  bool write_safe_outputs(const SafeOutput* outputs, std::size_t n) noexcept override;
  // at_stop safe: the safe outputs sent once more, waiting for every write
  // group's device to acknowledge them, each group at most its own device's
  // connect_timeout + (its groups + 1) x response_timeout (devices in
  // parallel; a dead device never holds the stop longer than its own bound).
  void stop_outputs(const SafeOutput* outputs, std::size_t n) noexcept override;
  // Online change: a device of `previous` at the same address and port (the
  // unit id is per request, not per connection) hands its open connection
  // over: this driver's link for it does not connect at open() but waits,
  // and take_over() moves the socket after the switch. Its groups show "no
  // reply yet" (268, not stale) until then.
  void will_take_over(IoDriver& previous) override;
  void take_over(IoDriver& previous) noexcept override;
  bool read_output(int channel, Cell* values) const override;
  // A read group's values channel: its group's ok at the newest latch.
  bool input_ok(int channel) const noexcept override;
  std::string summary() const override;
  std::vector<std::pair<std::string, double>> counters() const override;

  const ModbusClientConfig& config() const { return cfg_; }
  // The hand-over state of a fresh exchange: results, outputs, counters,
  // the values shown before the first reply (constructor and open()).
  void reset_exchange();
  int channel_index(const std::string& name) const;

  // --- tests: the exchange replaced by the test -----------------------------------
  // Before open(): the clock of stamps, ages and stale times (default monotonic_ns).
  void set_clock(Clock c) { clock_ = c; }
  // Before open(): no device threads; the test publishes results itself.
  void set_network(bool on) { network_ = on; }
  // Without network: a result of group g as its device thread would publish it
  // (`sent`: when its request went out; by default at `stamp`).
  // epoch: the connection it came on (the write gate); cycle: the hand-over
  // count its request was sent at (-1: the count now).
  void inject(std::size_t g, std::uint16_t error, std::int64_t stamp, const Cell* values, std::int64_t sent = -1,
              std::uint64_t epoch = 1, std::int64_t cycle = -1);
  // Without network: the epoch the newest outputs handed over for group g
  // carry (GroupHandover::kAnyEpoch: no reads to wait for).
  std::uint64_t handed_over_epoch(std::size_t g);
  // at_stop safe: how long the stop waits for device d at most.
  std::int64_t stop_bound_ns(std::size_t d) const;
  // Without network: the newest outputs handed over for group g (nullptr before any).
  const Cell* handed_over(std::size_t g);

 private:
  void hand_over_to_devices() noexcept;
  struct GroupChannels {
    int values = -1, write = -1, ok = -1, age = -1, cycles = -1, error = -1, reaction = -1;
    int requests = -1, errors = -1, timeouts = -1, reconnects = -1;
  };
  ModbusClientConfig cfg_;
  std::vector<DriverChannel> channels_;
  std::vector<GroupChannels> gch_;
  std::vector<Cell*> bound_;
  std::vector<std::unique_ptr<GroupHandover>> handover_;
  CycleSignal cycle_;  // the scans' hand-overs to the device threads (timing cycle); declared before links_, which use it
  std::vector<std::unique_ptr<DeviceLink>> links_;
  std::vector<GroupLatch> latch_;
  std::vector<std::vector<Cell>> values_;  // per group: the read values the scan shows (last good)
  std::vector<std::vector<Cell>> out_;     // per group: the outputs last handed over
  std::vector<std::uint64_t> out_seq_;
  std::vector<const DeviceLink*> group_link_;     // per group: its device's link (null without network), set by open()
  std::vector<std::uint64_t> closed_reconnects_;  // per device: its reconnections when the links were closed
  std::vector<std::int8_t> at_stop_;  // per group: -1 nothing sent at stop, 0 sent but not acknowledged, 1 acknowledged
  std::vector<bool> inherit_;  // per device: its connection comes from the driver this one replaces (will_take_over)
  std::vector<bool> device_reads_;             // per device: it has a reading group (the write gate applies)
  std::vector<std::uint64_t> device_epoch_;    // per device: the connection every reading group latched good values of, 0: none
  std::vector<int> channel_group_;             // per channel: the read group whose values it carries, -1: none
  std::unique_ptr<std::atomic<bool>[]> group_ok_;  // per group: ok at the newest latch (input_ok, other threads)
  Clock clock_;
  bool network_ = true;
  bool open_ = false;
  std::int64_t opened_ns_ = 0, closed_ns_ = 0;  // the driver clock: the span of requests/s
  SafeOutputLatch safe_;
};

DriverTypeInfo modbus_client_driver_type();

}  // namespace syncplc
