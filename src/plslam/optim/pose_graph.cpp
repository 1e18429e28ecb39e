#include "plslam/optim/pose_graph.h"

#include <string>

#include <Eigen/Cholesky>
#include <ceres/problem.h>
#include <ceres/solver.h>

#include "plslam/core/error.h"
#include "plslam/optim/ceres_costs.h"

namespace plslam::optim {

PoseGraphResult optimize_pose_graph(const std::vector<geometry::SE3>& poses,
                                    const std::vector<bool>& fixed,
                                    const std::vector<PoseGraphEdge>& edges,
                                    const PoseGraphOptions& options) {
  if (fixed.size() != poses.size()) {
    throw InputError("", "optimize_pose_graph: fixed flags and poses differ in size");
  }
  std::vector<PoseParams> x;
  x.reserve(poses.size());
  for (const auto& T : poses) x.push_back(to_params(T));

  SE3LeftManifold se3;
  YawTranslationManifold yaw_translation;
  ceres::Manifold* manifold = options.four_dof ? static_cast<ceres::Manifold*>(&yaw_translation) : &se3;
  ceres::Problem::Options po;
  po.manifold_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  ceres::Problem problem(po);
  for (std::size_t k = 0; k < x.size(); ++k) {
    problem.AddParameterBlock(x[k].data(), 7, manifold);
    if (fixed[k]) problem.SetParameterBlockConstant(x[k].data());
  }
  const auto n = static_cast<int>(poses.size());
  for (const auto& e : edges) {
    if (e.i < 0 || e.j < 0 || e.i >= n || e.j >= n || e.i == e.j) {
      throw InputError("", "optimize_pose_graph: bad edge " + std::to_string(e.i) + "-" +
                               std::to_string(e.j));
    }
    const Eigen::LLT<geometry::Matrix6d> llt(e.information);
    if (llt.info() != Eigen::Success) {
      throw InputError("", "optimize_pose_graph: edge information is not positive definite");
    }
    const geometry::Matrix6d L = llt.matrixU();  // L' L = information
    problem.AddResidualBlock(new RelativePoseCost(e.Z_ij, L), nullptr,
                             x[static_cast<std::size_t>(e.i)].data(),
                             x[static_cast<std::size_t>(e.j)].data());
  }

  PoseGraphResult res;
  if (problem.NumResidualBlocks() > 0) {
    ceres::Solver::Options so;
    so.linear_solver_type = ceres::SPARSE_NORMAL_CHOLESKY;
    // Eigen's sparse Cholesky, not CHOLMOD: CHOLMOD is built with OpenMP here, whose uninstrumented
    // worker threads ThreadSanitizer reports as racing with the loop-closing thread; a graph of a
    // few hundred keyframes is a small system either way.
    so.sparse_linear_algebra_library_type = ceres::EIGEN_SPARSE;
    so.max_num_iterations = options.iterations;
    so.num_threads = options.num_threads;
    so.logging_type = ceres::SILENT;
    ceres::Solver::Summary summary;
    ceres::Solve(so, &problem, &summary);
    res.initial_cost = summary.initial_cost;
    res.final_cost = summary.final_cost;
    res.iterations = static_cast<int>(summary.iterations.size());
    res.usable = summary.IsSolutionUsable();
  } else {
    res.usable = true;
  }
  for (std::size_t k = 0; k < x.size(); ++k) {
    res.poses.push_back(fixed[k] ? poses[k] : from_params(x[k].data()));
  }
  return res;
}

}  // namespace plslam::optim
