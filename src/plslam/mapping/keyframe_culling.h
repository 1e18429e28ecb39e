#pragma once
// Culling of redundant keyframes (ORB-SLAM2's KeyFrameCulling): a keyframe whose close map points
// are nearly all seen, at the same or a finer scale, by enough other keyframes adds nothing but
// cost to bundle adjustment and loop closing.
#include <functional>
#include <vector>

#include "plslam/map/map.h"

namespace plslam::mapping {

struct KeyframeCullingOptions {
  // Redundant when more than this share of its close points are seen by `observers` others.
  double redundancy = 0.9;
  // Other keyframes that must see a point, at the same or a finer scale (one octave of slack);
  // a point whose observation weight is at most this never counts (ORB-SLAM2's thObs).
  int observers = 3;
  // Close points: stereo depth below this many baselines (ORB-SLAM2's 40, as tracking's).
  double close_depth_baselines = 40;
  // A keyframe of the IMU chain (map::KeyFrameImu) is culled only when the IMU interval that its
  // neighbours would then span is at most this long: preintegration over a long interval is
  // loose, and its first-order bias correction poor (ORB-SLAM3: 0.5 s).
  double max_imu_interval_s = 0.5;
};

// Whether culling `k` leaves its IMU chain's neighbours within o.max_imu_interval_s (true for a
// keyframe outside a chain).
bool imu_chain_allows_culling(const map::KeyFrame& k, const KeyframeCullingOptions& o);

// Whether `k` is redundant (a test of its points only: the origin and loop rules are the caller's).
bool is_redundant(const map::KeyFrame& k, const KeyframeCullingOptions& o);

// Culls the redundant keyframes among the covisibles of `kf`, in covisibility order, never the
// map's origin nor a keyframe with loop edges, nor one imu_chain_allows_culling keeps: each is flagged bad, leaves the map, and is passed
// to `on_culled` before the next is tested. Returns them.
std::vector<map::KeyFrame*> cull_redundant_keyframes(map::Map& map, const map::KeyFrame& kf,
                                                     const KeyframeCullingOptions& o,
                                                     const std::function<void(map::KeyFrame*)>& on_culled = {});

}  // namespace plslam::mapping
