#pragma once
// Smooth, physically plausible camera motion along a scene's closed path: a closed cubic
// B-spline through the path's control points, traversed at constant speed, with hand-held
// sway, bobbing and looking around (or, for a car, a steady heading).
#include <cstdint>
#include <vector>

#include <Eigen/Geometry>

#include "plslam/synth/scene.h"

namespace plslam::synth {

class CameraPath {
 public:
  // speed in m/s along the path; the seed sets the phases of the hand-held wobble.
  CameraPath(const Scene& scene, double speed, std::uint64_t seed);

  double length() const { return cumulative_.back(); }  // one full loop, metres
  double speed() const { return speed_; }
  // T_wc of the (left) camera at time t seconds: x right, y down, z forward.
  Eigen::Isometry3d pose(double t) const;

 private:
  Eigen::Vector2d position(double s) const;  // at arc length s (wraps around the loop)
  double heading(double s, double window) const;

  std::vector<Eigen::Vector2d> samples_;
  std::vector<double> cumulative_;
  double speed_;
  double height_;
  bool vehicle_;
  double look_around_;
  double phase_[6];
};

// Rotation camera -> world for yaw (about world z, 0 = looking along +x), pitch (up positive)
// and roll (about the viewing direction).
Eigen::Matrix3d camera_rotation(double yaw, double pitch, double roll);

}  // namespace plslam::synth
