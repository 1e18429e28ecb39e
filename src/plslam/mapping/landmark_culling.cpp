#include "plslam/mapping/landmark_culling.h"

namespace plslam::mapping {
namespace {

template <class Landmark, class TooFew>
int cull_list(std::list<std::pair<Landmark*, long>>& recent, long current_id, const RecentLandmarkOptions& o,
              TooFew too_few_observations) {
  int culled = 0;
  for (auto it = recent.begin(); it != recent.end();) {
    auto* lm = it->first;
    const long age = current_id - it->second;
    if (lm->is_bad()) {
      it = recent.erase(it);
    } else if (lm->found_ratio() < o.min_found_ratio || (age >= o.probation_keyframes && too_few_observations(*lm))) {
      lm->set_bad();
      it = recent.erase(it);
      ++culled;
    } else if (age > o.probation_keyframes) {
      it = recent.erase(it);
    } else {
      ++it;
    }
  }
  return culled;
}

}  // namespace

RecentLandmarks::Culled RecentLandmarks::cull(long current_id) {
  Culled c;
  c.points = cull_list(points_, current_id, options_,
                       [&](const map::MapPoint& p) { return p.observation_weight() < options_.min_point_weight; });
  c.lines = cull_list(lines_, current_id, options_,
                      [&](const map::MapLine& l) { return l.num_observations() < options_.min_line_observers; });
  return c;
}

}  // namespace plslam::mapping
