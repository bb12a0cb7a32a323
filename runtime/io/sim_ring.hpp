// The simulated real-time ring of paper 000 §4.1 and Fig. 2, as an I/O
// driver: the master sends one lumped frame per cycle; in frame k it carries
// x_d(k+1) for every axis, and each node i reads its command and writes its
// feedback error e_i(k) into the frame as it passes. Node k sees the errors of
// nodes 1..k-1 from the previous frame, so D_ik = T_s (eq. (13)); every node
// buffers its command for one period, so all act on the same cycle (the
// deferred actuation itself is the table's actuation_delay).
//
// In the PLC the exchange is one scan: what the program writes at the end of
// scan k (master_cmd, err_tx) is frame k; what it latches at the start of scan
// k+1 (cmd, node<k>_err) is what the nodes received from frame k.
//
// Frames are lost per frame (every node misses it) or per link (a lost link
// cuts off every node after it), Bernoulli or Gilbert-Elliott, and arrive
// late with a probability; the receiver then gets valid = FALSE and the value
// of the last frame it did receive. All draws come from the driver's seed.
//
// Safe outputs written by the supervisor (write_safe_outputs) make up one
// last frame, the last one sent with the safe values in place, that every
// node receives at the next latch; the program's frames stop until the
// driver is opened again.
//
// Channels, n = nodes:
//   master_cmd        out  ARRAY[1..n*w] OF LREAL  x_d(k+1) for every axis, w words an axis
//                                                  (command_words: 1 = position; 3 = position,
//                                                  velocity, acceleration), axis after axis
//   err_tx            out  ARRAY[1..n] OF LREAL  element i: e_i(k) written by node i
//   cmd               in   ARRAY[1..n*w] OF LREAL  the words of axis i: the command node i received
//   cmd_valid         in   ARRAY[1..n] OF BOOL
//   node<k>_err       in   ARRAY[1..n] OF LREAL  node k's copy of e_1..e_{k-1} (elements >= k are 0)
//   node<k>_err_valid in   ARRAY[1..n] OF BOOL
//   frames_sent, frames_lost, frames_late  in ULINT
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "runtime/core/io_driver.hpp"
#include "runtime/io/bus_timing.hpp"
#include "runtime/io/loss_model.hpp"
#include "runtime/io/safe_output_latch.hpp"

namespace syncplc {

struct SimRingConfig {
  std::uint32_t nodes = 4;
  std::uint32_t command_words = 1;  // LREALs of command per axis in the frame
  LossConfig loss;
  bool per_link = false;  // loss scope: false = per frame, true = per link
  double late = 0;        // probability that a frame misses the nodes' deadline
  std::uint64_t seed = 1;
  std::string bus_summary;  // one line for `syncplc check`
};

class SimRingDriver final : public IoDriver {
 public:
  explicit SimRingDriver(SimRingConfig cfg);

  const std::vector<DriverChannel>& channels() const override { return channels_; }
  void bind(const std::vector<Cell*>& cells) override { bound_ = cells; }
  bool open(std::string*) override;
  void latch_inputs(const ScanContext& ctx) noexcept override;
  void write_outputs(const ScanContext& ctx) noexcept override;
  void close() noexcept override {}
  bool write_safe_outputs(const SafeOutput* outputs, std::size_t n) noexcept override;
  std::string summary() const override { return cfg_.bus_summary; }
  std::vector<std::pair<std::string, double>> counters() const override;

  std::uint64_t sent() const { return sent_; }
  std::uint64_t lost() const { return lost_; }
  std::uint64_t late() const { return late_; }
  // Whether node i (0-based) received the last frame sent.
  bool received(std::uint32_t node) const { return received_[node] != 0; }

  static constexpr int kMasterCmd = 0, kErrTx = 1, kCmd = 2, kCmdValid = 3;
  int node_err_channel(std::uint32_t node) const { return 4 + 2 * static_cast<int>(node); }
  int counter_channel() const { return 4 + 2 * static_cast<int>(cfg_.nodes); }

 private:
  SimRingConfig cfg_;
  std::vector<DriverChannel> channels_;
  std::vector<Cell*> bound_;
  SimRandom rng_;
  LossProcess frame_loss_;
  std::vector<LossProcess> link_loss_;
  std::vector<double> frame_cmd_, frame_err_;  // the frame in flight
  std::vector<std::uint8_t> received_;         // per node, for the frame in flight
  std::vector<double> held_cmd_;               // per node: last command received
  std::vector<double> held_err_;               // node-major n x n: last errors received
  bool frame_pending_ = false;
  std::uint64_t sent_ = 0, lost_ = 0, late_ = 0;
  // The safe frame: written by the supervisor, sent by the next latch.
  SafeOutputLatch safe_;
  std::vector<double> safe_cmd_, safe_err_;
  std::atomic<bool> safe_ready_{false};
  bool safe_sent_ = false;  // scan thread
};

DriverTypeInfo sim_ring_driver_type();

}  // namespace syncplc
