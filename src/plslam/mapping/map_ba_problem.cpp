#include "plslam/mapping/map_ba_problem.h"

#include <optional>

#include "plslam/core/pointer_set.h"
#include "plslam/inertial/gauge_prior_factor.h"
#include "plslam/inertial/imu_ba_factor.h"

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

void MapBaProblem::fill_keyframe_extra() {
  for (std::size_t k = problem.keyframe_extra.size(); k < keyframes.size(); ++k) {
    const auto imu = keyframes[k]->imu();
    problem.keyframe_extra.push_back(imu ? inertial::ba_extra_state(imu->v, imu->bias) : optim::Vector9d::Zero());
  }
}

void MapBaProblem::add_imu_factors(const std::vector<map::KeyFrame*>& chain, const geometry::SE3& T_imu_cam,
                                   const inertial::ReintegrationThresholds& reintegration, bool add_missing) {
  fill_keyframe_extra();
  for (map::KeyFrame* j : chain) {
    const auto imu = j->imu();
    const auto j_it = index_.find(j);
    if (!imu || !imu->previous || !imu->from_previous || j_it == index_.end()) continue;
    const auto i_it = index_.find(imu->previous);
    if (i_it == index_.end() && !add_missing) continue;
    const int i_index = i_it != index_.end() ? i_it->second : add_keyframe(imu->previous, true);
    fill_keyframe_extra();
    const inertial::ImuBias bias_i = inertial::bias_of(problem.keyframe_extra[static_cast<std::size_t>(i_index)]);
    const inertial::Preintegration* pim = imu->from_previous.get();
    std::optional<inertial::Preintegration> again;
    if (pim->bias_moved_far(bias_i, reintegration)) {
      again.emplace(*pim);
      again->reintegrate(bias_i);
      pim = &*again;
    }
    problem.keyframe_factors.push_back(std::make_shared<inertial::ImuBaFactor>(i_index, j_it->second, *pim, T_imu_cam));
  }
}

std::vector<bool> MapBaProblem::in_keyframe_factor() const {
  std::vector<bool> in_factor(keyframes.size(), false);
  for (const auto& f : problem.keyframe_factors) {
    for (const int k : f->keyframes()) in_factor[static_cast<std::size_t>(k)] = true;
  }
  return in_factor;
}

void MapBaProblem::hold_imu_gauge_by_centre_and_heading() {
  const std::vector<bool> in_factor = in_keyframe_factor();
  for (std::size_t k = 0; k < keyframes.size(); ++k) {
    if (!problem.keyframes[k].fixed || !in_factor[k]) continue;
    problem.keyframes[k].fixed = false;
    problem.keyframe_factors.push_back(
        std::make_shared<inertial::GaugePriorFactor>(static_cast<int>(k), problem.keyframes[k].T_cw));
  }
}

void MapBaProblem::write_back_imu_states(const optim::BaResult& result) const {
  if (result.keyframe_extra.empty()) return;
  const std::vector<bool> in_factor = in_keyframe_factor();
  for (std::size_t k = 0; k < keyframes.size(); ++k) {
    if (!in_factor[k] || problem.keyframes[k].fixed || keyframes[k]->is_bad() || !keyframes[k]->has_imu()) continue;
    keyframes[k]->set_imu_velocity_and_bias(inertial::velocity_of(result.keyframe_extra[k]),
                                            inertial::bias_of(result.keyframe_extra[k]));
  }
}

}  // namespace plslam::mapping
