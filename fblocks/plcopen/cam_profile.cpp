// The cam profile's interpolation (cam_profile.hpp): the spline's second
// derivatives by the tridiagonal (natural) or cyclic tridiagonal (periodic,
// Sherman-Morrison) system, solved without allocation into the storage
// taken at construction.
#include "fblocks/plcopen/cam_profile.hpp"

#include <algorithm>
#include <cmath>

namespace syncplc::plcopen {

namespace cam_profile {

// Thomas algorithm: a[i] x[i-1] + b[i] x[i] + c[i] x[i+1] = r[i], i < n
// (a[0], c[n-1] unused); w is scratch. False on a zero pivot.
bool solve_tridiagonal(const double* a, const double* b, const double* c, const double* r, double* x, double* w,
                       std::size_t n) noexcept {
  double beta = b[0];
  if (beta == 0) return false;
  x[0] = r[0] / beta;
  for (std::size_t i = 1; i < n; ++i) {
    w[i] = c[i - 1] / beta;
    beta = b[i] - a[i] * w[i];
    if (beta == 0) return false;
    x[i] = (r[i] - a[i] * x[i - 1]) / beta;
  }
  for (std::size_t i = n - 1; i > 0; --i) x[i - 1] -= w[i] * x[i];
  return true;
}

}  // namespace cam_profile

CamProfile::CamProfile(std::size_t capacity)
    : m_(capacity), s_(capacity), M_(capacity), a_(capacity), b_(capacity), c_(capacity), r_(capacity),
      z_(capacity), w_(capacity) {}

bool CamProfile::load(const double* m, const double* s, std::size_t n, Interpolation how, bool periodic) noexcept {
  if (n < 2 || n > m_.size()) return false;
  for (std::size_t i = 0; i < n; ++i) {
    if (!std::isfinite(m[i]) || !std::isfinite(s[i])) return false;
    if (i > 0 && !(m[i] > m[i - 1])) return false;
  }
  n_ = n;
  periodic_ = periodic;
  span_ = m[n - 1] - m[0];
  rise_ = periodic ? s[n - 1] - s[0] : 0;
  for (std::size_t i = 0; i < n; ++i) {
    m_[i] = m[i];
    s_[i] = s[i] - rise_ * (m[i] - m[0]) / span_;
  }
  if (periodic) s_[n - 1] = s_[0];  // exactly, whatever the rounding of the detrend
  std::fill(M_.begin(), M_.begin() + static_cast<std::ptrdiff_t>(n), 0.0);
  if (how == Interpolation::Linear) return true;
  return periodic ? periodic_spline() : natural();
}

// M[0] = M[n-1] = 0; h[i-1] M[i-1] + 2 (h[i-1] + h[i]) M[i] + h[i] M[i+1] =
// 6 (d[i] - d[i-1]) for the inner points, d[i] the slope of interval i.
bool CamProfile::natural() noexcept {
  const std::size_t k = n_ - 2;  // unknowns M[1..n-2]
  if (k == 0) return true;
  for (std::size_t j = 0; j < k; ++j) {
    const std::size_t i = j + 1;
    const double h0 = m_[i] - m_[i - 1], h1 = m_[i + 1] - m_[i];
    a_[j] = h0;
    b_[j] = 2 * (h0 + h1);
    c_[j] = h1;
    r_[j] = 6 * ((s_[i + 1] - s_[i]) / h1 - (s_[i] - s_[i - 1]) / h0);
  }
  return cam_profile::solve_tridiagonal(a_.data(), b_.data(), c_.data(), r_.data(), M_.data() + 1, w_.data(), k);
}

// The N = n-1 unknowns M[0..N-1] (M[N] = M[0]) on the cycle of intervals:
// the same equations, indices modulo N. Solved as a tridiagonal system plus a
// rank-one correction (Sherman-Morrison); N <= 2 directly.
bool CamProfile::periodic_spline() noexcept {
  const std::size_t N = n_ - 1;
  if (N == 1) return true;  // one interval, equal ends: a straight line
  auto h = [&](std::size_t i) { return m_[i + 1] - m_[i]; };
  auto d = [&](std::size_t i) { return (s_[i + 1] - s_[i]) / h(i); };
  for (std::size_t i = 0; i < N; ++i) {
    const std::size_t p = (i + N - 1) % N;
    a_[i] = h(p);
    b_[i] = 2 * (h(p) + h(i));
    c_[i] = h(i);
    r_[i] = 6 * (d(i) - d(p));
  }
  if (N == 2) {
    // Both neighbours of each unknown are the other one.
    const double a00 = b_[0], a01 = a_[0] + c_[0], a10 = a_[1] + c_[1], a11 = b_[1];
    const double det = a00 * a11 - a01 * a10;
    if (det == 0) return false;
    M_[0] = (r_[0] * a11 - a01 * r_[1]) / det;
    M_[1] = (a00 * r_[1] - a10 * r_[0]) / det;
    M_[2] = M_[0];
    return true;
  }
  const double alpha = c_[N - 1], beta = a_[0];  // A[N-1][0], A[0][N-1]
  const double gamma = -b_[0];
  b_[0] -= gamma;
  b_[N - 1] -= alpha * beta / gamma;
  if (!cam_profile::solve_tridiagonal(a_.data(), b_.data(), c_.data(), r_.data(), M_.data(), w_.data(), N))
    return false;
  for (std::size_t i = 0; i < N; ++i) r_[i] = 0;
  r_[0] = gamma;
  r_[N - 1] = alpha;
  if (!cam_profile::solve_tridiagonal(a_.data(), b_.data(), c_.data(), r_.data(), z_.data(), w_.data(), N))
    return false;
  const double f = (M_[0] + beta * M_[N - 1] / gamma) / (1 + z_[0] + beta * z_[N - 1] / gamma);
  for (std::size_t i = 0; i < N; ++i) M_[i] -= f * z_[i];
  M_[N] = M_[0];
  return true;
}

void CamProfile::eval_in(double u, double* s, double* ds) const noexcept {
  const double* end = m_.data() + n_;
  std::size_t i = static_cast<std::size_t>(std::upper_bound(m_.data(), end, u) - m_.data());
  i = i == 0 ? 0 : i - 1;
  if (i > n_ - 2) i = n_ - 2;
  const double h = m_[i + 1] - m_[i];
  const double A = (m_[i + 1] - u) / h, B = (u - m_[i]) / h;
  *s = A * s_[i] + B * s_[i + 1] + ((A * A * A - A) * M_[i] + (B * B * B - B) * M_[i + 1]) * h * h / 6;
  *ds = (s_[i + 1] - s_[i]) / h - (3 * A * A - 1) / 6 * h * M_[i] + (3 * B * B - 1) / 6 * h * M_[i + 1];
}

void CamProfile::eval(double u, double* s, double* ds, long long* period) const noexcept {
  const double m0 = m_[0], mN = m_[n_ - 1];
  if (!periodic_) {
    *period = u < m0 ? -1 : (u > mN ? 1 : 0);
    if (u <= m0) {
      *s = s_[0];
      *ds = 0;
    } else if (u >= mN) {
      *s = s_[n_ - 1];
      *ds = 0;
    } else {
      eval_in(u, s, ds);
    }
    return;
  }
  const double k = std::floor((u - m0) / span_);
  double r = u - m0 - k * span_;
  if (r < 0) r = 0;
  if (r > span_) r = span_;
  eval_in(m0 + r, s, ds);
  // The rise: the trend of the whole periods and of the part of this one.
  *s += rise_ * k + rise_ * r / span_;
  *ds += rise_ / span_;
  *period = static_cast<long long>(k);
}

}  // namespace syncplc::plcopen
