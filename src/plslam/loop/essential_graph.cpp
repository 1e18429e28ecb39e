#include "plslam/loop/essential_graph.h"

#include <set>
#include <string>
#include <stdexcept>
#include <utility>


namespace plslam::loop {

void EssentialGraphOptions::validate() const {
  if (min_covisibility_weight < 1) throw std::invalid_argument("loop.essential_min_weight: must be >= 1");
  if (iterations < 1) throw std::invalid_argument("loop.essential_iterations: must be >= 1");
}

EssentialGraphProblem build_essential_graph(const EssentialGraphInput& in, const EssentialGraphOptions& o) {
  o.validate();
  EssentialGraphProblem g;
  map::IdMap<map::KeyFrame, int> index;
  for (map::KeyFrame* kf : in.keyframes) {
    const auto it = in.initial.find(kf);
    if (it == in.initial.end() || !in.odometry.count(kf)) {
      throw std::invalid_argument("optimize_essential_graph: keyframe " + std::to_string(kf->id()) + " has no pose");
    }
    index[kf] = static_cast<int>(g.poses.size());
    g.nodes.push_back(kf);
    g.poses.push_back(it->second);
    g.fixed.push_back(kf == in.candidate);
  }
  if (!index.count(in.candidate) && !g.fixed.empty()) g.fixed.front() = true;  // some node must hold the gauge
  g.four_dof = in.query && in.candidate && in.query->has_imu() && in.candidate->has_imu();
  std::set<std::pair<long, long>> linked;  // by ids, lower first
  auto add = [&](map::KeyFrame* a, map::KeyFrame* b, const map::IdMap<map::KeyFrame, geometry::SE3>& from) {
    const auto ia = index.find(a), ib = index.find(b);
    if (ia == index.end() || ib == index.end() || a == b) return false;
    if (!linked.emplace(std::min(a->id(), b->id()), std::max(a->id(), b->id())).second) return false;
    g.edges.push_back({ia->second, ib->second, (from.at(a) * from.at(b).inverse()).normalized(),
                       geometry::Matrix6d::Identity()});
    return true;
  };
  // New loop connections first, with the corrected poses: they carry the loop. Weak ones are left
  // out, except the pair that was verified.
  for (const auto& [kf, others] : in.loop_connections) {
    for (map::KeyFrame* other : others) {
      const bool verified = (kf == in.query && other == in.candidate) || (kf == in.candidate && other == in.query);
      if (!verified && kf->weight(other) < o.min_covisibility_weight) continue;
      if (add(kf, other, in.initial)) ++g.loop_edges;
    }
  }
  // The old structure, with odometry's relative poses.
  for (map::KeyFrame* kf : in.keyframes) {
    if (map::KeyFrame* parent = kf->parent()) add(kf, parent, in.odometry);
    for (map::KeyFrame* l : kf->loop_edges()) add(kf, l, in.odometry);
    for (map::KeyFrame* c : kf->covisibles()) {
      if (kf->weight(c) < o.min_covisibility_weight) break;  // covisibles() is by decreasing weight
      add(kf, c, in.odometry);
    }
  }
  return g;
}

EssentialGraphResult solve_essential_graph(const EssentialGraphProblem& g, const EssentialGraphOptions& o) {
  EssentialGraphResult r;
  r.loop_edges = g.loop_edges;
  r.edges = static_cast<int>(g.edges.size());
  optim::PoseGraphOptions po;
  po.iterations = o.iterations;
  po.four_dof = g.four_dof;
  const auto res = optim::optimize_pose_graph(g.poses, g.fixed, g.edges, po);
  r.usable = res.usable;
  r.initial_cost = res.initial_cost;
  r.final_cost = res.final_cost;
  for (std::size_t i = 0; i < g.nodes.size(); ++i) r.poses[g.nodes[i]] = res.poses[i];
  return r;
}

EssentialGraphResult optimize_essential_graph(const EssentialGraphInput& in, const EssentialGraphOptions& o) {
  return solve_essential_graph(build_essential_graph(in, o), o);
}

}  // namespace plslam::loop
