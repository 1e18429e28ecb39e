#pragma once
// Culling of recent landmarks (ORB-SLAM2's MapPointCulling for stereo, with lines): a landmark
// made by a keyframe stays on probation for a few keyframes, and tracking must find it often
// enough and other keyframes must observe it, or it is flagged bad.
#include <list>
#include <utility>

#include "plslam/map/map_line.h"
#include "plslam/map/map_point.h"

namespace plslam::mapping {

struct RecentLandmarkOptions {
  // Found by tracking in at least this share of the frames that should have seen it.
  double min_found_ratio = 0.25;
  // Once `probation_keyframes` keyframes have passed: a point needs this observation weight (a
  // stereo observation counts 2: two stereo keyframes, or three of which one stereo) ...
  int min_point_weight = 4;
  // ... and a line this many observing keyframes. Lines keep the stricter rule: a stereo line's
  // depth is far less certain than a stereo point's (endpoints slide along the epipolar
  // direction), and on the rendered street and corridor the weight rule kept 4-20x more lines
  // and raised the ATE.
  int min_line_observers = 3;
  // Keyframes after the one that made it before the observation rule applies; one keyframe later
  // the landmark leaves probation.
  int probation_keyframes = 2;
};

class RecentLandmarks {
 public:
  explicit RecentLandmarks(RecentLandmarkOptions options = {}) : options_(options) {}

  // A landmark made by the keyframe with id `keyframe_id` (in keyframe order).
  void add(map::MapPoint* p, long keyframe_id) { points_.emplace_back(p, keyframe_id); }
  void add(map::MapLine* l, long keyframe_id) { lines_.emplace_back(l, keyframe_id); }

  struct Culled {
    int points = 0, lines = 0;
  };
  // Applies the rules as of keyframe `current_id`: flags failing landmarks bad, and forgets them,
  // the bad ones and those past probation.
  Culled cull(long current_id);

  // Forgets the bad ones only (before Map::reclaim() frees them).
  void drop_bad() {
    std::erase_if(points_, [](const auto& e) { return e.first->is_bad(); });
    std::erase_if(lines_, [](const auto& e) { return e.first->is_bad(); });
  }

  std::size_t points_on_probation() const { return points_.size(); }
  std::size_t lines_on_probation() const { return lines_.size(); }

 private:
  RecentLandmarkOptions options_;
  std::list<std::pair<map::MapPoint*, long>> points_;  // point, id of the keyframe that made it
  std::list<std::pair<map::MapLine*, long>> lines_;
};

}  // namespace plslam::mapping
