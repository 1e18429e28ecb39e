#include "plslam/loop/global_ba.h"

#include <algorithm>
#include <deque>
#include <stdexcept>

#include "plslam/loop/unmapped_keyframes.h"

namespace plslam::loop {

void GlobalBaOptions::validate() const {
  if (iterations < 1) throw std::invalid_argument("loop.global_ba_iterations: must be >= 1");
}

GlobalBaSnapshot snapshot_for_global_ba(const map::Map& map, const GlobalBaOptions& o) {
  o.validate();
  GlobalBaSnapshot s;
  s.problem = std::make_unique<mapping::MapBaProblem>(o.line_information, o.far_stereo_baselines, o.lines);
  // Keyframes local mapping has not connected yet have no observations of the map's points: the
  // merge moves them with their anchors.
  const auto keyframes = split_unmapped(map.keyframes()).connected;
  if (keyframes.empty()) return s;
  s.camera = geometry::StereoCamera(keyframes.front()->data().calib);
  // The origin holds the gauge; without it among the connected keyframes, the oldest one does.
  const bool has_origin = std::any_of(keyframes.begin(), keyframes.end(), [](auto* kf) { return kf->is_origin(); });
  for (map::KeyFrame* kf : keyframes) {
    s.problem->add_keyframe(kf, has_origin ? kf->is_origin() : kf == keyframes.front());
  }
  s.problem->add_landmarks_of(keyframes);
  if (o.T_imu_cam) {
    s.problem->add_imu_factors(keyframes, *o.T_imu_cam, o.reintegration, /*add_missing=*/false);
    s.problem->hold_imu_gauge_by_centre_and_heading();
  }
  return s;
}

optim::BaResult run_global_ba(const GlobalBaSnapshot& s, const GlobalBaOptions& o, const std::atomic<bool>* abort) {
  optim::BaOptions ba;
  ba.iterations = o.iterations;
  ba.remove_outliers = o.remove_outliers;
  ba.second_pass_iterations = o.iterations;
  ba.linear_solver = optim::BaLinearSolver::kSparseSchur;
  ba.abort = abort;
  if (!s.problem->keyframes.empty()) ba.scale_factor = s.problem->keyframes.front()->data().scale_factor;
  if (s.problem->problem.point_observations.empty()) return {};
  return optim::bundle_adjust(s.camera, s.problem->problem, ba);
}

GlobalBaMergeStats merge_global_ba(map::Map& map, const GlobalBaSnapshot& s, const optim::BaResult& r) {
  GlobalBaMergeStats st;
  const auto& p = *s.problem;
  // Keyframes: the BA's poses; the ones made since move with their parent, top-down from the roots
  // of the spanning tree, keeping their pose relative to it.
  map::IdMap<map::KeyFrame, geometry::SE3> before, after;  // T_cw
  for (map::KeyFrame* kf : map.keyframes()) before[kf] = kf->pose();
  for (std::size_t i = 0; i < p.keyframes.size(); ++i) {
    if (!p.keyframes[i]->is_bad()) after[p.keyframes[i]] = r.poses[i];
  }
  st.keyframes = static_cast<int>(after.size());
  std::deque<map::KeyFrame*> queue;
  for (const auto& [kf, T] : after) queue.push_back(kf);
  while (!queue.empty()) {
    map::KeyFrame* parent = queue.front();
    queue.pop_front();
    for (map::KeyFrame* child : parent->children()) {
      if (after.count(child) || !before.count(child)) continue;
      after[child] = (before.at(child) * before.at(parent).inverse() * after.at(parent)).normalized();
      ++st.propagated_keyframes;
      queue.push_back(child);
    }
  }
  for (const auto& [kf, anchor] : split_unmapped(map.keyframes()).unmapped) {
    if (after.count(kf) || !after.count(anchor)) continue;
    after[kf] = (before.at(kf) * before.at(anchor).inverse() * after.at(anchor)).normalized();
    ++st.propagated_keyframes;
  }
  for (const auto& [kf, T] : after) kf->move_to(T);
  p.write_back_imu_states(r);  // after move_to: the BA's velocities replace the turned ones

  // Landmarks: the BA's positions; the ones made since move with their reference keyframe.
  map::IdSet<map::MapPoint> optimised_points(p.points.begin(), p.points.end());
  for (std::size_t i = 0; i < p.points.size(); ++i) {
    if (p.points[i]->is_bad()) continue;
    p.points[i]->set_position(r.points[i]);
    p.points[i]->update_normal_and_depth();
    ++st.points;
  }
  map::IdSet<map::MapLine> optimised_lines(p.lines.begin(), p.lines.end());
  for (std::size_t i = 0; i < p.lines.size(); ++i) {
    if (p.lines[i]->is_bad()) continue;
    p.lines[i]->set_endpoints(r.lines[i].start, r.lines[i].end);
    p.lines[i]->refit_to_observations();
    p.lines[i]->update_normal_and_depth();
    ++st.lines;
  }
  auto motion_of = [&](map::KeyFrame* ref, geometry::SE3* M) {
    if (!ref || !before.count(ref) || !after.count(ref)) return false;
    *M = (after.at(ref).inverse() * before.at(ref)).normalized();
    return true;
  };
  for (map::MapPoint* mp : map.points()) {
    if (mp->is_bad() || optimised_points.count(mp)) continue;
    geometry::SE3 M;
    if (!motion_of(mp->reference(), &M)) continue;
    mp->set_position(M * mp->position());
    mp->update_normal_and_depth();
    ++st.moved_points;
  }
  for (map::MapLine* ml : map.lines()) {
    if (ml->is_bad() || optimised_lines.count(ml)) continue;
    geometry::SE3 M;
    if (!motion_of(ml->reference(), &M)) continue;
    ml->set_endpoints(M * ml->start(), M * ml->end());
    ml->update_normal_and_depth();
    ++st.moved_lines;
  }
  map.note_big_change();
  return st;
}

}  // namespace plslam::loop
