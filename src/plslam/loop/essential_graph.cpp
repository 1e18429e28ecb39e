#include "plslam/loop/essential_graph.h"

#include <set>
#include <string>
#include <stdexcept>
#include <utility>

#include "plslam/optim/pose_graph.h"

namespace plslam::loop {

void EssentialGraphOptions::validate() const {
  if (min_covisibility_weight < 1) throw std::invalid_argument("loop.essential_min_weight: must be >= 1");
  if (iterations < 1) throw std::invalid_argument("loop.essential_iterations: must be >= 1");
}

EssentialGraphResult optimize_essential_graph(const EssentialGraphInput& in, const EssentialGraphOptions& o) {
  o.validate();
  map::IdMap<map::KeyFrame, int> index;
  std::vector<geometry::SE3> poses;
  std::vector<bool> fixed;
  for (map::KeyFrame* kf : in.keyframes) {
    const auto it = in.initial.find(kf);
    if (it == in.initial.end() || !in.odometry.count(kf)) {
      throw std::invalid_argument("optimize_essential_graph: keyframe " + std::to_string(kf->id()) + " has no pose");
    }
    index[kf] = static_cast<int>(poses.size());
    poses.push_back(it->second);
    fixed.push_back(kf == in.candidate);
  }
  if (!index.count(in.candidate) && !fixed.empty()) fixed.front() = true;  // some node must hold the gauge
  std::vector<optim::PoseGraphEdge> edges;
  std::set<std::pair<long, long>> linked;  // by ids, lower first
  auto add = [&](map::KeyFrame* a, map::KeyFrame* b, const map::IdMap<map::KeyFrame, geometry::SE3>& from) {
    const auto ia = index.find(a), ib = index.find(b);
    if (ia == index.end() || ib == index.end() || a == b) return false;
    if (!linked.emplace(std::min(a->id(), b->id()), std::max(a->id(), b->id())).second) return false;
    edges.push_back({ia->second, ib->second, (from.at(a) * from.at(b).inverse()).normalized(),
                     geometry::Matrix6d::Identity()});
    return true;
  };
  EssentialGraphResult r;
  // New loop connections first, with the corrected poses: they carry the loop. Weak ones are left
  // out, except the pair that was verified.
  for (const auto& [kf, others] : in.loop_connections) {
    for (map::KeyFrame* other : others) {
      const bool verified = (kf == in.query && other == in.candidate) || (kf == in.candidate && other == in.query);
      if (!verified && kf->weight(other) < o.min_covisibility_weight) continue;
      if (add(kf, other, in.initial)) ++r.loop_edges;
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
  r.edges = static_cast<int>(edges.size());
  optim::PoseGraphOptions po;
  po.iterations = o.iterations;
  const auto res = optim::optimize_pose_graph(poses, fixed, edges, po);
  r.usable = res.usable;
  r.initial_cost = res.initial_cost;
  r.final_cost = res.final_cost;
  for (const auto& [kf, i] : index) r.poses[kf] = res.poses[static_cast<std::size_t>(i)];
  return r;
}

}  // namespace plslam::loop
