// OPTIMAL_COMPENSATOR: the "optimal" dropout compensator that paper 003
// (§4, Figs. 7-8) compares its Taylor estimator against (Ling & Lemmon 2003,
// 2004): a lost sample is replaced by a linear combination of the last
// `order` values of the compensated stream. Its taps are either given
// (design 1: Ling & Lemmon's output-power optimum for a loop, computed by
// `syncplc design-compensator`, dropout_design.hpp) or computed at load as the
// predictor that minimises the mean-square estimation error for the signal's
// autocorrelation and the dropout rate (design 0, optimal_compensator_math.hpp).
// Derivations: docs/motion/dropout-compensators.md. The scan is a dot
// product over a fixed ring.
#include <cmath>
#include <cstdint>
#include <memory>
#include <span>
#include <stdexcept>
#include <string>
#include <utility>

#include "fblocks/motion/motion.hpp"
#include "fblocks/motion/optimal_compensator_math.hpp"
#include "fblocks/motion/param_read.hpp"
#include "runtime/core/pin_decl.hpp"

namespace syncplc::motion {
namespace optimal_compensator_block {

enum : int { kIn = 0, kValid, kOut, kEstimated, kConsecutive };
constexpr int kBlockMaxOrder = 4;  // rho1..rho4: the same four taps as paper 003 eq. (5)

class OptimalCompensator final : public Block {
 public:
  explicit OptimalCompensator(const OptimalDropoutPredictor& p) : p_(p) {}

  void execute(ScanContext&) noexcept override {
    const double x = in<double>(kIn);
    double y;
    if (in<bool>(kValid) && std::isfinite(x)) {
      y = x;
      consecutive_ = 0;
    } else {
      y = 0.0;
      for (int j = 0; j < p_.order; ++j) y += p_.a[j] * hist_[j];
      if (consecutive_ < 0xFFFFFFFFu) ++consecutive_;
    }
    // Fig. 3: the compensated value (sample or estimate) becomes history.
    for (int j = kBlockMaxOrder - 1; j > 0; --j) hist_[j] = hist_[j - 1];
    hist_[0] = y;
    out<double>(kOut, y);
    out<bool>(kEstimated, consecutive_ > 0);
    out<std::uint32_t>(kConsecutive, consecutive_);
  }

 private:
  OptimalDropoutPredictor p_;
  double hist_[kBlockMaxOrder] = {};  // newest first; zeros before start: the zero-mean model's prior
  std::uint32_t consecutive_ = 0;
};

}  // namespace optimal_compensator_block

void register_optimal_compensator(BlockRegistry& r) {
  using optimal_compensator_block::kBlockMaxOrder;
  BlockTypeInfo t;
  t.name = "OPTIMAL_COMPENSATOR";
  t.category = kCategory;
  t.doc =
      "Optimal dropout compensator (the one paper 003 Figs. 7-8 compares the Taylor estimator against): out = in "
      "while valid, else a_1 out(k-1) + ... + a_order out(k-order), a linear predictor over the compensated stream "
      "(estimates are fed back, paper 003 Fig. 3). design 1 takes the taps a1..a4 as given: Ling & Lemmon's "
      "optimum, the taps that minimise the loop's output power E[y^2] under Bernoulli dropouts, computed for a "
      "loop by `syncplc design-compensator` (exact second moment of the jump-linear loop, minimised by NLopt). "
      "design 0 computes the coefficients at load from the signal's "
      "normalised autocorrelation rho1..rho4 (rho_j = R(j)/R(0)) and the dropout rate eps: they minimise the "
      "mean-square estimation error when each history entry carries, with probability eps, an estimation error "
      "of the same variance s2: (R + eps s2 I) a = r, s2 = R(0) - a'r (Yule-Walker loaded by the dropouts; at "
      "eps = 0 the order-N Wiener predictor; AR(1): a = [rho, 0, ...]). For a zero-mean stationary signal: a "
      "constant or slow motion command is predicted with a bias (the coefficients sum to less than 1). Rejected "
      "at load: lags that are not an autocorrelation (Toeplitz matrix not positive definite). Out = 0 before "
      "the first sample. docs/motion/dropout-compensators.md has the derivation.";
  t.reference =
      "Ling, Lemmon: Optimal dropout compensation in networked control systems (2003); Power spectral analysis of "
      "networked control systems with data dropouts (2004); as compared in Hsieh, Hsu, Wang (paper 003) §4, Figs. 7-8";
  t.pins = {
      input("in", IecType::LREAL).required().doc("received sample"),
      input("valid", IecType::BOOL).init("TRUE").doc("TRUE: in is this scan's sample; FALSE: lost or late"),
      output("out", IecType::LREAL).doc("in when valid, else the estimate"),
      output("estimated", IecType::BOOL).doc("TRUE when out is an estimate"),
      output("consecutive", IecType::UDINT).doc("estimates in a row, 0 after a valid sample"),
  };
  t.params = {
      parameter("design", IecType::INT).init("0").min(0).max(1)
          .doc("0: the Wiener predictor from rho1..rho4 and dropout_rate; 1: the taps a1..a4 as given (Ling & "
               "Lemmon's output-power optimum for a loop, from `syncplc design-compensator`)"),
      parameter("order", IecType::INT).init("4").min(1).max(kBlockMaxOrder)
          .doc("taps of the predictor (uses rho1..rho_order, or a1..a_order)"),
      parameter("dropout_rate", IecType::LREAL).init("0.2").min(0).max(0.95)
          .doc("design 0: the Bernoulli dropout rate eps the coefficients are designed for"),
      parameter("rho1", IecType::LREAL).init("0").min(-1).max(1).doc("design 0: normalised autocorrelation of the signal at lag 1"),
      parameter("rho2", IecType::LREAL).init("0").min(-1).max(1).doc("... at lag 2"),
      parameter("rho3", IecType::LREAL).init("0").min(-1).max(1).doc("... at lag 3"),
      parameter("rho4", IecType::LREAL).init("0").min(-1).max(1)
          .doc("... at lag 4 (all 0, the default: white signal, the optimal estimate is its mean 0)"),
      parameter("a1", IecType::LREAL).init("0").min(-100).max(100).doc("design 1: tap on out(k-1)"),
      parameter("a2", IecType::LREAL).init("0").min(-100).max(100).doc("design 1: tap on out(k-2)"),
      parameter("a3", IecType::LREAL).init("0").min(-100).max(100).doc("design 1: tap on out(k-3)"),
      parameter("a4", IecType::LREAL).init("0").min(-100).max(100).doc("design 1: tap on out(k-4)"),
  };
  t.create = [](BlockSetup& s) -> std::unique_ptr<Block> {
    bool ok = true;
    const auto design = ctl::int_param(s, "design", &ok);
    const auto order = static_cast<int>(ctl::int_param(s, "order", &ok));
    if (!ok) return nullptr;
    if (design == 1) {
      // Taps as designed elsewhere; the ones beyond `order` are not used and must be 0.
      OptimalDropoutPredictor p;
      p.order = order;
      const char* names[kBlockMaxOrder] = {"a1", "a2", "a3", "a4"};
      for (int j = 0; j < kBlockMaxOrder; ++j) {
        const double v = ctl::real_param(s, names[j], &ok);
        if (j < order) p.a[j] = v;
        else if (v != 0.0) {
          s.error(std::string("OPTIMAL_COMPENSATOR: ") + names[j] + " is set but order is " + std::to_string(order));
          ok = false;
        }
      }
      if (!ok) return nullptr;
      return std::make_unique<optimal_compensator_block::OptimalCompensator>(p);
    }
    const double eps = ctl::real_param(s, "dropout_rate", &ok);
    double r[kBlockMaxOrder + 1] = {1.0};
    const char* names[kBlockMaxOrder] = {"rho1", "rho2", "rho3", "rho4"};
    for (int j = 0; j < kBlockMaxOrder; ++j) r[j + 1] = ctl::real_param(s, names[j], &ok);
    if (!ok) return nullptr;
    try {
      const OptimalDropoutPredictor p = optimal_dropout_predictor(std::span<const double>(r, static_cast<std::size_t>(order) + 1), order, eps);
      return std::make_unique<optimal_compensator_block::OptimalCompensator>(p);
    } catch (const std::invalid_argument& e) {
      s.error(std::string("OPTIMAL_COMPENSATOR: rho1..rho") + std::to_string(order) + ": " + e.what());
      return nullptr;
    }
  };
  r.add(std::move(t));
}

}  // namespace syncplc::motion
