#include "plslam/mapping/local_ba_window.h"

#include <algorithm>
#include <mutex>
#include <optional>

#include <spdlog/spdlog.h>

#include "plslam/geometry/stereo_camera.h"
#include "plslam/inertial/imu_ba_factor.h"

namespace plslam::mapping {
namespace {

// The last `n` keyframes of the IMU chain that ends at `kf`, oldest first (empty without a state).
std::vector<map::KeyFrame*> imu_chain_before(map::KeyFrame& kf, int n) {
  std::vector<map::KeyFrame*> chain;
  for (map::KeyFrame* k = &kf; k && static_cast<int>(chain.size()) < n;) {
    const auto imu = k->imu();
    if (!imu) break;
    chain.push_back(k);
    k = imu->previous;
  }
  std::reverse(chain.begin(), chain.end());
  return chain;
}

// The IMU factors between consecutive keyframes of the window's chain (its first keyframe's
// predecessor included, fixed), and every keyframe's extra state ([v; bg; ba], zero outside the
// chain).
void add_imu_factors(MapBaProblem& window, const std::vector<map::KeyFrame*>& chain, const LocalBaOptions& o) {
  auto& p = window.problem;
  p.keyframe_extra.assign(p.keyframes.size(), optim::Vector9d::Zero());
  for (std::size_t k = 0; k < window.keyframes.size(); ++k) {
    if (const auto imu = window.keyframes[k]->imu()) p.keyframe_extra[k] = inertial::ba_extra_state(imu->v, imu->bias);
  }
  for (map::KeyFrame* j : chain) {
    const auto imu = j->imu();
    if (!imu->previous || !imu->from_previous) continue;
    const int i_index = window.add_keyframe(imu->previous, true);
    if (static_cast<std::size_t>(i_index) >= p.keyframe_extra.size()) {
      const auto before = imu->previous->imu();
      p.keyframe_extra.push_back(before ? inertial::ba_extra_state(before->v, before->bias) : optim::Vector9d::Zero());
    }
    const inertial::ImuBias bias_i = inertial::bias_of(p.keyframe_extra[static_cast<std::size_t>(i_index)]);
    const inertial::Preintegration* pim = imu->from_previous.get();
    std::optional<inertial::Preintegration> again;
    if (pim->bias_moved_far(bias_i, o.reintegration)) {
      again.emplace(*pim);
      again->reintegrate(bias_i);
      pim = &*again;
    }
    p.keyframe_factors.push_back(
        std::make_shared<inertial::ImuBaFactor>(i_index, window.add_keyframe(j, j->is_origin()), *pim, o.T_imu_cam));
  }
}

}  // namespace

MapBaProblem local_ba_window(map::KeyFrame& kf, const LocalBaOptions& o,
                             const std::vector<map::KeyFrame*>& also_free) {
  std::vector<map::KeyFrame*> local{&kf};
  for (auto* n : kf.covisibles()) {
    if (!n->is_bad()) local.push_back(n);
  }
  for (auto* k : also_free) {
    if (k != &kf && !k->is_bad() && std::find(local.begin(), local.end(), k) == local.end()) local.push_back(k);
  }
  const std::vector<map::KeyFrame*> chain = o.imu_window > 0 ? imu_chain_before(kf, o.imu_window) : std::vector<map::KeyFrame*>{};
  for (auto* k : chain) {
    if (std::find(local.begin(), local.end(), k) == local.end()) local.push_back(k);
  }
  MapBaProblem window(o.line_information, o.far_stereo_baselines, o.lines);
  for (auto* k : local) window.add_keyframe(k, k->is_origin());
  window.add_landmarks_of(local);
  if (chain.size() > 1 || (chain.size() == 1 && chain.front()->imu()->previous)) add_imu_factors(window, chain, o);
  return window;
}

void write_back_local_ba(const MapBaProblem& window, const optim::BaResult& result) {
  const auto& problem = window.problem;
  const auto& points = window.points;
  const auto& lines = window.lines;
  for (std::size_t i = 0; i < window.point_observers.size(); ++i) {
    if (!result.point_observation_outlier[i]) continue;
    map::MapPoint* mp = points[static_cast<std::size_t>(problem.point_observations[i].point)];
    map::KeyFrame* k = window.point_observers[i];
    const int idx = mp->index_in(k);
    if (idx >= 0) k->erase_map_point(idx);
    mp->erase_observation(k);
  }
  for (std::size_t i = 0; i < window.line_observers.size(); ++i) {
    if (!result.line_observation_outlier[i]) continue;
    map::MapLine* ml = lines[static_cast<std::size_t>(problem.line_observations[i].line)];
    map::KeyFrame* k = window.line_observers[i];
    const int idx = ml->index_in(k);
    if (idx >= 0) k->erase_map_line(idx);
    ml->erase_observation(k);
  }
  std::vector<bool> in_imu_factor(window.keyframes.size(), false);
  for (const auto& f : problem.keyframe_factors) {
    for (const int k : f->keyframes()) in_imu_factor[static_cast<std::size_t>(k)] = true;
  }
  for (std::size_t i = 0; i < window.keyframes.size(); ++i) {
    if (problem.keyframes[i].fixed) continue;
    window.keyframes[i]->set_pose(result.poses[i]);
    if (in_imu_factor[i] && window.keyframes[i]->has_imu()) {
      window.keyframes[i]->set_imu_velocity_and_bias(inertial::velocity_of(result.keyframe_extra[i]),
                                                     inertial::bias_of(result.keyframe_extra[i]));
    }
  }
  for (std::size_t p = 0; p < points.size(); ++p) {
    if (points[p]->is_bad()) continue;
    points[p]->set_position(result.points[p]);
    points[p]->update_normal_and_depth();
  }
  for (std::size_t l = 0; l < lines.size(); ++l) {
    if (lines[l]->is_bad()) continue;
    lines[l]->set_endpoints(result.lines[l].start, result.lines[l].end);
    lines[l]->refit_to_observations();
    lines[l]->update_normal_and_depth();
  }
}

optim::BaResult solve_local_ba(const MapBaProblem& window, const map::KeyFrame& kf, const LocalBaOptions& o,
                               const std::atomic<bool>* abort) {
  optim::BaOptions ba;
  ba.iterations = o.iterations;
  ba.second_pass_iterations = o.second_iterations;
  ba.scale_factor = kf.data().scale_factor;
  ba.linear_solver = optim::BaLinearSolver::kSparseSchur;
  ba.abort = abort;
  const geometry::StereoCamera cam(kf.data().calib);
  return optim::local_bundle_adjustment(cam, window.problem, ba);
}

bool apply_local_ba(map::Map& map, const MapBaProblem& window, const optim::BaResult& result) {
  if (!result.usable) {
    spdlog::debug("local BA unusable: {}", result.message);
    return false;
  }
  std::lock_guard lock(map.update_mutex());
  write_back_local_ba(window, result);
  map.note_change();  // poses and positions moved: readers of snapshots redraw
  return true;
}

bool run_local_ba(map::Map& map, map::KeyFrame& kf, const LocalBaOptions& o, const std::atomic<bool>* abort,
                  bool* aborted) {
  const MapBaProblem window = local_ba_window(kf, o);
  if (window.problem.point_observations.empty()) return false;
  const auto result = solve_local_ba(window, kf, o, abort);
  if (aborted) *aborted = result.aborted;
  return apply_local_ba(map, window, result);
}

}  // namespace plslam::mapping
