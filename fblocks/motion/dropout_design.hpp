// Ling & Lemmon's optimal dropout compensator: the taps a_1..a_N that
// minimise the loop's stationary output power E[y^2] under Bernoulli
// dropouts (dropout_loop.hpp), found numerically with NLopt
// (docs/motion/dropout-compensators.md, "Minimising it").
#pragma once

#include <string>
#include <vector>

#include "fblocks/motion/dropout_loop.hpp"

namespace syncplc::motion {

struct DropoutDesign {
  std::vector<double> taps;          // a_1..a_N
  double output_power = 0;           // E[y^2] with these taps
  double gradient_norm = 0;          // |dE[y^2]/da| there (a certificate of a stationary point)
  int evaluations = 0;               // output-power evaluations spent
  std::string start;                 // which start point the optimum came from
};

// Minimises E[y^2] over taps of length `order` (1..16) for dropout rate
// eps in [0, 1). Local searches (NLopt's Subplex, then its L-BFGS) start from
// zero fill, hold, its negative, and the best point of a scan of a_1; the
// best mean-square stable result wins. Throws std::invalid_argument with the
// reason for a bad loop, order or eps, and std::runtime_error when no
// mean-square stable compensator was found (then even zero fill is
// unstable: the loop cannot stand this loss rate with any start tried).
DropoutDesign design_dropout_compensator(const DropoutLoop& loop, int order, double eps);

}  // namespace syncplc::motion
