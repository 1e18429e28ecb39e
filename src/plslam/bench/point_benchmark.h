#pragma once
// Per-stage timing of the point front end on real stereo frames, for `plslam bench features`:
// pyramid, FAST, SSC and quadtree on the same candidates, descriptors, stereo matching, plus
// keypoint counts and spatial uniformity. One thread, so the numbers are per-core costs.
#include <cstddef>
#include <functional>

#include <nlohmann/json.hpp>

#include "plslam/features/orb_extractor.h"
#include "plslam/io/dataset.h"

namespace plslam::bench {

struct PointBenchmarkOptions {
  std::size_t max_frames = 0;     // 0: every frame of the dataset
  int distribution_repeats = 5;   // SSC and quadtree timings per frame: median of this many runs
  int n_features = 0;             // 0: 1200 for EuRoC, 2000 for KITTI
  features::OrbOptions orb;                 // n_features is overridden as above
  double right_feature_factor = 2.0;
  // Polled before each frame after the first: true ends the benchmark with the frames measured
  // so far (a signal asked the program to stop).
  std::function<bool()> stop;
};

// JSON keys: pyramid_ms, fast_ms, ssc_ms, quadtree_ms, orb_ms, left_extract_ms,
// stereo_points_ms (objects with median, p90, mean), keypoints, stereo_matches, uniformity_cv
// (objects with median), ssc_speedup, and the configuration used.
nlohmann::json run_point_benchmark(const io::Dataset& dataset, const PointBenchmarkOptions& options);


}  // namespace plslam::bench
