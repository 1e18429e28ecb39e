#include "plslam/mapping/keyframe_culling.h"

namespace plslam::mapping {

bool is_redundant(const map::KeyFrame& k, const KeyframeCullingOptions& o) {
  const auto& d = k.data();
  const double th_depth = o.close_depth_baselines * d.calib.baseline;
  const auto pts = k.map_points();
  int total = 0, redundant = 0;
  for (std::size_t i = 0; i < pts.size(); ++i) {
    map::MapPoint* mp = pts[i];
    if (!mp || mp->is_bad()) continue;
    if (d.depth[i] > th_depth || d.depth[i] < 0) continue;
    ++total;
    if (mp->observation_weight() <= o.observers) continue;
    const int level = d.keypoints[i].octave;
    // Visited under the point's lock, without copying its list: is_bad() is lock-free and a
    // keyframe's keypoints never change.
    int seen = 0;
    mp->for_each_observation([&](const map::KeyFrame* other, int idx) {
      if (seen >= o.observers || other == &k || other->is_bad()) return;
      if (other->data().keypoints[static_cast<std::size_t>(idx)].octave <= level + 1) ++seen;
    });
    if (seen >= o.observers) ++redundant;
  }
  return total > 0 && redundant > o.redundancy * total;
}

bool imu_chain_allows_culling(const map::KeyFrame& k, const KeyframeCullingOptions& o) {
  const auto imu = k.imu();
  if (!imu) return true;
  const map::KeyFrame* next = k.imu_next();
  // The chain's last keyframe is where tracking's IMU prediction starts.
  if (!next) return false;
  if (!imu->previous) return true;
  return next->timestamp() - imu->previous->timestamp() <= o.max_imu_interval_s;
}

std::vector<map::KeyFrame*> cull_redundant_keyframes(map::Map& map, const map::KeyFrame& kf,
                                                     const KeyframeCullingOptions& o,
                                                     const std::function<void(map::KeyFrame*)>& on_culled) {
  std::vector<map::KeyFrame*> culled;
  for (map::KeyFrame* k : kf.covisibles()) {
    if (k->is_origin() || k->is_bad() || !k->loop_edges().empty()) continue;
    if (!is_redundant(*k, o) || !imu_chain_allows_culling(*k, o)) continue;
    k->set_bad();
    map.erase_keyframe(k);
    if (on_culled) on_culled(k);
    culled.push_back(k);
  }
  return culled;
}

}  // namespace plslam::mapping
