#pragma once
// Local bundle adjustment around a new keyframe (ORB-SLAM2's LocalBundleAdjustment, with lines):
// which keyframes and landmarks it optimises, which keyframes stay fixed, and how the result goes
// back into the map.
#include <atomic>
#include <vector>

#include "plslam/inertial/preintegration.h"
#include "plslam/map/map.h"
#include "plslam/mapping/map_ba_problem.h"
#include "plslam/optim/bundle_adjustment.h"

namespace plslam::mapping {

struct LocalBaOptions {
  int iterations = 5;          // first pass (ORB-SLAM2: 5 + 10 without outliers)
  int second_iterations = 10;
  // Shared with tracking and loop closing: LocalMapper sets them from LocalMapperOptions.
  double line_information = 0.5;
  double far_stereo_baselines = 0;
  bool lines = true;
  // A visual-inertial map: the window also holds the last `imu_window` keyframes of the new
  // keyframe's IMU chain (map::KeyFrameImu), free, with their velocities and biases and an IMU
  // factor between each consecutive pair, and the keyframe before them held fixed (ORB-SLAM3's
  // local inertial BA). 0: no IMU in local BA. `T_imu_cam` is the input's (ImuData::T_imu_cam).
  int imu_window = 0;
  geometry::SE3 T_imu_cam;
  // A factor's preintegration is integrated again once its first keyframe's bias moved this far
  // from the bias it was integrated at.
  inertial::ReintegrationThresholds reintegration;
};

// The window of `kf`: it and its good covisibles are optimised, except the map's origin, which
// stays fixed; so are the points (and lines) they see; every other good keyframe that sees those
// landmarks joins fixed (with the IMU chain's keyframes when o.imu_window > 0). `also_free`: keyframes optimised with them, covisible or not (the
// keyframes mapped before `kf` in one go, whose BA this one is; bad ones are left out).
MapBaProblem local_ba_window(map::KeyFrame& kf, const LocalBaOptions& o,
                             const std::vector<map::KeyFrame*>& also_free = {});

// Writes a BA result of `window` back into the map: removes the outlier observations, sets the
// poses of the free keyframes (and the velocities and biases of those in its IMU chain), the positions of good points and the endpoints of good lines (each
// line refitted to its observations), with their normals and ranges. The caller holds the map's
// update mutex.
void write_back_local_ba(const MapBaProblem& window, const optim::BaResult& result);

// The solver's step alone: reads only `window`'s arrays, never the map, so it may run beside
// tracking (deterministic mode). `kf` gives the camera and the scale factor.
optim::BaResult solve_local_ba(const MapBaProblem& window, const map::KeyFrame& kf, const LocalBaOptions& o,
                               const std::atomic<bool>* abort = nullptr);

// Writes a usable result back under the map's update mutex and tells snapshot readers; false
// (logged at debug level) when the result is unusable.
bool apply_local_ba(map::Map& map, const MapBaProblem& window, const optim::BaResult& result);

// Builds the window of `kf`, optimises it and writes the result back under the map's update
// mutex. False when there was nothing to optimise or the solver's result was unusable. `abort`
// (may be null), raised from another thread, stops the solver after its current iteration; the
// partial result is written back and `*aborted` (may be null) says so.
bool run_local_ba(map::Map& map, map::KeyFrame& kf, const LocalBaOptions& o,
                  const std::atomic<bool>* abort = nullptr, bool* aborted = nullptr);

}  // namespace plslam::mapping
