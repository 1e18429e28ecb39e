#pragma once
// The process's resident set size, for the per-frame log of long runs (frames.csv rss_mb).

namespace plslam::core {

// Resident memory in MiB from /proc/self/statm; -1 where it cannot be read (not Linux).
double resident_memory_mb();

}  // namespace plslam::core
