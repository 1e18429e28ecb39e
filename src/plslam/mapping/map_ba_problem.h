#pragma once
// A bundle-adjustment problem built from map objects, with the way back from its arrays to the
// objects: local BA (a window of keyframes) and global BA (all of them) both fill one.
#include <unordered_map>
#include <vector>

#include "plslam/geometry/se3.h"
#include "plslam/inertial/preintegration.h"
#include "plslam/map/keyframe.h"
#include "plslam/map/map_line.h"
#include "plslam/map/map_point.h"
#include "plslam/optim/bundle_adjustment.h"

namespace plslam::mapping {

class MapBaProblem {
 public:
  // line_information and far_stereo_baselines as LocalMapperOptions; lines false: points only.
  MapBaProblem(double line_information, double far_stereo_baselines, bool lines);

  // Adds the keyframe once, with its current pose; returns its index.
  int add_keyframe(map::KeyFrame* kf, bool fixed);
  // The points (and lines) these keyframes see, each once, with every observation by a good
  // keyframe; observers not added yet join as fixed keyframes.
  void add_landmarks_of(const std::vector<map::KeyFrame*>& keyframes);
  // An IMU factor (inertial/imu_ba_factor.h) between each keyframe of `chain` with an IMU state and
  // its predecessor in the IMU chain, and every keyframe's extra state ([v; bg; ba], zero without
  // a state). A predecessor not in the problem joins fixed when `add_missing`, else that factor is
  // left out. A preintegration whose first keyframe's bias moved past `reintegration` is
  // integrated again at it. Call after every keyframe is added.
  void add_imu_factors(const std::vector<map::KeyFrame*>& chain, const geometry::SE3& T_imu_cam,
                       const inertial::ReintegrationThresholds& reintegration, bool add_missing);
  // A whole map's BA: a fixed keyframe that holds the gauge and has IMU factors is held by its
  // camera centre and heading alone (inertial/gauge_prior_factor.h); gravity sets its roll and
  // pitch, and its velocity and biases are estimated. Call after add_imu_factors.
  void hold_imu_gauge_by_centre_and_heading();
  // Writes a result's velocities and biases into the free keyframes that have IMU factors (their
  // states become `estimated`).
  void write_back_imu_states(const optim::BaResult& result) const;

  optim::BaProblem problem;
  std::vector<map::KeyFrame*> keyframes;  // indexed like problem.keyframes
  std::vector<map::MapPoint*> points;     // like problem.points
  std::vector<map::MapLine*> lines;       // like problem.lines
  // Per observation (like problem.point_observations / line_observations): the observer.
  std::vector<map::KeyFrame*> point_observers;
  std::vector<map::KeyFrame*> line_observers;

 private:
  double line_information_;
  double far_stereo_baselines_;
  bool with_lines_;
  std::unordered_map<const map::KeyFrame*, int> index_;
  void fill_keyframe_extra();
  std::vector<bool> in_keyframe_factor() const;  // per keyframe: in some keyframe factor
};

}  // namespace plslam::mapping
