// The hand-over between a request group's device thread and its task's scan,
// lock-free both ways (runtime/core/triple_buffer.hpp, one producer and one
// consumer each):
//
//   results  device thread -> latch_inputs: the newest completed exchange,
//            cells [seq, error, stamp, sent, epoch, cycle, read values...]
//            (stamp: the exchange completed, sent: its request was sent,
//            epoch: the device's connection it ran on, cycle: the scans'
//            hand-over count when its request was sent); the latch takes the
//            newest whole one and never waits for an exchange under way.
//   outputs  write_outputs -> device thread: the newest values to write,
//            cells [seq, epoch, values...]; the device thread writes the
//            newest it finds when the group is due, and only when `epoch` is
//            its connection's: the scan that computed them had latched good
//            reads of every reading group of the device on this connection
//            (kAnyEpoch: values that need none, a device without reads or the
//            safe values).
//
// The counters are atomics the scan reads for the status channels and
// `syncplc run` for IoDriver::counters. The round-trip histograms have one
// writer each: `reply` the device thread (request sent -> reply in), `latched`
// the scan (request sent -> its reply latched by latch_inputs, what the
// program sees). The rest is the device thread's.
#pragma once

#include <algorithm>
#include <atomic>
#include <cstdint>
#include <vector>

#include "runtime/core/histogram.hpp"
#include "runtime/core/triple_buffer.hpp"
#include "runtime/io/modbus_client/client_config.hpp"

namespace syncplc {

struct GroupHandover {
  static constexpr std::size_t kSeq = 0, kError = 1, kStamp = 2, kSent = 3, kEpoch = 4, kCycle = 5,
                               kValues = 6;                       // results cells
  static constexpr std::size_t kOutEpoch = 1, kOutValues = 2;    // outputs cells
  static constexpr std::uint64_t kAnyEpoch = ~std::uint64_t{0};  // outputs any connection may carry

  explicit GroupHandover(const RequestGroup& g)
      : group(&g), results(kValues + g.read_values()), outputs(kOutValues + g.written_values()) {
    read.assign(g.read_values(), Cell{});
    written.assign(g.written_values(), Cell{});
    regs.assign(std::max(g.count, g.write_count) * g.format.width(), 0);
    bits.assign(g.count, 0);
  }

  // Device thread: one completed exchange (or failure), stamped with the
  // driver's clock; `sent` when its request went out (a failure to connect
  // sent none: the stamp).
  void publish(std::uint16_t error, std::int64_t stamp, const Cell* values, std::int64_t sent, std::uint64_t epoch,
               std::uint32_t cycle) noexcept {
    Cell* b = results.back();
    b[kSeq].set<std::uint64_t>(++seq);
    b[kError].set<std::uint16_t>(error);
    b[kStamp].set<std::int64_t>(stamp);
    b[kSent].set<std::int64_t>(sent);
    b[kEpoch].set<std::uint64_t>(epoch);
    b[kCycle].set<std::uint32_t>(cycle);
    if (!error) reply.record(stamp - sent);
    if (values && !read.empty()) std::copy(values, values + read.size(), b + kValues);
    results.publish();
    // errors: exchanges and connection attempts that failed; a group that
    // did not even try (another group's failure closed the connection) is
    // counted apart, in not_connected.
    if (error == code(ClientError::NotConnected)) not_connected.fetch_add(1, std::memory_order_relaxed);
    else if (error) errors.fetch_add(1, std::memory_order_relaxed);
    if (error == code(ClientError::Timeout)) timeouts.fetch_add(1, std::memory_order_relaxed);
  }

  const RequestGroup* group;
  TripleBuffer results;
  TripleBuffer outputs;
  std::atomic<std::uint64_t> requests{0}, errors{0}, timeouts{0}, not_connected{0};
  std::atomic<std::uint64_t> acked{0};  // seq of the newest outputs the device has (acknowledged, or equal to those it acknowledged)
  Histogram reply;    // ns, successful exchanges: request sent -> reply in (device thread)
  Histogram latched;  // ns, request sent -> reply latched by a scan (latch_inputs)

  // --- the device thread's ---
  std::uint64_t seq = 0;
  std::int64_t next_due = 0;
  std::vector<Cell> read;            // decoded read values
  std::vector<Cell> written;         // the values last acknowledged by the device
  bool have_written = false;
  std::int64_t written_ns = 0;      // monotonic: the last write was sent (on_change's alive_every)
  std::vector<std::uint16_t> regs;   // encoded registers to write
  std::vector<std::uint8_t> bits;    // coils to write
};

}  // namespace syncplc
