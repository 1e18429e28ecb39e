#pragma once
// Duplicate map points (ORB-SLAM2's SearchInNeighbors, points): a new keyframe's points are
// projected into its best covisibles; where the neighbour's matching keypoint already has a map
// point, the two are one landmark and the less observed one is replaced by the other.
#include "plslam/map/keyframe.h"
#include "plslam/mapping/keyframe_projection.h"

namespace plslam::mapping {

struct FusionOptions {
  int neighbors = 10;  // best covisible keyframes searched
  ProjectionMatchOptions match;
};

// Fuses the map points of `kf` with those of its neighbours (or adds the observation where the
// neighbour's keypoint is free), refreshes their descriptors and ranges and kf's covisibility.
// Returns the number of fused pairs.
int fuse_landmarks(map::KeyFrame& kf, const FusionOptions& o);

}  // namespace plslam::mapping
