#pragma once
// Small value types shared by every stage.
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <vector>

namespace plslam {

// A pose with its time in seconds. T maps points from the sensor frame to the world frame
// (T_wc for a camera trajectory).
struct StampedPose {
  double t = 0.0;
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
};

using Trajectory = std::vector<StampedPose>;

// Rectified stereo pinhole model: the only camera model the SLAM stages see.
struct StereoCalibration {
  int width = 0;
  int height = 0;
  double fx = 0, fy = 0, cx = 0, cy = 0;
  double baseline = 0;  // metres, positive: the right camera sits at +baseline along x
  double bf() const { return baseline * fx; }
};

}  // namespace plslam
