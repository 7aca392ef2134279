#include "core/solve/convergence.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>

namespace radiosity {
namespace {

// Worth it only when convergence is slow; the ratio must agree with the last
// one to within this much, for this many iterations, to be trusted as a
// single mode's; the tail factor is capped (r = 0.995 at most).
constexpr double kSlowRatio = 0.7;
constexpr double kRatioAgreement = 0.01;
constexpr int kSteadyIterations = 3;
constexpr double kMaxTail = 200.0;
constexpr int kWaitAfter = 3;

}  // namespace

void TailExtrapolation::before(const Hierarchy& h) {
  const auto& elements = h.elements();
  previous_.resize(elements.size());
  tbb::parallel_for(tbb::blocked_range<size_t>(0, elements.size()), [&](const auto& range) {
    for (size_t e = range.begin(); e != range.end(); ++e) previous_[e] = elements[e].radiance;
  });
}

bool TailExtrapolation::after(Hierarchy& h, double residual, bool links_changed) {
  const double ratio = last_residual_ > 0.0 ? residual / last_residual_ : 0.0;
  last_residual_ = residual;
  if (links_changed || !std::isfinite(ratio)) {
    steady_ = 0;
    last_ratio_ = 0.0;
    return false;
  }
  const bool steady =
      ratio > kSlowRatio && ratio < 1.0 && std::abs(ratio - last_ratio_) < kRatioAgreement * ratio;
  last_ratio_ = ratio;
  steady_ = steady ? steady_ + 1 : 0;
  if (wait_ > 0) {
    if (--wait_ == 0 && residual > residual_before_) failed_ = true;
    return false;
  }
  if (failed_ || steady_ < kSteadyIterations) return false;
  const double tail = std::min(kMaxTail, ratio / (1.0 - ratio));
  auto& elements = h.elements();
  tbb::parallel_for(tbb::blocked_range<size_t>(0, elements.size()), [&](const auto& range) {
    for (size_t e = range.begin(); e != range.end(); ++e) {
      Rgb& l = elements[e].radiance;
      l = glm::max(l + tail * (l - previous_[e]), Rgb(0.0));
    }
  });
  steady_ = 0;
  wait_ = kWaitAfter;
  residual_before_ = residual;
  last_residual_ = 0.0;  // the next change is not part of the same tail
  return true;
}

}  // namespace radiosity
