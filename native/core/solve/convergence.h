// Faster convergence of the Jacobi iteration in bright scenes. Each gather
// carries light one more bounce, so in a white room (rho = 0.99) the radiance
// creeps up by a factor close to rho per iteration: 900 iterations to 1e-6.
// What remains is, after a few iterations, nearly one mode (the scene's
// ambient light), which shrinks by a fixed ratio r per iteration: the change
// of the last iteration, dL, times r / (1 - r) is what the rest of the
// iterations would still add (the geometric tail; Aitken's extrapolation on
// the whole vector of radiances). It is added once the ratio has held steady,
// then the iteration carries on, so the result is the converged one whatever
// the extrapolation got wrong. An extrapolation after which the iterations
// change the radiances more than before it took a mode for the tail that was
// not (one that alternates in sign, from broken geometry): extrapolating
// again would feed it, and a bent quad with its reversed copy overflowed
// (fuzzing), so the rest of the solve iterates plainly.
#pragma once

#include <vector>

#include "core/hierarchy/hierarchy.h"

namespace radiosity {

class TailExtrapolation {
 public:
  // Call before each iteration's push/pull.
  void before(const Hierarchy& hierarchy);
  // Call after it with its residual (relative change) and whether the links
  // changed in this iteration; returns true if it extrapolated the radiances.
  bool after(Hierarchy& hierarchy, double residual, bool links_changed);

 private:
  std::vector<Rgb> previous_;  // radiance per element before the iteration
  double last_ratio_ = 0.0, last_residual_ = 0.0;
  int steady_ = 0;                // iterations in a row with a steady ratio
  int wait_ = 0;                  // iterations to let pass after an extrapolation
  double residual_before_ = 0.0;  // of the iteration that extrapolated
  bool failed_ = false;           // an extrapolation made things worse
};

}  // namespace radiosity
