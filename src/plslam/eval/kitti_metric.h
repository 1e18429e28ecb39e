#pragma once
// The official KITTI odometry metric (devkit evaluate_odometry.cpp): relative errors over
// segments of 100, 200, ..., 800 m of ground-truth path, one start every 10 frames, averaged over
// all segments of all lengths.
#include <cstddef>
#include <vector>

#include "plslam/core/types.h"

namespace plslam::eval {

struct KittiSegmentError {
  std::size_t first_frame = 0;
  std::size_t last_frame = 0;
  double length_m = 0.0;
  double t_err = 0.0;  // translation error / length (m/m)
  double r_err = 0.0;  // rotation error / length (rad/m), as the devkit writes it
};

struct KittiMetric {
  double t_rel_percent = 0.0;        // mean t_err * 100
  double r_rel_deg_per_100m = 0.0;   // mean r_err in deg per 100 m (kitti-odom-eval's unit)
  std::vector<KittiSegmentError> segments;
};

// gt and est paired frame by frame (same length). Throws InputError when the ground truth is too
// short for a single 100 m segment.
KittiMetric kitti_odometry_metric(const Trajectory& gt, const Trajectory& est);

}  // namespace plslam::eval
