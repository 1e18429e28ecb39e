#include "plslam/loop/loop_correction.h"

#include <vector>

#include "plslam/loop/unmapped_keyframes.h"

namespace plslam::loop {
namespace {

using map::IdMap;
using map::IdSet;
using map::KeyFrame;
using map::MapLine;
using map::MapPoint;

bool same_pose(const geometry::SE3& a, const geometry::SE3& b) {
  return a.rotation() == b.rotation() && a.translation() == b.translation();
}

// The keyframe a landmark moves with: the one that corrected it, else its reference, else any
// good observer (a culled reference).
template <class L>
KeyFrame* anchor_of(L* l, const IdMap<L, KeyFrame*>& corrected_by, const IdMap<KeyFrame, geometry::SE3>& poses) {
  // (A correction finished beside local mapping: the keyframe that corrected it may be culled since.)
  if (const auto it = corrected_by.find(l); it != corrected_by.end() && poses.count(it->second)) return it->second;
  KeyFrame* ref = l->reference();
  if (ref && !ref->is_bad() && poses.count(ref)) return ref;
  for (const auto& [kf, idx] : l->observation_list()) {
    if (!kf->is_bad() && poses.count(kf)) return kf;
  }
  return nullptr;
}

// Landmarks seen by the recognised place: the candidate and its covisible keyframes.
template <class L>
std::vector<L*> place_landmarks(const std::vector<KeyFrame*>& place, std::vector<L*> (KeyFrame::*get)() const) {
  IdSet<L> seen;
  std::vector<L*> out;
  for (KeyFrame* kf : place) {
    for (L* l : (kf->*get)()) {
      if (l && !l->is_bad() && seen.insert(l).second) out.push_back(l);
    }
  }
  return out;
}

}  // namespace

LoopCorrectionResult correct_loop(map::Map& map, const LoopConstraint& loop, const LoopCorrectionOptions& o) {
  auto plan = begin_loop_correction(map, loop, o);
  return finish_loop_correction(map, plan, solve_essential_graph(plan.problem, o.graph));
}

LoopCorrectionPlan begin_loop_correction(map::Map& map, const LoopConstraint& loop, const LoopCorrectionOptions& o) {
  o.graph.validate();
  LoopCorrectionPlan plan;
  LoopCorrectionResult& r = plan.result;
  EssentialGraphInput& graph = plan.graph;
  KeyFrame* query = loop.query;
  KeyFrame* candidate = loop.candidate;
  query->update_connections();

  // 1. Poses before the correction, and the query's neighbourhood moved by the verified pose.
  auto [connected, unmapped] = split_unmapped(map.keyframes());
  graph.keyframes = std::move(connected);
  plan.unmapped = std::move(unmapped);
  for (KeyFrame* kf : graph.keyframes) graph.odometry[kf] = graph.initial[kf] = kf->pose();
  for (const auto& u : plan.unmapped) graph.odometry[u.keyframe] = graph.initial[u.keyframe] = u.keyframe->pose();
  graph.query = query;
  graph.candidate = candidate;
  std::vector<KeyFrame*> neighbourhood{query};
  for (KeyFrame* kf : query->covisibles()) {
    if (!kf->is_bad() && kf != candidate) neighbourhood.push_back(kf);
  }
  const geometry::SE3 T_qw_corrected = (loop.T_query_candidate * candidate->pose()).normalized();
  const geometry::SE3 T_wq = query->pose_inverse();
  for (KeyFrame* kf : neighbourhood) {
    graph.initial[kf] = (kf->pose() * T_wq * T_qw_corrected).normalized();
  }
  r.neighbourhood = static_cast<int>(neighbourhood.size());

  // 2. Their landmarks, each with the first neighbourhood keyframe that sees it.
  auto& point_corrected_by = plan.point_corrected_by;
  auto& line_corrected_by = plan.line_corrected_by;
  for (KeyFrame* kf : neighbourhood) {
    const geometry::SE3 M = graph.initial.at(kf).inverse() * graph.odometry.at(kf);  // old world -> corrected world
    for (MapPoint* p : kf->map_points()) {
      if (!p || p->is_bad() || !point_corrected_by.emplace(p, kf).second) continue;
      p->set_position(M * p->position());
    }
    for (MapLine* l : kf->map_lines()) {
      if (!l || l->is_bad() || !line_corrected_by.emplace(l, kf).second) continue;
      l->set_endpoints(M * l->start(), M * l->end());
    }
    kf->move_to(graph.initial.at(kf));
  }

  // 3. Fusion: the verified matches, then the place's landmarks projected into the neighbourhood.
  // The place's landmark stays: it is anchored to the side of the loop that does not move.
  for (const auto& [qp, cp] : loop.matches) {
    if (qp != cp && !qp->is_bad() && !cp->is_bad()) {
      qp->replace_with(cp);
      ++r.fused_points;
    }
  }
  std::vector<KeyFrame*> place{candidate};
  for (KeyFrame* kf : candidate->covisibles()) {
    if (!kf->is_bad()) place.push_back(kf);
  }
  const auto place_points = place_landmarks<MapPoint>(place, &KeyFrame::map_points);
  const auto place_lines = o.lines ? place_landmarks<MapLine>(place, &KeyFrame::map_lines) : std::vector<MapLine*>{};
  for (KeyFrame* kf : neighbourhood) {
    const geometry::SE3 T = kf->pose();
    const Eigen::Vector3d O = kf->camera_center();
    for (MapPoint* p : place_points) {
      if (p->is_bad() || p->index_in(kf) >= 0) continue;
      const int j = mapping::match_point_in_keyframe(*kf, T, O, *p, o.fusion);
      if (j < 0) continue;
      MapPoint* there = kf->map_point(j);
      if (there && !there->is_bad()) {
        there->replace_with(p);
        ++r.fused_points;
      } else {
        if (p->add_observation(kf, j)) {
          kf->add_map_point(p, j);
          ++r.added_points;
        }
      }
    }
    for (MapLine* l : place_lines) {
      if (l->is_bad() || l->index_in(kf) >= 0) continue;
      const int j = mapping::match_line_in_keyframe(*kf, T, *l, o.fusion);
      if (j < 0) continue;
      MapLine* there = kf->map_line(j);
      if (there && !there->is_bad()) {
        there->replace_with(l);
        ++r.fused_lines;
      } else {
        if (l->add_observation(kf, j)) {
          kf->add_map_line(l, j);
          ++r.added_lines;
        }
      }
    }
  }
  for (MapPoint* p : place_points) {
    if (!p->is_bad()) {
      p->update_descriptor();
      p->update_normal_and_depth();
    }
  }
  for (MapLine* l : place_lines) {
    if (!l->is_bad()) {
      l->update_descriptor();
      l->refit_to_observations();  // the fused observations may extend it
      l->update_normal_and_depth();
    }
  }

  // 4. The connections the fusion made across the loop.
  IdSet<KeyFrame> neighbourhood_set(neighbourhood.begin(), neighbourhood.end());
  for (KeyFrame* kf : neighbourhood) {
    IdSet<KeyFrame> before;
    for (KeyFrame* c : kf->covisibles()) before.insert(c);
    kf->update_connections();
    for (KeyFrame* c : kf->covisibles()) {
      if (!before.count(c) && !neighbourhood_set.count(c)) {
        graph.loop_connections[kf].insert(c);
        ++r.loop_connections;
      }
    }
  }
  graph.loop_connections[query].insert(candidate);

  // 5. The essential graph, solved by the caller.
  plan.problem = build_essential_graph(graph, o.graph);
  return plan;
}

LoopCorrectionResult finish_loop_correction(map::Map& map, LoopCorrectionPlan& plan, EssentialGraphResult solved) {
  LoopCorrectionResult& r = plan.result;
  const EssentialGraphInput& graph = plan.graph;
  r.graph = std::move(solved);
  if (!r.graph.usable) return r;
  for (const auto& [kf, anchor] : plan.unmapped) {
    r.graph.poses[kf] = (graph.odometry.at(kf) * graph.odometry.at(anchor).inverse() * r.graph.poses.at(anchor)).normalized();
    ++r.unmapped_keyframes;
  }
  // Where each keyframe is now and where it goes. A keyframe of the graph that local mapping moved
  // since the first step keeps that change on top of its optimised pose; one made since moves with
  // its parent (or the latest keyframe before it), as an unmapped one does.
  IdMap<KeyFrame, geometry::SE3> before, after;
  KeyFrame* latest = nullptr;
  for (KeyFrame* kf : map.keyframes()) {
    if (kf->is_bad()) continue;
    const geometry::SE3 now = kf->pose();
    before[kf] = now;
    if (const auto it = r.graph.poses.find(kf); it != r.graph.poses.end()) {
      const geometry::SE3& start = graph.initial.at(kf);
      after[kf] = same_pose(now, start) ? it->second : (now * start.inverse() * it->second).normalized();
      latest = kf;
      continue;
    }
    KeyFrame* anchor = kf->parent() && after.count(kf->parent()) ? kf->parent() : latest;
    if (!anchor) continue;
    const geometry::SE3 motion = (after.at(anchor).inverse() * before.at(anchor)).normalized();
    after[kf] = (now * motion.inverse()).normalized();
    ++r.unmapped_keyframes;
  }
  for (const auto& [kf, T] : after) kf->move_to(T);
  // A landmark's anchor moved from `before` to `after`; it keeps its place in the anchor's camera frame.
  auto motion_of = [&](KeyFrame* anchor) { return (after.at(anchor).inverse() * before.at(anchor)).normalized(); };
  const auto& point_corrected_by = plan.point_corrected_by;
  const auto& line_corrected_by = plan.line_corrected_by;
  for (MapPoint* p : map.points()) {
    if (p->is_bad()) continue;
    KeyFrame* anchor = anchor_of(p, point_corrected_by, after);
    if (!anchor) continue;
    p->set_position(motion_of(anchor) * p->position());
    p->update_normal_and_depth();
  }
  for (MapLine* l : map.lines()) {
    if (l->is_bad()) continue;
    KeyFrame* anchor = anchor_of(l, line_corrected_by, after);
    if (!anchor) continue;
    const geometry::SE3 M = motion_of(anchor);
    l->set_endpoints(M * l->start(), M * l->end());
    l->update_normal_and_depth();
  }

  // 6. The loop edge, kept for every later essential graph.
  graph.query->add_loop_edge(graph.candidate);
  graph.candidate->add_loop_edge(graph.query);
  map.note_big_change();
  return r;
}

}  // namespace plslam::loop
