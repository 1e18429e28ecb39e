#pragma once
// The essential graph of a map (ORB-SLAM2's OptimizeEssentialGraph, in SE(3) since stereo fixes
// the scale): every keyframe, linked by its spanning-tree edge, by the loop edges of earlier loops,
// by strong covisibility edges, and by the new connections the loop being closed just made. The
// old edges keep the relative poses odometry measured (the poses before the correction); the new
// loop connections take the corrected poses. The pose graph spreads the loop error over the map.
#include <vector>

#include "plslam/geometry/se3.h"
#include "plslam/map/by_id.h"
#include "plslam/map/keyframe.h"
#include "plslam/optim/pose_graph.h"

namespace plslam::loop {

struct EssentialGraphOptions {
  int min_covisibility_weight = 100;  // config loop.essential_min_weight (ORB-SLAM2: 100)
  int iterations = 20;
  // Throws std::invalid_argument naming the bad field.
  void validate() const;
};

struct EssentialGraphInput {
  std::vector<map::KeyFrame*> keyframes;            // the nodes (good keyframes)
  map::IdMap<map::KeyFrame, geometry::SE3> odometry;  // T_cw before the correction, every node
  map::IdMap<map::KeyFrame, geometry::SE3> initial;   // T_cw where the optimisation starts, every node
  // Keyframe -> keyframes on the other side of the loop it is now connected to.
  map::IdMap<map::KeyFrame, map::IdSet<map::KeyFrame>> loop_connections;
  map::KeyFrame* query = nullptr;      // the keyframe that found the loop
  map::KeyFrame* candidate = nullptr;  // the place it found: fixed, it anchors the map
};

struct EssentialGraphResult {
  map::IdMap<map::KeyFrame, geometry::SE3> poses;  // optimised T_cw, every node
  int edges = 0;
  int loop_edges = 0;  // of them, new loop connections
  double initial_cost = 0, final_cost = 0;
  bool usable = false;
};

// The graph as plain data: what the solver needs, and nothing that points into the map except the
// node order, so it may be solved beside threads that edit the map (deterministic mode).
struct EssentialGraphProblem {
  std::vector<map::KeyFrame*> nodes;  // node i's keyframe (only to read the result back)
  std::vector<geometry::SE3> poses;   // where the optimisation starts
  std::vector<bool> fixed;
  std::vector<optim::PoseGraphEdge> edges;
  int loop_edges = 0;
  // The loop's keyframes carry IMU states (a gravity-aligned visual-inertial map): the graph moves
  // the keyframes by yaw and translation only (optim::PoseGraphOptions::four_dof).
  bool four_dof = false;
};

// Reads the graph (parents, loop edges, covisibility weights); writes nothing to the map.
EssentialGraphProblem build_essential_graph(const EssentialGraphInput& input, const EssentialGraphOptions& options = {});
// Reads only `problem`.
EssentialGraphResult solve_essential_graph(const EssentialGraphProblem& problem, const EssentialGraphOptions& options = {});
// Both, in one step.
EssentialGraphResult optimize_essential_graph(const EssentialGraphInput& input, const EssentialGraphOptions& options = {});

}  // namespace plslam::loop
