#pragma once
// A 3D line landmark: a segment with two world endpoints (see Landmark for observations, LBD
// descriptor, culling statistics). Same ownership and locking rules as MapPoint.
#include <Eigen/Core>

#include "plslam/map/landmark.h"

namespace plslam::map {

class MapLine : public Landmark<MapLine> {
 public:
  MapLine(long id, const Eigen::Vector3d& start, const Eigen::Vector3d& end, KeyFrame* reference,
          long created_frame);

  Eigen::Vector3d start() const;
  Eigen::Vector3d end() const;
  void set_endpoints(const Eigen::Vector3d& start, const Eigen::Vector3d& end);
  Eigen::Vector3d midpoint() const;

  // Mean viewing direction of the midpoint; lines are detected on the finest level only, and LBD
  // bands tolerate about a factor of two in scale either way.
  void update_normal_and_depth();

  static MapLine* slot(const KeyFrame& kf, int index);
  static void set_slot(KeyFrame& kf, int index, MapLine* value);
  static cv::Mat descriptor_row(const KeyFrame& kf, int index);
  static bool is_stereo(const KeyFrame& kf, int index);

 private:
  Eigen::Vector3d start_, end_;
};

}  // namespace plslam::map
