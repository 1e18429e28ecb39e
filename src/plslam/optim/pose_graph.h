#pragma once
// SE(3) pose-graph optimisation (stereo: scale is observable, so no Sim(3)) for the essential
// graph after a loop closure, on Ceres with analytic Jacobians of the relative-pose error; or
// 4-DoF (PoseGraphOptions::four_dof) in a gravity-aligned visual-inertial map.
#include <vector>

#include "plslam/geometry/se3.h"

namespace plslam::optim {

// Measured relative pose between nodes i and j (both T_cw): Z_ij = T_i * T_j^-1, i.e. the pose
// of camera j in camera i's frame, inverted. Residual e = log(Z_ij^-1 T_i T_j^-1).
struct PoseGraphEdge {
  int i = 0;
  int j = 0;
  geometry::SE3 Z_ij;
  geometry::Matrix6d information = geometry::Matrix6d::Identity();  // order [rho; phi]
};

struct PoseGraphOptions {
  int iterations = 20;
  // Move each free node only by a yaw about the world's z axis and a translation (a visual-inertial
  // map, whose z axis is up: roll and pitch are observable from gravity and stay as they are).
  bool four_dof = false;
  int num_threads = 1;
};

struct PoseGraphResult {
  std::vector<geometry::SE3> poses;
  double initial_cost = 0.0;
  double final_cost = 0.0;
  int iterations = 0;
  bool usable = false;
};

// fixed[k] keeps node k at its initial pose (at least one node should be fixed). Throws
// InputError on bad indices, size mismatch or an information matrix that is not positive
// definite.
PoseGraphResult optimize_pose_graph(const std::vector<geometry::SE3>& poses,
                                    const std::vector<bool>& fixed,
                                    const std::vector<PoseGraphEdge>& edges,
                                    const PoseGraphOptions& options = {});

}  // namespace plslam::optim
