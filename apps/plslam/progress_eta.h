#pragma once
// Long commands log "N/M ..., ETA S s": the remaining time at the mean pace so far.
#include <chrono>
#include <cstddef>

namespace plslam::cli {

inline double eta_seconds(std::chrono::steady_clock::time_point start, std::size_t done, std::size_t total) {
  if (done == 0 || done >= total) return 0.0;
  const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return elapsed / static_cast<double>(done) * static_cast<double>(total - done);
}

}  // namespace plslam::cli
