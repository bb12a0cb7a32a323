// Motion metrics of a simulation run (`syncplc sim --metrics out.json`):
// paper 000 eqs. (26)-(27) over the axis errors the project names in
// `metrics: {axis_errors: ...}`, sampled after every scan of the task that
// owns them:
//   Track-RSME = sqrt( mean over samples of sum_i e_i^2 )     (a sum over axes, not a mean)
//   Sync-RSME  = sqrt( mean over samples of sum_{i>=2} eps_i^2 ),
//   eps = T e (eqs. (3), (6)): eps_1 = 0, eps_k = e_k - mean(e_1 .. e_{k-1}),
// plus per-axis maxima and RMS, the per-task statistics and the drivers'
// counters.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "runtime/core/program.hpp"
#include "runtime/project/contour_metric.hpp"

namespace syncplc {

// The project's `metrics:` section, resolved: the axes' tracking errors in
// axis order, and the logical time from which samples count.
struct MetricsSettings {
  std::vector<TraceColumn> axis_errors;
  std::int64_t from_ns = 0;
  std::optional<ContourSettings> contour;  // metrics: contour (contour_metric.hpp)
};

class MotionMetrics {
 public:
  explicit MotionMetrics(const MetricsSettings& m);
  // After the scans of time t: samples when the errors' task scanned since the last call.
  // In virtual time, from the clock's observer: `a` is the clock's (image_access.hpp).
  void sample(const Program& p, ImageAccess a, std::int64_t t, std::uint64_t owner_scans);
  bool enabled() const { return !errors_.empty(); }
  std::uint16_t task() const { return task_; }

  std::uint64_t samples() const { return n_; }
  double track_rsme() const;
  double sync_rsme() const;
  double max_abs_error(std::size_t axis) const { return max_e_[axis]; }
  double rms_error(std::size_t axis) const;
  double max_abs_sync_error(std::size_t axis) const { return max_eps_[axis]; }
  // The true contour error, when the project names a contour.
  const ContourMetric* contour() const { return contour_ ? &contour_error_ : nullptr; }

  // The whole report as JSON text.
  std::string json(const Program& p, std::int64_t duration_ns, double wall_s) const;

 private:
  std::vector<CellRef> errors_;
  std::vector<std::string> labels_;
  std::uint16_t task_ = 0;
  std::int64_t from_ns_ = 0;
  std::uint64_t last_scans_ = 0;
  std::uint64_t n_ = 0;
  double sum_track_ = 0, sum_sync_ = 0;
  std::vector<double> max_e_, sum_e2_, max_eps_;
  std::vector<double> e_;
  std::optional<ContourSettings> contour_;
  ContourMetric contour_error_;
};

}  // namespace syncplc
