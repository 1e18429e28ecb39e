#pragma once
// A read-only copy of the map for readers outside the SLAM threads (the public API, a viewer, a
// writer): plain values, no pointers into the live map, so it can be read at leisure while
// tracking, local mapping and loop closing go on.
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "plslam/geometry/se3.h"
#include "plslam/map/map.h"

namespace plslam::map {

struct KeyframeSnapshot {
  long id = 0;
  double timestamp = 0;
  geometry::SE3 T_wc;
  long parent = -1;                  // spanning-tree parent, -1 for a root
  std::vector<long> loop_edges;      // keyframes a loop closure connected it to
  std::vector<std::pair<long, int>> covisibility;  // keyframe id, weight; by decreasing weight
};

struct PointSnapshot {
  long id = 0;
  Eigen::Vector3d position;
};

struct LineSnapshot {
  long id = 0;
  Eigen::Vector3d start, end;
};

struct MapSnapshot {
  long changes = 0;  // Map::changes() when it was taken: a reader re-takes it when this differs
  std::vector<KeyframeSnapshot> keyframes;  // by id
  std::vector<PointSnapshot> points;        // by id
  std::vector<LineSnapshot> lines;          // by id
};

// Copies the active keyframes, points and lines under the map's update mutex, so that no local BA
// write-back or loop correction is seen half done. Do not call it while holding that mutex.
MapSnapshot take_snapshot(const Map& map);

}  // namespace plslam::map
