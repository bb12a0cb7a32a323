// One axis of the simulated table: paper 000 eq. (25),
//   P(s) = k / (s (tau s + 1)),
// from the PWM command u to the position theta (rad). In state form, with
// q = [theta, omega]:  theta' = omega,  omega' = (k u - omega) / tau.
//
// The command is held constant between updates (zero-order hold), so the
// discretisation over any interval h is exact:
//   q(t + h) = Phi(h) q(t) + Gamma(h) u,   [Phi Gamma; 0 1] = exp([A B; 0 0] h),
// computed with Eigen's matrix exponential. Intervals met every scan (the
// period and the pieces the deferred actuation cuts it into) are computed
// once at load; any other interval is computed when it is met, with
// fixed-size matrices (no allocation).
#pragma once

#include <Eigen/Dense>
#include <array>
#include <cstdint>

namespace syncplc {

struct AxisModel {
  double tau = 0.055;    // s, mechanical time constant
  double gain = 35.6206; // (rad/s)/PWM, steady-state speed per unit command
};

struct ZohStep {
  Eigen::Matrix2d phi;
  Eigen::Vector2d gamma;
};

// exp([A B; 0 0] h) for the model: the exact ZOH step of length h seconds.
ZohStep discretize(const AxisModel& m, double h);

class AxisPlant {
 public:
  AxisPlant() = default;
  explicit AxisPlant(const AxisModel& m) : model_(m) {}

  // Computes and keeps the step for an interval length (ns) met often.
  void prepare(std::int64_t h_ns);
  // Moves the state forward by h_ns with the command u held constant.
  void advance(double u, std::int64_t h_ns) noexcept;

  double position() const noexcept { return q_[0]; }
  double velocity() const noexcept { return q_[1]; }
  void set_state(double position, double velocity) noexcept { q_ = {position, velocity}; }
  const AxisModel& model() const noexcept { return model_; }

 private:
  static constexpr std::size_t kCache = 6;
  AxisModel model_;
  Eigen::Vector2d q_ = Eigen::Vector2d::Zero();
  std::array<std::int64_t, kCache> cached_h_{};
  std::array<ZohStep, kCache> cached_{};
  std::size_t n_cached_ = 0;
};

}  // namespace syncplc
