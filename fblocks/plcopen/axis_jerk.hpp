// The jerk limit of the PLCopen axis's profiles (docs/motion/jerk-profile.md):
// the set values of a jerk-limited command are the moving average, over a
// window of m samples, of an inner acceleration-limited profile (paper 004's
// filter for a discrete move, the velocity ramp for MC_MoveVelocity, MC_Halt
// and MC_Stop). Averaging keeps the inner profile's velocity and acceleration
// bounds and its arrival without overshoot from rest, and makes the
// acceleration change by at most (u_new - u_oldest)/m per sample: the jerk is
// at most 2 U / (m T) for inner accelerations |u| <= U, so m = ceil(2 U/(J T))
// keeps it within J. The set values arrive exactly, at rest, m - 1 samples
// after the inner profile. Plain data, fixed capacity, no allocation.
#pragma once

#include <array>
#include <cstdint>

#include "fblocks/motion/nonlinear_filter_math.hpp"

namespace syncplc::plcopen {

class JerkWindow {
 public:
  // Longest window: a command whose jerk would need more samples is refused
  // (0x0204). 2048 samples is 2 s of jerk ramp at 1 ms.
  static constexpr std::int64_t kCapacity = 2048;

  // Samples the window needs so that a new inner acceleration within
  // [-U, U] replacing an old one within [-U_old, U_old] changes the averaged
  // one by at most J T: ceil((U + max(U, U_old)) / (J T)), at least 1; 1
  // when J is 0 (not jerk-limited); kCapacity + 1 when too long.
  static std::int64_t length_for(double U, double U_old, double J, double T) noexcept;

  // Starts a command with window m from the set values (position, velocity)
  // and the acceleration `a_last` over the sample before. When the window
  // already runs with the same m and still makes these set values (the
  // command before was averaged the same way and nothing moved the axis
  // since), it carries on: the inner profile continues from its own state.
  // Otherwise it takes a history of constant acceleration a_last that
  // averages to exactly these set values, and the inner profile starts at
  // its newest sample.
  // U: the new command's acceleration bound (the ring's bound becomes the
  // larger of U and what the ring holds).
  void begin(std::int64_t m, double U, const motion::FilterState& set, double a_last, double T) noexcept;
  // The largest |acceleration| the inner samples in the window may have.
  double accel_bound() const noexcept { return u_bound_; }
  // Whether the window runs (m > 1) and makes `set`.
  bool in_step_with(const motion::FilterState& set) const noexcept;

  std::int64_t length() const noexcept { return m_; }
  bool averaging() const noexcept { return m_ > 1; }
  // The inner profile's state, from which its next sample is computed.
  const motion::FilterState& inner() const noexcept { return inner_; }
  // The set values after pushing the inner sample `next` (not stored).
  motion::FilterState peek(const motion::FilterState& next) const noexcept;
  // Pushes the inner profile's next sample; `inner_at_end` says it reached
  // its end (goal at rest, or the commanded velocity). Returns the set
  // values; once the inner profile has been at its end for the whole
  // window, they are its end exactly and settled() is true.
  motion::FilterState push(const motion::FilterState& next, bool inner_at_end) noexcept;
  bool settled() const noexcept { return at_end_ >= m_; }
  // Samples until settled, given the inner profile's own remaining samples
  // (0: it is at its end).
  std::int64_t remaining(std::int64_t inner_remaining) const noexcept;

 private:
  void refresh_sums() noexcept;

  std::int64_t m_ = 1;
  double T_ = 0;
  double u_bound_ = 0;
  motion::FilterState inner_{};
  motion::FilterState out_{};
  std::array<motion::FilterState, kCapacity> ring_{};
  std::int64_t head_ = 0;  // index of the oldest sample
  double sum_x_ = 0, sum_v_ = 0;
  std::int64_t at_end_ = 0;    // consecutive pushes of an inner sample at its end
  std::int64_t since_refresh_ = 0;
};

}  // namespace syncplc::plcopen
