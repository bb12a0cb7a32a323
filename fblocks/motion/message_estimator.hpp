// MessageEstimator: the Taylor motion-message estimator of one signal, used by
// the TAYLOR_ESTIMATOR block and by any block that must fill lost or late
// network samples (e.g. SYNC_CONTROLLER for the preceding axes' errors).
//
// Paper 003 (Hsieh, Hsu, Wang, "The motion message estimator in networked
// control systems"), eqs. (3)-(5): with dP_j the backward differences,
//   v(k-1) = dP(k-1) + 1/2 (dP(k-1) - dP(k-2)) + 1/8 (dP(k-1) - 2 dP(k-2) + dP(k-3))   (3)
//   P^(k)  = P(k-1) + v(k-1)                                                         (4)
//          = 21/8 P(k-1) - 19/8 P(k-2) + 7/8 P(k-3) - 1/8 P(k-4)                     (5)
// and paper 000 eq. (15), the same predictor on the one-scan-late errors of the
// preceding axes. In backward-difference form (D = nabla, P1 = P(k-1)):
//   P^(k) = P1 + D P1 + 1/2 D^2 P1 + 1/8 D^3 P1.
// Truncating that series gives the lower orders of the same construction:
//   order 0: P1                                  (hold)
//   order 1: P1 + D P1            = 2 P1 - P2     (2-tap)
//   order 2: ... + 1/2 D^2 P1     = 5/2 P1 - 2 P2 + 1/2 P3
//   order 3: ... + 1/8 D^3 P1     = eq. (5)
// Every form's coefficients sum to 1 (exact on constants); orders 1..3 are
// exact on linear signals; on a constant acceleration a orders 2 and 3 leave
// the error P^ - P = -a T^2 / 2 and order 1 leaves -a T^2 (the 1/8 D^3 term
// is not a third derivative: "3rd order" names the series, not exactness).
//
// What the history holds after a loss (EstimatorHistory) decides stability;
// see docs/motion/taylor-estimator.md ("What the history holds"):
//  - Robust (default): the history holds received samples only. A loss is
//    filled by a predictor run over the contiguous run of received samples
//    that ends at the newest one (order ramped down to what that run holds);
//    across a gap the estimated increment is frozen: the h-th consecutive
//    estimate is P_last + min(h, max_extrapolation) * v^ (a ramp, then a hold).
//    With a single received sample after a gap, v^ is the secant to the sample
//    before the gap (if that one is at most max_extrapolation + 1 scans older).
//    Estimates never enter the history, so the output is a combination of at
//    most four received samples with coefficients bounded for every loss
//    pattern: bounded under ANY loss pattern (error bound in the doc).
//  - Recursive: paper 003 Fig. 3, estimates are fed back into the history.
//    Mean-square unstable under frequent interleaved losses (order 3 above
//    roughly 12 % Bernoulli loss); kept to reproduce the paper.
//  - Zero: a lost sample is recorded as 0 and the history starts zero-padded
//    (paper 003 eq. (1) feeding the predictor); catastrophic, kept to show why.
//
// Start-up (Robust, Recursive): no zero padding; the order ramps up as samples
// arrive (hold with one, 2-tap with two, ...). Before the first valid sample
// the output is 0. After max_extrapolation consecutive estimates the output
// holds (Recursive and Zero: the last output; Robust: the end of the ramp).
// A valid sample that is not finite (NaN, inf) is treated as lost.
//
// No allocation, no virtual calls; copyable; every member function noexcept.
#pragma once

#include <cstdint>

namespace syncplc::motion {

enum class EstimatorHistory : std::uint8_t {
  Robust = 0,     // received samples only, frozen-velocity ramp across gaps (default)
  Recursive = 1,  // estimates fed back into the history (paper 003 Fig. 3)
  Zero = 2,       // lost samples recorded as 0, zero-padded start (paper 003 eq. (1))
};

// Predictor coefficients of P(k-1), P(k-2), ... for each order (see above).
inline constexpr double kTaylor0[1] = {1.0};
inline constexpr double kTaylor1[2] = {2.0, -1.0};
inline constexpr double kTaylor2[3] = {5.0 / 2, -2.0, 1.0 / 2};
inline constexpr double kTaylor3[4] = {21.0 / 8, -19.0 / 8, 7.0 / 8, -1.0 / 8};

// Coefficients of `order` (clamped to 0..3): order + 1 values.
const double* taylor_coefficients(int order) noexcept;

class MessageEstimator {
 public:
  static constexpr int kMaxOrder = 3;
  static constexpr std::uint32_t kDefaultMaxExtrapolation = 20;

  // order is clamped to 0..3.
  explicit MessageEstimator(int order = 3, EstimatorHistory history = EstimatorHistory::Robust,
                            std::uint32_t max_extrapolation = kDefaultMaxExtrapolation) noexcept;

  // One sample period: returns the sample if valid (and finite), else the
  // estimate. Call exactly once per period, lost or not.
  double update(bool valid, double sample) noexcept;

  // What update(false, ...) would return next period, without changing any
  // state: the one-step prediction of eqs. (5)/(15) from the current history
  // (for compensating a one-scan delay, paper 000 eq. (15)).
  double predict_next() const noexcept;

  double output() const noexcept { return out_; }                 // last value update() returned
  bool estimated() const noexcept { return consecutive_ > 0; }     // the last update() was an estimate
  std::uint32_t consecutive() const noexcept { return consecutive_; }  // estimates in a row (0 after a sample)
  // Order of the predictor the next estimate would use (ramped down at
  // start-up or, for Robust, after a gap), 0..order().
  int effective_order() const noexcept;

  int order() const noexcept { return order_; }
  EstimatorHistory history() const noexcept { return mode_; }
  std::uint32_t max_extrapolation() const noexcept { return max_extra_; }

  // Back to the freshly constructed state (same configuration).
  void reset() noexcept;

 private:
  double estimate(std::uint32_t h) const noexcept;  // the h-th consecutive estimate
  void push(double v) noexcept;

  int order_;
  EstimatorHistory mode_;
  std::uint32_t max_extra_;
  double hist_[4];           // newest first: received samples (Robust) or outputs (Recursive, Zero)
  std::uint32_t count_;      // entries of hist_ in use (0..4)
  std::uint32_t run_;        // Robust: contiguous received samples ending at hist_[0] (0..4)
  std::uint32_t gap_;        // Robust: scans between hist_[1] and hist_[0] (1 = contiguous)
  std::uint32_t consecutive_;
  double out_;
};

}  // namespace syncplc::motion
