// How far the current pass is, for the progress bar (SolveProgress::fraction),
// so that the bar moves while a pass refines and gathers instead of standing
// still until the pass ends (it sat at one value while a pass grew from 376 to
// 2,623 elements).
//
// Refinement takes the first kRefiningShare of a pass: the leaves made so far,
// x of the count the pass is expected to make (the previous pass's growth, at
// least a doubling), counted as x / (1 + x): half way at the expected count,
// never complete while refinement goes on. Gathering takes the rest: the
// decades the residual has fallen from the pass's first towards the
// tolerance, or the iterations done of a fixed number.
#pragma once

#include <cstddef>

namespace radiosity {

class PassProgress {
 public:
  static constexpr double kRefiningShare = 0.6;
  static constexpr double kLeastGrowth = 2.0;

  // A pass starts with `leaves` (the previous pass's growth sets what it expects).
  void start(std::size_t leaves);
  // Refinement has made the hierarchy `leaves` leaves.
  void refined(std::size_t leaves);
  // An iteration gathered with this residual, against `tolerance`; or, where
  // the tolerance is not positive (a fixed number of iterations), iteration
  // `done` of `iterations`.
  void gathered(double residual, double tolerance, int done, int iterations);
  // How far the pass is, 0 to 1 (1 only once it has converged).
  double within() const { return kRefiningShare * refined_ + (1.0 - kRefiningShare) * gathered_; }

 private:
  std::size_t start_ = 0;
  double expected_ = 1.0;  // new leaves the pass is expected to make
  double refined_ = 0.0, gathered_ = 0.0;
  double first_residual_ = 0.0;
};

}  // namespace radiosity
