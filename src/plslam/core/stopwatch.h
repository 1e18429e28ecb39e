#pragma once
// Milliseconds of wall clock since a steady_clock time point, for per-stage timings.
#include <chrono>

namespace plslam {

inline double ms_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

}  // namespace plslam
