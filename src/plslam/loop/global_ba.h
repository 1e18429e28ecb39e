#pragma once
// Global bundle adjustment after a loop correction (ORB-SLAM2's RunGlobalBundleAdjustment): every
// keyframe, point and line, with the stereo point and line reprojection errors, optimised from a
// snapshot of the map while tracking and local mapping go on. The result is merged afterwards:
// what the BA optimised takes its result, and what the map gained meanwhile (new keyframes and
// landmarks) moves with its parent or reference keyframe through the spanning tree.
#include <atomic>
#include <memory>
#include <optional>

#include "plslam/map/map.h"
#include "plslam/inertial/preintegration.h"
#include "plslam/mapping/map_ba_problem.h"
#include "plslam/optim/bundle_adjustment.h"

namespace plslam::loop {

struct GlobalBaOptions {
  int iterations = 10;  // ORB-SLAM2: 10
  // Then the observations beyond their chi-square gate are dropped and `iterations` more run
  // without them. With the robust pass alone, 5 of 88 concurrent runs of the office loop went from
  // a good map (ATE ~0.01 m) to a bent one (0.03-0.05 m): wrong associations, of lines mostly
  // (global BA without lines did not bend either), still pulled it. 0 of 60 with the gate.
  bool remove_outliers = true;
  double line_information = 0.5;
  double far_stereo_baselines = 0;
  bool lines = true;
  // A visual-inertial map (LoopCloser::use_imu): the IMU factors between consecutive keyframes of
  // the IMU chain join the BA, with every keyframe's velocity and biases. The map's origin holds
  // the gauge as before, but where it is in the IMU chain by its centre and heading alone: gravity
  // sets its roll and pitch (inertial/gauge_prior_factor.h).
  std::optional<geometry::SE3> T_imu_cam;
  inertial::ReintegrationThresholds reintegration;
  void validate() const;
};

struct GlobalBaSnapshot {
  std::unique_ptr<mapping::MapBaProblem> problem;
  geometry::StereoCamera camera;
};

struct GlobalBaMergeStats {
  int keyframes = 0;             // optimised
  int propagated_keyframes = 0;  // made during the BA, moved through the spanning tree
  int points = 0, lines = 0;     // optimised
  int moved_points = 0, moved_lines = 0;  // made during the BA, moved with their reference
};

// Every good keyframe (the map's first fixed) and landmark. Hold the map's update lock.
GlobalBaSnapshot snapshot_for_global_ba(const map::Map& map, const GlobalBaOptions& options);

// The optimisation itself: no map access, so it runs without locks. `abort` stops it early.
optim::BaResult run_global_ba(const GlobalBaSnapshot& snapshot, const GlobalBaOptions& options,
                              const std::atomic<bool>* abort = nullptr);

// Writes the result into the map. Call with local mapping paused and the update lock held.
GlobalBaMergeStats merge_global_ba(map::Map& map, const GlobalBaSnapshot& snapshot, const optim::BaResult& result);

}  // namespace plslam::loop
