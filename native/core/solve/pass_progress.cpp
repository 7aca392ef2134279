#include "core/solve/pass_progress.h"

#include <algorithm>
#include <cmath>

namespace radiosity {

void PassProgress::start(std::size_t leaves) {
  const double now = static_cast<double>(std::max<std::size_t>(leaves, 1));
  const double growth = start_ > 0 ? now / static_cast<double>(start_) : 0.0;
  expected_ = (std::max(growth, kLeastGrowth) - 1.0) * now;
  start_ = std::max<std::size_t>(leaves, 1);
  refined_ = gathered_ = first_residual_ = 0.0;
}

void PassProgress::refined(std::size_t leaves) {
  const double x = static_cast<double>(leaves > start_ ? leaves - start_ : 0) / expected_;
  refined_ = std::max(refined_, x / (1.0 + x));
}

void PassProgress::gathered(double residual, double tolerance, int done, int iterations) {
  double g = 0.0;
  if (!(tolerance > 0.0)) {
    g = iterations > 0 ? static_cast<double>(done) / static_cast<double>(iterations) : 1.0;
  } else if (!(residual > tolerance)) {
    g = 1.0;
  } else {
    if (!(first_residual_ > 0.0)) first_residual_ = residual;
    const double span = std::log(first_residual_ / tolerance);
    g = span > 0.0 ? std::log(first_residual_ / residual) / span : 0.0;
  }
  gathered_ = std::max(gathered_, std::clamp(g, 0.0, 1.0));
}

}  // namespace radiosity
