#include "plslam/mapping/map_ba_problem.h"

#include "plslam/core/pointer_set.h"

namespace plslam::mapping {

MapBaProblem::MapBaProblem(double line_information, double far_stereo_baselines, bool lines)
    : line_information_(line_information), far_stereo_baselines_(far_stereo_baselines), with_lines_(lines) {}

int MapBaProblem::add_keyframe(map::KeyFrame* kf, bool fixed) {
  const auto [it, added] = index_.emplace(kf, static_cast<int>(keyframes.size()));
  if (added) {
    keyframes.push_back(kf);
    problem.keyframes.push_back({kf->pose(), fixed});
  }
  return it->second;
}

void MapBaProblem::add_landmarks_of(const std::vector<map::KeyFrame*>& kfs) {
  core::PointerSet seen_p, seen_l;
  seen_p.assign(points);
  seen_l.assign(lines);
  const std::size_t first_point = points.size(), first_line = lines.size();
  for (auto* k : kfs) {
    for (auto* mp : k->map_points()) {
      if (mp && !mp->is_bad() && seen_p.insert(mp)) points.push_back(mp);
    }
    if (with_lines_) {
      for (auto* ml : k->map_lines()) {
        if (ml && !ml->is_bad() && seen_l.insert(ml)) lines.push_back(ml);
      }
    }
  }
  for (std::size_t p = first_point; p < points.size(); ++p) {
    problem.points.push_back({points[p]->position(), false});
    for (const auto& [k, idx] : points[p]->observation_list()) {
      if (k->is_bad()) continue;
      const int ki = add_keyframe(k, true);
      const auto& d = k->data();
      const auto i = static_cast<std::size_t>(idx);
      optim::StereoPointObservation o = d.point_observation(i, far_stereo_baselines_);
      o.keyframe = ki;
      o.point = static_cast<int>(p);
      problem.point_observations.push_back(o);
      point_observers.push_back(k);
    }
  }
  for (std::size_t l = first_line; l < lines.size(); ++l) {
    problem.lines.push_back({lines[l]->start(), lines[l]->end(), false});
    for (const auto& [k, idx] : lines[l]->observation_list()) {
      if (k->is_bad()) continue;
      const int ki = add_keyframe(k, true);
      const auto& obs = k->data().lines[static_cast<std::size_t>(idx)];
      optim::StereoLineObservation o;
      o.keyframe = ki;
      o.line = static_cast<int>(l);
      o.left_line = obs.left_line;
      o.right_line = obs.right_line;
      o.information = line_information_;
      problem.line_observations.push_back(o);
      line_observers.push_back(k);
    }
  }
}

}  // namespace plslam::mapping
