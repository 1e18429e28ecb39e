#pragma once
// Plain observation records the optimisers consume. Poses are T_cw (world -> camera). Indices
// refer to the keyframe / landmark arrays of the problem that holds the observation.
#include <Eigen/Core>

namespace plslam::optim {

struct StereoPointObservation {
  int keyframe = 0;
  int point = 0;
  Eigen::Vector3d measurement = Eigen::Vector3d::Zero();  // (u_l, v, u_r) in pixels
  bool has_right = true;  // false: no stereo match, u_r is ignored (2-DoF observation)
  int level = 0;          // pyramid level; information = 1 / 1.2^(2 level)
};

struct StereoLineObservation {
  int keyframe = 0;
  int line = 0;
  // Image lines a u + b v + c = 0 with a^2 + b^2 = 1 (geometry::line_through), from the detected
  // left segment and from its matched right segment.
  Eigen::Vector3d left_line = Eigen::Vector3d::Zero();
  Eigen::Vector3d right_line = Eigen::Vector3d::Zero();
  int level = 0;
  double information = 0.5;  // the paper's line information, multiplied by the level information
};

}  // namespace plslam::optim
