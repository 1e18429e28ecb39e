#pragma once
// Smooth, physically plausible camera motion along a scene's closed path: a closed cubic
// B-spline through the path's control points, traversed at constant speed, with hand-held
// sway, bobbing and looking around (or, for a car, a steady heading).
#include <cstdint>
#include <vector>

#include <Eigen/Geometry>

#include "plslam/synth/scene.h"

namespace plslam::synth {

// Another walk (or drive) through the same scene, for testing localization on images a map never
// saw: where on the loop it starts, which way it goes, and a constant sideways and height offset.
struct PathVariation {
  double start = 0;      // arc-length offset as a share of the loop, in [0, 1)
  bool reverse = false;  // travel the loop the other way round
  double lateral = 0;    // metres to the left of the path (in the direction of travel)
  double height = 0;     // metres up
};
// The variation of `synth --path-seed`: 0 is none (the scene's own path); others draw a start
// anywhere on the loop, either direction, and offsets of up to +-0.25 m sideways and +-0.1 m in
// height on foot, +-0.5 m and +-0.05 m in a car (within the scene's clearance either way).
PathVariation path_variation(std::uint64_t path_seed, bool vehicle);

class CameraPath {
 public:
  // speed in m/s along the path; the seed sets the phases of the hand-held wobble (mixed with
  // the path seed when there is one).
  CameraPath(const Scene& scene, double speed, std::uint64_t seed, std::uint64_t path_seed = 0);

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
  PathVariation variation_;
};

// Rotation camera -> world for yaw (about world z, 0 = looking along +x), pitch (up positive)
// and roll (about the viewing direction).
Eigen::Matrix3d camera_rotation(double yaw, double pitch, double roll);

}  // namespace plslam::synth
