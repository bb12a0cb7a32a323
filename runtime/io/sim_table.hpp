// The simulated multi-axis table: n axes (4 by default), each the DC-motor
// plant of paper 000 eq. (25) with the paper's parameters (section 5.1), as an
// I/O driver. A project switches between this table and real drives by
// changing the driver entry, not the program.
//
// Channels (n elements each):
//   cmd      out  PWM    the drive commands written by the PLC
//   pos      in   rad    measured positions (optionally encoder-quantised, noisy)
//   vel      in   rad/s  velocities as a drive reports them (noise-free model value)
//   applied  in   PWM    the input each motor received last period: saturated
//                        command plus the scheduled disturbance and the load
//   load     out  PWM    a load the program applies, added to the motor input
//                        beyond the drive's limit, from the same instant as
//                        the command: a disturbance on a schedule the program
//                        knows and the driver does not (another node's time)
//
// Timing: at the start of the scan released at t_k the plant is advanced from
// t_{k-1} to t_k and sampled. The commands written at the end of that scan
// take effect at t_k + actuation_delay on every axis at once (paper 000
// §4.1's deferred actuation), held constant until replaced (zero-order hold).
// Safe commands written by the supervisor (write_safe_outputs) act from the
// next latch on, without delay, and stay until the driver is opened again.
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include "runtime/core/io_driver.hpp"
#include "runtime/io/axis_plant.hpp"
#include "runtime/io/safe_output_latch.hpp"
#include "runtime/core/sim_random.hpp"

namespace syncplc {

struct Disturbance {
  std::uint32_t axis = 0;  // 0-based
  std::int64_t from_ns = 0, to_ns = 0;
  double value = 0;  // PWM, added to the motor input
};

struct SimTableConfig {
  std::vector<AxisModel> axes;
  double saturation = 1.0;        // |command| limit, PWM
  std::vector<double> position0;  // rad
  std::uint32_t encoder_lines = 0;  // lines per revolution, counted 4x (quadrature); 0 = ideal
  double noise = 0;               // rad, standard deviation of the position measurement noise
  std::int64_t actuation_delay_ns = 0;
  std::vector<Disturbance> disturbances;
  std::uint64_t seed = 1;
  std::int64_t period_ns = 1'000'000;
};

class SimTableDriver final : public IoDriver {
 public:
  explicit SimTableDriver(SimTableConfig cfg);

  const std::vector<DriverChannel>& channels() const override { return channels_; }
  void bind(const std::vector<Cell*>& cells) override { bound_ = cells; }
  bool open(std::string*) override;
  void latch_inputs(const ScanContext& ctx) noexcept override;
  void write_outputs(const ScanContext& ctx) noexcept override;
  void close() noexcept override {}
  bool write_safe_outputs(const SafeOutput* outputs, std::size_t n) noexcept override;
  bool read_output(int channel, Cell* values) const override;

  // For tests and metrics: the true state, not the measurement.
  const AxisPlant& axis(std::size_t i) const { return plants_[i]; }
  std::size_t axes() const { return plants_.size(); }
  std::uint64_t bad_commands() const { return bad_commands_; }

  enum Channel { kCmd = 0, kPos = 1, kVel = 2, kApplied = 3, kLoad = 4 };

 private:
  void advance_to(std::int64_t t) noexcept;
  double disturbance(std::size_t axis, std::int64_t t) const noexcept;
  double measure(double theta) noexcept;

  SimTableConfig cfg_;
  std::vector<DriverChannel> channels_;
  std::vector<Cell*> bound_;
  std::vector<AxisPlant> plants_;
  // active_ and pending_ hold the motor input the program set: the limited
  // command plus the load.
  std::vector<double> active_, pending_, applied_, last_cmd_, last_load_;
  std::vector<std::int64_t> edges_;  // disturbance switching times, sorted
  std::int64_t t_ = 0;               // time the plant state belongs to
  std::int64_t switch_at_ = 0;       // when pending_ becomes active
  bool started_ = false, have_pending_ = false;
  double quantum_ = 0;               // rad per count, 0 = ideal
  SimRandom rng_;
  std::uint64_t bad_commands_ = 0;
  // The safe state: written by the supervisor, taken by the next latch.
  SafeOutputLatch safe_;
  std::vector<double> safe_cmd_;
  std::atomic<bool> safe_ready_{false};
  bool safe_taken_ = false;  // scan thread
};

DriverTypeInfo sim_table_driver_type();

}  // namespace syncplc
