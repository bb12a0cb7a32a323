// Frame loss of the simulated network: none, Bernoulli (independent losses
// with probability p) or Gilbert-Elliott (a two-state Markov chain: in the
// good state frames are lost with probability loss_good, in the bad state with
// loss_bad; good -> bad with p_good_bad and bad -> good with p_bad_good per
// frame), which makes the bursts real networks show. The long-run loss rate
// is pi_bad loss_bad + (1 - pi_bad) loss_good, pi_bad = p_gb / (p_gb + p_bg).
#pragma once

#include "runtime/core/sim_random.hpp"

namespace syncplc {

struct LossConfig {
  enum class Model { None, Bernoulli, GilbertElliott };
  Model model = Model::None;
  double p = 0;                    // Bernoulli
  double p_good_bad = 0, p_bad_good = 1, loss_good = 0, loss_bad = 1;  // Gilbert-Elliott

  double mean_rate() const {
    switch (model) {
      case Model::None: return 0;
      case Model::Bernoulli: return p;
      case Model::GilbertElliott: {
        double pi_bad = p_good_bad + p_bad_good > 0 ? p_good_bad / (p_good_bad + p_bad_good) : 0;
        return pi_bad * loss_bad + (1 - pi_bad) * loss_good;
      }
    }
    return 0;
  }
};

// One loss process (a frame, or one link): call lost() once per frame.
class LossProcess {
 public:
  LossProcess() = default;
  explicit LossProcess(const LossConfig& c) : c_(c) {}
  bool lost(SimRandom& rng) noexcept {
    switch (c_.model) {
      case LossConfig::Model::None: return false;
      case LossConfig::Model::Bernoulli: return rng.chance(c_.p);
      case LossConfig::Model::GilbertElliott:
        bad_ = bad_ ? !rng.chance(c_.p_bad_good) : rng.chance(c_.p_good_bad);
        return rng.chance(bad_ ? c_.loss_bad : c_.loss_good);
    }
    return false;
  }

 private:
  LossConfig c_;
  bool bad_ = false;
};

}  // namespace syncplc
