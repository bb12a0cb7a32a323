// A cam profile (MC_CamIn's table, PLCopen Part 1 v2.0 §4.1, §4.2): slave positions
// over master positions, interpolated linearly or by a cubic spline, single
// shot or periodic. Storage for `capacity` points is taken at construction;
// load() and eval() never allocate.
//
// Splines (docs/motion/plcopen.md, "Camming"): single shot, the natural cubic
// spline (second derivative 0 at both ends); periodic, the periodic cubic
// spline (first and second derivatives equal at the two ends) of the table
// with its rise R = s[n-1] - s[0] taken out, R (u - m[0]) / P added back
// (P = m[n-1] - m[0]): a cam whose slave advances R per period, as a rotary
// knife's, is C2 across the wrap. Linear interpolation is the same formula with
// every second derivative 0.
#pragma once

#include <cstddef>
#include <vector>

namespace syncplc::plcopen {

class CamProfile {
 public:
  enum class Interpolation { Linear = 0, CubicSpline = 1 };

  explicit CamProfile(std::size_t capacity);

  // Takes the table m[0..n-1] (strictly increasing) / s[0..n-1], all finite,
  // 2 <= n <= capacity; false (nothing changes) otherwise.
  bool load(const double* m, const double* s, std::size_t n, Interpolation how, bool periodic) noexcept;

  // The slave value and its slope ds/du at the table's master coordinate u.
  // Periodic: u anywhere, the profile repeats with the rise per period
  // added (position continuous across the wrap); *period is the period index
  // floor((u - m[0]) / P). Single shot: before m[0] the first value, after
  // m[n-1] the last, slope 0 there.
  void eval(double u, double* s, double* ds, long long* period) const noexcept;

  double first_master() const noexcept { return m_[0]; }
  double last_master() const noexcept { return m_[n_ - 1]; }
  double first_slave() const noexcept { return s_[0]; }
  bool periodic() const noexcept { return periodic_; }

 private:
  void eval_in(double u, double* s, double* ds) const noexcept;  // u in [m0, m[n-1]], detrended
  bool natural() noexcept;
  bool periodic_spline() noexcept;

  std::size_t n_ = 0;
  bool periodic_ = false;
  double rise_ = 0, span_ = 1;
  // Table (slave values detrended when periodic), second derivatives, and
  // scratch of the tridiagonal solves.
  std::vector<double> m_, s_, M_, a_, b_, c_, r_, z_, w_;
};

}  // namespace syncplc::plcopen
