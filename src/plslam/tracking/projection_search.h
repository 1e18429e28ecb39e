#pragma once
// Data association for tracking: map points and map lines are projected into the frame with its
// current pose estimate, and matched by descriptor to the features found near the projection.
#include <vector>

#include "plslam/tracking/frame.h"

namespace plslam::tracking {

struct SearchOptions {
  int point_max_hamming = 100;   // ORB-SLAM2's TH_HIGH
  double point_ratio = 0.8;      // best < ratio * second best (local map search)
  int line_max_hamming = 80;     // of 256 LBD bits
  double line_max_angle_deg = 10;
  double line_min_overlap = 0.3; // of the projected segment's length
};

// Matches the map points of `last` into `cur` within radius * scale(level) pixels of their
// projection (ORB-SLAM2's motion-model search). Returns the number of new matches.
int search_points_from_frame(Frame& cur, const Frame& last, double radius, const SearchOptions& o = {});

// Matches `candidates` (visible map points of the local map not yet matched in `cur`). The
// radius grows when the viewing direction differs from the point's mean one.
int search_points_in_local_map(Frame& cur, const std::vector<map::MapPoint*>& candidates, double radius,
                               const SearchOptions& o = {});

// How many of `points` the frame can see from its pose (in front, inside the image, within their
// scale range, less than 60 degrees off their mean viewing direction), matched or not.
int count_visible_points(const Frame& f, const std::vector<map::MapPoint*>& points);

// Where in the image the frame's inliers explain the map: the image is cut into `cols` x `rows`
// cells; `predicted` counts the cells where at least `min_points` of `points` are visible from the
// frame's pose, `covered` those of them holding at least one of the frame's inlier matches. A true
// place is matched all over the part of the image the map covers; a look-alike only where the
// repeated object is, while the map's surroundings, visible from the same pose, find nothing.
struct CellCoverage {
  int predicted = 0;
  int covered = 0;
  double share() const { return predicted > 0 ? static_cast<double>(covered) / predicted : 0.0; }
};
CellCoverage cell_coverage(const Frame& f, const std::vector<map::MapPoint*>& points, int cols = 8, int rows = 6,
                           int min_points = 5);

// Matches map lines projected with cur.T_cw: a candidate frame line must be nearly parallel to the
// projected segment, lie within `radius` pixels of it (both endpoints' distances to the candidate
// line) and overlap it; the smallest LBD distance under the threshold wins.
int search_lines(Frame& cur, const std::vector<map::MapLine*>& candidates, double radius,
                 const SearchOptions& o = {});

// Descriptor-only matching of the frame to a keyframe's map points and lines (used to re-track
// against the reference keyframe when the motion model fails; no vocabulary needed).
int match_to_keyframe(Frame& cur, const map::KeyFrame& kf, double ratio = 0.75, const SearchOptions& o = {});

}  // namespace plslam::tracking
