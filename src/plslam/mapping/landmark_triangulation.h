#pragma once
// New landmarks from a new keyframe and its best covisible neighbours (ORB-SLAM2's
// CreateNewMapPoints, with lines): free keypoints matched along epipolar lines and triangulated
// from the two views; free stereo lines (too far for tracking to create them) intersected with
// the plane of their match in the neighbour. Each new landmark is observed by both keyframes.
#include <vector>

#include "plslam/map/map.h"

namespace plslam::mapping {

struct TriangulationOptions {
  int neighbors = 10;                // best covisible keyframes paired with the new one
  // Camera centres closer than this many stereo baselines add nothing to the stereo depth.
  double min_baselines = 1;
  int point_max_hamming = 50;        // ORB-SLAM2's TH_LOW: a match is strictly closer than this
  // Rays closer to parallel than this cosine: stereo depth already did better.
  double max_parallax_cos = 0.9998;
  // The ratio of distances to the two cameras must agree with the ratio of the octaves' scales
  // to within this factor times the pyramid's scale factor.
  double scale_tolerance = 1.5;
  bool lines = true;
  int line_max_hamming = 60;         // a line match is strictly closer than this (of 256 LBD bits)
  double line_min_ray_plane_sine = 0.05;  // geometry::triangulate_line: nearly epipolar lines fail
  // The two-view segment's endpoint depths must agree with view 1's stereo ones to within this share.
  double line_depth_tolerance = 0.2;
};

struct NewLandmarks {
  std::vector<map::MapPoint*> points;  // in creation order
  std::vector<map::MapLine*> lines;
};

// Triangulates between `kf` and each of its `neighbors` best covisibles in turn, creating the
// landmarks in `map`; each is observed by both keyframes, with its descriptor, normal and range.
NewLandmarks triangulate_new_landmarks(map::Map& map, map::KeyFrame& kf, const TriangulationOptions& o);

}  // namespace plslam::mapping
