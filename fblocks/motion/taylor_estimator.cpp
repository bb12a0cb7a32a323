// TAYLOR_ESTIMATOR: fills lost or late samples of a smooth motion signal with
// the Taylor motion-message estimator of paper 003 eqs. (3)-(5) (Fig. 3) and
// paper 000 eq. (15). The arithmetic lives in MessageEstimator
// (message_estimator.hpp), which other motion blocks reuse; see
// docs/motion/taylor-estimator.md for the forms, the stability analysis and
// the loss limits.
#include <memory>
#include <string>
#include <utility>

#include "fblocks/motion/message_estimator.hpp"
#include "fblocks/motion/motion.hpp"
#include "runtime/core/pin_decl.hpp"

namespace syncplc::motion {
namespace {

enum : int { kIn = 0, kValid, kOut, kEstimated, kConsecutive, kNext };

class TaylorEstimator final : public Block {
 public:
  explicit TaylorEstimator(const BlockSetup& s)
      : est_(s.param<std::int16_t>("order"), static_cast<EstimatorHistory>(s.param<std::int16_t>("history")),
             s.param<std::uint32_t>("max_extrapolation")) {}

  void execute(ScanContext&) noexcept override {
    const double y = est_.update(in<bool>(kValid), in<double>(kIn));
    out<double>(kOut, y);
    out<bool>(kEstimated, est_.estimated());
    out<std::uint32_t>(kConsecutive, est_.consecutive());
    out<double>(kNext, est_.predict_next());
  }

 private:
  MessageEstimator est_;
};

}  // namespace

void register_taylor_estimator(BlockRegistry& r) {
  BlockTypeInfo t;
  t.name = "TAYLOR_ESTIMATOR";
  t.category = kCategory;
  t.doc =
      "Motion message estimator: out = in while valid, else an estimate of the lost sample. Paper 003 eq. (5): "
      "P^(k) = 21/8 P(k-1) - 19/8 P(k-2) + 7/8 P(k-3) - 1/8 P(k-4), i.e. P1 + D P1 + 1/2 D^2 P1 + 1/8 D^3 P1 "
      "with backward differences D (eqs. 3-4); order truncates that series: 0 hold [1], 1 [2, -1], "
      "2 [5/2, -2, 1/2], 3 the paper's. Coefficients sum to 1; orders 1-3 are exact on linear signals, and a "
      "constant acceleration a leaves P^ - P = -a T^2/2 (order 1: -a T^2). history 0 (robust, default): the "
      "history holds received samples only; a loss is predicted over the contiguous run of received samples "
      "ending at the newest (order ramped down to what the run holds; one sample after a gap: the secant to "
      "the sample before it), and across a gap the increment is frozen, so the h-th consecutive estimate is "
      "P_last + min(h, max_extrapolation) * v^: bounded under any loss pattern. history 1 (recursive, paper "
      "003 Fig. 3): estimates are fed back into the history; mean-square unstable above about 12 % random "
      "loss for order 3 (15 % order 2, 33 % order 1). history 2 (zero): lost samples enter the history as 0 "
      "from a zero-padded start (eq. 1), catastrophic, for comparison only. Start-up: no padding, the order "
      "ramps up as samples arrive; out = 0 before the first valid sample. After max_extrapolation consecutive "
      "estimates the output holds. A non-finite sample counts as lost. next = the one-step prediction from "
      "the current history (paper 000 eq. 15: compensates a one-scan network delay).";
  t.reference =
      "Hsieh, Hsu, Wang: The motion message estimator in networked control systems (paper 003), eqs. (3)-(5), "
      "Fig. 3; decentralized multi-axis synchronous control (paper 000), eq. (15)";
  t.pins = {
      input("in", IecType::LREAL).required().doc("received sample (any unit; out, next are in the same unit)"),
      input("valid", IecType::BOOL).init("TRUE").doc("TRUE: in is this scan's sample; FALSE: lost or late"),
      output("out", IecType::LREAL).doc("in when valid, else the estimate"),
      output("estimated", IecType::BOOL).doc("TRUE when out is an estimate"),
      output("consecutive", IecType::UDINT).doc("estimates in a row, 0 after a valid sample"),
      output("next", IecType::LREAL)
          .doc("one-step prediction of the next sample from the current history (the estimate out would take if the "
               "next sample were lost)"),
  };
  t.params = {
      parameter("order", IecType::INT).init("3").min(0).max(3)
          .doc("predictor order: 0 hold, 1 [2, -1], 2 [5/2, -2, 1/2], 3 [21/8, -19/8, 7/8, -1/8] (paper 003 eq. 5)"),
      parameter("history", IecType::INT).init("0").min(0).max(2)
          .doc("what the history holds after a loss: 0 robust (received samples only, frozen-velocity ramp across "
               "gaps; bounded), 1 recursive (estimates fed back, paper 003 Fig. 3; unstable above ~12 % loss), 2 zero "
               "(lost samples as 0, zero-padded start; catastrophic, for comparison)"),
      parameter("max_extrapolation", IecType::UDINT).init("20").min(0).max(1'000'000)
          .doc("consecutive estimates that extrapolate; later ones hold the last estimate (0 = hold at once)"),
  };
  t.create = [](BlockSetup& s) -> std::unique_ptr<Block> {
    const auto order = s.param<std::int16_t>("order"), history = s.param<std::int16_t>("history");
    if (order < 0 || order > MessageEstimator::kMaxOrder) s.error("TAYLOR_ESTIMATOR: order must be 0..3");
    if (history < 0 || history > 2) s.error("TAYLOR_ESTIMATOR: history must be 0 (robust), 1 (recursive) or 2 (zero)");
    return std::make_unique<TaylorEstimator>(s);
  };
  r.add(std::move(t));
}

}  // namespace syncplc::motion
