#include "fblocks/plcopen/axis_jerk.hpp"

#include <cmath>

namespace syncplc::plcopen {

using motion::FilterState;

std::int64_t JerkWindow::length_for(double U, double U_old, double J, double T) noexcept {
  if (!(J > 0)) return 1;
  const double n = std::ceil((U + (U_old > U ? U_old : U)) / (J * T) * (1 - 1e-12));  // an exact ratio stays that ratio
  if (!(n <= static_cast<double>(kCapacity))) return kCapacity + 1;
  return n < 1 ? 1 : static_cast<std::int64_t>(n);
}

bool JerkWindow::in_step_with(const FilterState& set) const noexcept {
  return m_ > 1 && out_.x == set.x && out_.v == set.v;
}

void JerkWindow::begin(std::int64_t m, double U, const FilterState& set, double a_last, double T) noexcept {
  if (m < 1) m = 1;
  if (m > kCapacity) m = kCapacity;
  if (m == m_ && T == T_ && in_step_with(set)) {  // the inner profile carries on
    if (U > u_bound_) u_bound_ = U;
    return;
  }
  u_bound_ = std::fabs(a_last) > U ? std::fabs(a_last) : U;
  m_ = m;
  T_ = T;
  at_end_ = 0;
  out_ = set;
  if (m == 1) {
    inner_ = set;
    ring_[0] = set;
    head_ = 0;
    refresh_sums();
    return;
  }
  // A history of constant acceleration a over the last m samples, newest
  // i = 0: v_i = v0 - i T a, x_i = x0 - i T v0 + (i T)^2 a / 2, whose means are
  // the set values: v0 = v + T a (m-1)/2, x0 = x + T v0 (m-1)/2 - T^2 a (m-1)(2m-1)/12.
  // (The history of a command that ran with this acceleration, so the
  // acceleration and its rate stay continuous: the next averaged sample
  // changes it by (u - a)/m.)
  const double a = a_last, k = static_cast<double>(m - 1);
  const double v0 = set.v + T * a * k / 2;
  const double x0 = set.x + T * v0 * k / 2 - T * T * a * k * (2 * k + 1) / 12;
  inner_ = {x0, v0};
  head_ = 0;
  for (std::int64_t j = 0; j < m; ++j) {  // ring_[head_] is the oldest: i = m-1-j
    const double t = T * static_cast<double>(m - 1 - j);
    ring_[j] = {x0 - t * v0 + t * t * a / 2, v0 - t * a};
  }
  refresh_sums();
}

void JerkWindow::refresh_sums() noexcept {
  double sx = 0, sv = 0;
  for (std::int64_t j = 0; j < m_; ++j) {
    sx += ring_[j].x;
    sv += ring_[j].v;
  }
  sum_x_ = sx;
  sum_v_ = sv;
  since_refresh_ = 0;
}

FilterState JerkWindow::peek(const FilterState& next) const noexcept {
  if (m_ == 1) return next;
  const FilterState& oldest = ring_[head_];
  const double m = static_cast<double>(m_);
  return {(sum_x_ + (next.x - oldest.x)) / m, (sum_v_ + (next.v - oldest.v)) / m};
}

FilterState JerkWindow::push(const FilterState& next, bool inner_at_end) noexcept {
  at_end_ = inner_at_end ? at_end_ + 1 : 0;
  inner_ = next;
  if (m_ == 1) {
    ring_[0] = next;
    out_ = next;
    return out_;
  }
  FilterState out = peek(next);
  const FilterState oldest = ring_[head_];
  ring_[head_] = next;
  head_ = head_ + 1 == m_ ? 0 : head_ + 1;
  sum_x_ += next.x - oldest.x;
  sum_v_ += next.v - oldest.v;
  // Running sums drift by rounding; recomputed once per window (O(1) a sample).
  if (++since_refresh_ >= m_) refresh_sums();
  if (settled()) {
    // The whole window holds the end: at rest every sample is the goal; at a
    // velocity the average is that velocity exactly.
    out = next.v == 0 ? next : FilterState{out.x, next.v};
  }
  out_ = out;
  return out_;
}

std::int64_t JerkWindow::remaining(std::int64_t inner_remaining) const noexcept {
  if (inner_remaining < 0) return -1;
  if (inner_remaining > 0) return inner_remaining + m_ - 1;
  return at_end_ >= m_ ? 0 : m_ - at_end_;
}

}  // namespace syncplc::plcopen
