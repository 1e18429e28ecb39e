#pragma once
// A 3D point landmark (see Landmark for observations, descriptor, culling statistics). Owned by
// the Map; everything else holds non-owning pointers valid for the Map's lifetime.
#include <Eigen/Core>

#include "plslam/map/landmark.h"

namespace plslam::map {

class MapPoint : public Landmark<MapPoint> {
 public:
  MapPoint(long id, const Eigen::Vector3d& position, KeyFrame* reference, long created_frame);

  Eigen::Vector3d position() const;
  void set_position(const Eigen::Vector3d& p);

  // Mean viewing direction, and the distances at which the point can be detected: the reference
  // observation's level and the pyramid give the scale-invariance range (with ORB-SLAM2's 0.8/1.2
  // margins in min_distance()/max_distance()).
  void update_normal_and_depth();
  // Pyramid level at which a point seen at `distance` should be detected.
  int predict_level(double distance, int levels, double scale_factor) const;
  // The distance at which it would be seen at level 0 (map files store it as is).
  double level0_max_distance() const;
  void restore_level0_max_distance(double d);

  // Where a point sits in a keyframe (Landmark's CRTP hooks).
  static MapPoint* slot(const KeyFrame& kf, int index);
  static void set_slot(KeyFrame& kf, int index, MapPoint* value);
  static cv::Mat descriptor_row(const KeyFrame& kf, int index);
  static bool is_stereo(const KeyFrame& kf, int index);

 private:
  Eigen::Vector3d position_;
  double level0_max_distance_ = 0;  // distance at which it would be seen at level 0
};

}  // namespace plslam::map
