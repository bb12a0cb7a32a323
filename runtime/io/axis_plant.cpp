#include "runtime/io/axis_plant.hpp"

#include <unsupported/Eigen/MatrixFunctions>

namespace syncplc {

ZohStep discretize(const AxisModel& m, double h) {
  // Augmented system: d/dt [theta omega u] = M [theta omega u], u constant.
  Eigen::Matrix3d M = Eigen::Matrix3d::Zero();
  M(0, 1) = 1.0;
  M(1, 1) = -1.0 / m.tau;
  M(1, 2) = m.gain / m.tau;
  const Eigen::Matrix3d E = (M * h).exp();
  ZohStep s;
  s.phi = E.topLeftCorner<2, 2>();
  s.gamma = E.topRightCorner<2, 1>();
  return s;
}

void AxisPlant::prepare(std::int64_t h_ns) {
  for (std::size_t i = 0; i < n_cached_; ++i)
    if (cached_h_[i] == h_ns) return;
  if (n_cached_ == kCache) return;
  cached_h_[n_cached_] = h_ns;
  cached_[n_cached_] = discretize(model_, static_cast<double>(h_ns) * 1e-9);
  ++n_cached_;
}

void AxisPlant::advance(double u, std::int64_t h_ns) noexcept {
  if (h_ns <= 0) return;
  for (std::size_t i = 0; i < n_cached_; ++i)
    if (cached_h_[i] == h_ns) {
      q_ = cached_[i].phi * q_ + cached_[i].gamma * u;
      return;
    }
  const ZohStep s = discretize(model_, static_cast<double>(h_ns) * 1e-9);
  q_ = s.phi * q_ + s.gamma * u;
}

}  // namespace syncplc
