#pragma once
// Smooth, physically plausible camera motion along a scene's closed path: a closed cubic
// B-spline through the path's control points, traversed at (nearly) constant speed, with hand-held
// sway, bobbing and looking around (or, for a car, a steady heading), and optionally the fast turns
// and shake of a hand-held rig or a drone. The motion is smooth to second order everywhere (C2),
// and its velocity, acceleration and angular velocity are exact derivatives, for the synthetic IMU.
#include <cstdint>
#include <string>
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

// What moves the camera along the path. kWalk is the scene's own motion (a walker, or a car on the
// street). kHandheld adds a rig carried by hand: quick looks aside (up to 3 rad/s) and hand shake;
// kDrone adds a multicopter's fast yaw turns, swoops with the tilt they need, and vibration.
// Accelerations reach about 10 m/s^2 in both.
enum class MotionProfile { kWalk, kHandheld, kDrone };
const char* to_string(MotionProfile m);
MotionProfile parse_motion_profile(const std::string& name);  // walk|handheld|drone; InputError else

// The camera's motion at one instant, exact to rounding: the pose and its time derivatives.
struct CameraKinematics {
  Eigen::Isometry3d T_wc = Eigen::Isometry3d::Identity();
  Eigen::Vector3d velocity = Eigen::Vector3d::Zero();      // of the camera centre, world frame, m/s
  Eigen::Vector3d acceleration = Eigen::Vector3d::Zero();  // of the camera centre, world frame, m/s^2
  Eigen::Matrix3d R_dot = Eigen::Matrix3d::Zero();         // d/dt of R_wc
  Eigen::Matrix3d R_ddot = Eigen::Matrix3d::Zero();        // d2/dt2 of R_wc
};

class CameraPath {
 public:
  // speed in m/s along the path; the seed sets the phases of the hand-held wobble (mixed with
  // the path seed when there is one).
  CameraPath(const Scene& scene, double speed, std::uint64_t seed, std::uint64_t path_seed = 0,
             MotionProfile motion = MotionProfile::kWalk);

  double length() const { return length_; }  // one full loop, metres
  double speed() const { return speed_; }
  MotionProfile motion() const { return motion_; }
  // T_wc of the (left) camera at time t seconds: x right, y down, z forward.
  Eigen::Isometry3d pose(double t) const;
  CameraKinematics kinematics(double t) const;

 private:
  template <class S>
  void evaluate(const S& t, S (&R)[3][3], S (&p)[3]) const;
  template <class S>
  void position(const S& s, S (&xy)[2]) const;  // at arc length s (wraps around the loop)
  template <class S>
  S heading(const S& s, double window) const;

  std::vector<Eigen::Vector2d> control_;  // the closed B-spline's control points
  // Arc length -> spline parameter: u(s) = s * control_.size() / length_ + a closed cubic B-spline
  // through these offsets at uniform knots, so that the composition is C2 and nearly unit-speed.
  std::vector<double> u_offset_;
  double length_ = 0;
  double speed_;
  double height_;
  bool vehicle_;
  double look_around_;
  double phase_[6];
  double motion_phase_[12];
  PathVariation variation_;
  MotionProfile motion_;
};

// Rotation camera -> world for yaw (about world z, 0 = looking along +x), pitch (up positive)
// and roll (about the viewing direction).
Eigen::Matrix3d camera_rotation(double yaw, double pitch, double roll);

}  // namespace plslam::synth
