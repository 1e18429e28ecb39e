#pragma once
// Geometric verification of a loop candidate in SE(3): stereo fixes the scale, so the relative
// pose of the two keyframes is a rigid transform. From BoW matches between their map points, a
// RANSAC over 3-point Umeyama alignments (seeded), scored by reprojection errors in both keyframes
// (depth errors grow with depth squared, pixel errors do not), then refined over the query's pixel
// errors of the inliers (loop closing then searches the place by projection and refines again).
// Perceptual aliasing gives matches that agree on no single transform, and is rejected.
#include <cstdint>
#include <optional>
#include <utility>
#include <vector>

#include "plslam/geometry/se3.h"
#include "plslam/place/bow_matching.h"
#include "plslam/place/keyframe_database.h"

namespace plslam::map {
class KeyFrame;
class MapPoint;
}  // namespace plslam::map

namespace plslam::loop {

struct LoopVerifierOptions {
  int min_matches = 20;        // BoW matches between map points before RANSAC
  int ransac_iterations = 300;
  double chi2 = 9.21;          // squared reprojection error bound, 2 DoF at 99 %, times the level's scale^2
  int min_inliers = 20;        // after RANSAC and refinement (ORB-SLAM2: 20)
  std::uint32_t seed = 1;
  place::BowMatchOptions bow;
  void validate() const;
};

struct LoopConstraint {
  map::KeyFrame* query = nullptr;
  map::KeyFrame* candidate = nullptr;
  geometry::SE3 T_query_candidate;  // the candidate's camera frame into the query's
  // Query keyframe's map points matched to the candidate's, inliers of the transform.
  std::vector<std::pair<map::MapPoint*, map::MapPoint*>> matches;
  int inliers = 0;  // matches.size() here; loop closing's projection check raises it
};

// The constraint when the candidate passes; nullopt otherwise. Reads map points' positions and the
// keyframes' poses: hold the map's update lock (or stop local mapping) while it runs.
std::optional<LoopConstraint> verify_loop(map::KeyFrame* query, map::KeyFrame* candidate,
                                          const place::KeyframeDatabase& database,
                                          const LoopVerifierOptions& options = {});

}  // namespace plslam::loop
