#pragma once
// A landmark projected into a keyframe with a given pose: which of the keyframe's features it is.
// Local mapping fuses duplicates with it (the keyframe's own pose), loop closing fuses the two
// sides of a loop (the corrected pose, before it is written).
#include "plslam/geometry/se3.h"
#include "plslam/map/keyframe.h"
#include "plslam/map/map_line.h"
#include "plslam/map/map_point.h"

namespace plslam::mapping {

struct ProjectionMatchOptions {
  double point_radius = 3.0;     // search radius in pixels at the predicted level, times its scale
  double point_chi2 = 7.8;       // bound on the squared pixel error over the keypoint's level sigma^2
  int point_max_hamming = 50;    // a match must be strictly closer than this
  double line_radius = 6.0;      // pixels: both projected endpoints to the keyframe line
  double line_max_angle_deg = 10;
  double line_min_overlap = 0.3;  // of the projected segment's length
  int line_max_hamming = 80;      // of 256 LBD bits
};

// The index of the keypoint of `kf` that `mp` projects onto with pose T_cw (camera centre O), or
// -1: in front, inside the image, inside the point's distance range, and nearest in descriptor.
int match_point_in_keyframe(const map::KeyFrame& kf, const geometry::SE3& T_cw, const Eigen::Vector3d& O,
                            const map::MapPoint& mp, const ProjectionMatchOptions& o = {});

// The index of the line of `kf` that `ml` projects onto with pose T_cw, or -1: nearly parallel,
// both projected endpoints close to it, overlapping, and nearest in LBD distance.
int match_line_in_keyframe(const map::KeyFrame& kf, const geometry::SE3& T_cw, const map::MapLine& ml,
                           const ProjectionMatchOptions& o = {});

}  // namespace plslam::mapping
