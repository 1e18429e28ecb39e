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

  // BA constrains a line's endpoints only across the line: each endpoint is held by the same
  // planes (one per observed image line), so along the line it is free, and with noisy planes
  // both endpoints converge to the one point that fits the planes best: the segment collapses and
  // no image matches it again. This re-estimates the line from that point and its observations:
  // the direction that lies in all observed planes (the weakest direction of the sum of their
  // normals' outer products; the current one where the planes do not fix it), then the endpoints
  // at the extent of the observed segments (each endpoint's viewing ray meets the line at its
  // closest point; rays within 5 degrees of the line are skipped). False when nothing changed.
  bool refit_to_observations();

  static MapLine* slot(const KeyFrame& kf, int index);
  static void set_slot(KeyFrame& kf, int index, MapLine* value);
  static cv::Mat descriptor_row(const KeyFrame& kf, int index);
  static bool is_stereo(const KeyFrame& kf, int index);

 private:
  Eigen::Vector3d start_, end_;
};

}  // namespace plslam::map
