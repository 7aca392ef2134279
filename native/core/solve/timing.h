// Wall-clock seconds for the statistics and the time budget: one clock.
#pragma once

#include <chrono>

namespace radiosity {

using Clock = std::chrono::steady_clock;

inline double seconds_since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

}  // namespace radiosity
