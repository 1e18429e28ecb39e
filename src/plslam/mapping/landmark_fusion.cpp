#include "plslam/mapping/landmark_fusion.h"

#include "plslam/map/map_point.h"

namespace plslam::mapping {

int fuse_landmarks(map::KeyFrame& kf, const FusionOptions& o) {
  int fused = 0;
  const auto points = kf.map_points();
  for (map::KeyFrame* kf2 : kf.best_covisibles(static_cast<std::size_t>(o.neighbors))) {
    const geometry::SE3 T2 = kf2->pose();
    const Eigen::Vector3d O2 = kf2->camera_center();
    for (map::MapPoint* mp : points) {
      if (!mp || mp->is_bad() || mp->index_in(kf2) >= 0) continue;
      const int best_j = match_point_in_keyframe(*kf2, T2, O2, *mp, o.match);
      if (best_j < 0) continue;
      map::MapPoint* other = kf2->map_point(best_j);
      if (other && !other->is_bad()) {
        if (other == mp) continue;
        if (other->num_observations() > mp->num_observations()) {
          mp->replace_with(other);
        } else {
          other->replace_with(mp);
        }
        ++fused;
      } else {
        if (mp->add_observation(kf2, best_j)) kf2->add_map_point(mp, best_j);
      }
    }
  }
  for (map::MapPoint* mp : kf.map_points()) {
    if (mp && !mp->is_bad()) {
      mp->update_descriptor();
      mp->update_normal_and_depth();
    }
  }
  kf.update_connections();
  return fused;
}

}  // namespace plslam::mapping
