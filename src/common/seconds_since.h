#pragma once
// Wall time of a stage, for timings that are printed (never for results).
#include <chrono>

namespace treeanim {

// Seconds elapsed since `start` on the steady clock.
inline double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

}  // namespace treeanim
