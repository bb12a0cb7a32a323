#include "fblocks/motion/message_estimator.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace syncplc::motion {
namespace {

constexpr std::uint32_t kSatMax = std::numeric_limits<std::uint32_t>::max();

std::uint32_t sat_inc(std::uint32_t v) noexcept { return v == kSatMax ? v : v + 1; }

}  // namespace

const double* taylor_coefficients(int order) noexcept {
  switch (std::clamp(order, 0, MessageEstimator::kMaxOrder)) {
    case 0: return kTaylor0;
    case 1: return kTaylor1;
    case 2: return kTaylor2;
    default: return kTaylor3;
  }
}

MessageEstimator::MessageEstimator(int order, EstimatorHistory history, std::uint32_t max_extrapolation) noexcept
    : order_(std::clamp(order, 0, kMaxOrder)), mode_(history), max_extra_(max_extrapolation) {
  reset();
}

void MessageEstimator::reset() noexcept {
  for (double& h : hist_) h = 0.0;
  count_ = mode_ == EstimatorHistory::Zero ? 4 : 0;  // Zero: the zero-padded history of eq. (1)
  run_ = 0;
  gap_ = 1;
  consecutive_ = 0;
  out_ = 0.0;
}

void MessageEstimator::push(double v) noexcept {
  hist_[3] = hist_[2];
  hist_[2] = hist_[1];
  hist_[1] = hist_[0];
  hist_[0] = v;
  if (count_ < 4) ++count_;
}

int MessageEstimator::effective_order() const noexcept {
  if (count_ == 0) return 0;
  if (mode_ == EstimatorHistory::Robust) {
    if (run_ >= 2) return std::min<int>(order_, static_cast<int>(run_) - 1);
    // One received sample after a gap: the secant to the sample before it.
    const bool secant = order_ >= 1 && count_ >= 2 && gap_ <= static_cast<std::uint64_t>(max_extra_) + 1;
    return secant ? 1 : 0;
  }
  return std::min<int>(order_, static_cast<int>(count_) - 1);
}

double MessageEstimator::estimate(std::uint32_t h) const noexcept {
  if (count_ == 0) return 0.0;  // nothing received yet: no information
  if (mode_ == EstimatorHistory::Robust) {
    // Increment per scan from the received history only.
    double inc = 0.0;
    if (run_ >= 2) {
      const int p = std::min<int>(order_, static_cast<int>(run_) - 1);
      const double* c = taylor_coefficients(p);
      double pred = 0.0;
      for (int i = 0; i <= p; ++i) pred += c[i] * hist_[i];
      inc = pred - hist_[0];
    } else if (effective_order() == 1) {
      inc = (hist_[0] - hist_[1]) / static_cast<double>(gap_);
    }
    const double n = static_cast<double>(std::min(h, max_extra_));
    return hist_[0] + n * inc;  // frozen-velocity ramp, then a hold
  }
  // Recursive and Zero: the predictor over whatever the history holds.
  if (h > max_extra_) return out_;  // past the extrapolation limit: hold
  const int p = effective_order();
  const double* c = taylor_coefficients(p);
  double pred = 0.0;
  for (int i = 0; i <= p; ++i) pred += c[i] * hist_[i];
  return pred;
}

double MessageEstimator::update(bool valid, double sample) noexcept {
  if (valid && std::isfinite(sample)) {
    if (mode_ == EstimatorHistory::Robust) {
      const bool contiguous = consecutive_ == 0 && count_ > 0;
      const std::uint32_t gap = sat_inc(consecutive_);
      push(sample);
      run_ = contiguous ? std::min<std::uint32_t>(run_ + 1, 4) : 1;
      gap_ = gap;
    } else {
      push(sample);
    }
    consecutive_ = 0;
    out_ = sample;
    return out_;
  }
  const std::uint32_t h = sat_inc(consecutive_);
  const double e = estimate(h);
  switch (mode_) {
    case EstimatorHistory::Robust: break;  // estimates never enter the history
    case EstimatorHistory::Recursive:
      if (count_ > 0) push(e);  // paper 003 Fig. 3: the estimate becomes history
      break;
    case EstimatorHistory::Zero: push(0.0); break;
  }
  consecutive_ = h;
  out_ = e;
  return out_;
}

double MessageEstimator::predict_next() const noexcept { return estimate(sat_inc(consecutive_)); }

}  // namespace syncplc::motion
