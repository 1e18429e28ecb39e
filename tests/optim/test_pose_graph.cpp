// SE(3) pose graph: an odometry chain with injected drift plus one loop edge.
#include <cstdio>
#include <random>

#include <gtest/gtest.h>

#include "optim/synthetic_scene.h"
#include "plslam/core/error.h"
#include "plslam/optim/ceres_costs.h"
#include "plslam/optim/pose_graph.h"

namespace plslam::optim {
namespace {

using geometry::SE3;

// A closed loop (circle of radius 20 m, 60 poses) returning near its start.
std::vector<SE3> loop_trajectory(int n) {
  std::vector<SE3> T_cw;
  for (int k = 0; k < n; ++k) {
    const double a = 2.0 * M_PI * k / n;
    // Camera looks along the tangent (z forward), y down: yaw about the camera's y axis.
    const Eigen::Matrix3d R_wc = geometry::so3_exp(Eigen::Vector3d(0.0, -a, 0.0));
    const Eigen::Vector3d c(20.0 * std::sin(a), 0.3 * std::sin(3 * a), 20.0 * (1 - std::cos(a)));
    T_cw.push_back(SE3(R_wc, c).inverse());
  }
  return T_cw;
}

TEST(PoseGraph, LoopEdgeRemovesInjectedDrift) {
  std::mt19937 rng(1);
  const int n = 60;
  const auto gt = loop_trajectory(n);
  std::vector<PoseGraphEdge> edges;
  // Odometry edges with a little measurement noise (0.1 mm, 0.001 deg per edge; their random walk
  // alone would be ~1 cm after 60 edges without the loop edge).
  for (int k = 0; k + 1 < n; ++k) {
    const SE3 Z = test::random_pose(rng, 1e-4, 1.7e-5) * gt[k] * gt[k + 1].inverse();
    edges.push_back({k, k + 1, Z, geometry::Matrix6d::Identity() * 100.0});
  }
  // Loop edge from the last pose back to the first, as a loop closure would measure it.
  edges.push_back({0, n - 1, gt[0] * gt[n - 1].inverse(), geometry::Matrix6d::Identity() * 100.0});

  // Initial guess: the odometry chain with drift injected (a yaw and a scale-free offset that
  // grow along the trajectory): about 2.5 m and 6 deg off at the end.
  std::vector<SE3> init = gt;
  for (int k = 0; k < n; ++k) {
    const double s = static_cast<double>(k) / n;
    geometry::Vector6d drift;
    drift << 2.0 * s, 0.3 * s, -1.5 * s, 0.02 * s, 0.1 * s, -0.03 * s;
    init[static_cast<std::size_t>(k)] = gt[static_cast<std::size_t>(k)] * SE3::exp(drift);
  }
  std::vector<bool> fixed(n, false);
  fixed[0] = true;

  double init_err = 0.0;
  for (int k = 0; k < n; ++k) init_err = std::max(init_err, test::centre_error(init[k], gt[k]));
  const PoseGraphResult r = optimize_pose_graph(init, fixed, edges);
  ASSERT_TRUE(r.usable);
  double worst = 0.0, worst_rot = 0.0;
  for (int k = 0; k < n; ++k) {
    worst = std::max(worst, test::centre_error(r.poses[k], gt[k]));
    worst_rot = std::max(worst_rot, test::rotation_error_deg(r.poses[k], gt[k]));
  }
  std::printf("pose graph: initial max error %.3f m, final %.2f mm %.4f deg, %d iterations\n",
              init_err, worst * 1e3, worst_rot, r.iterations);
  EXPECT_GT(init_err, 1.0);
  EXPECT_LT(worst, 0.01);
  EXPECT_LT(worst_rot, 0.1);
  EXPECT_LT(r.final_cost, r.initial_cost);
}

// Weighted edges: a conflicting low-weight edge barely moves the result.
TEST(PoseGraph, InformationWeightsEdges) {
  const std::vector<SE3> init(2);
  const SE3 Z_strong = SE3::exp((geometry::Vector6d() << 1, 0, 0, 0, 0, 0).finished());
  const SE3 Z_weak = SE3::exp((geometry::Vector6d() << 2, 0, 0, 0, 0, 0).finished());
  const std::vector<PoseGraphEdge> edges = {
      {0, 1, Z_strong, geometry::Matrix6d::Identity() * 1e4},
      {0, 1, Z_weak, geometry::Matrix6d::Identity()}};
  const auto r = optimize_pose_graph(init, {true, false}, edges);
  const double x = (r.poses[0] * r.poses[1].inverse()).log()(0);
  // Weighted mean of the two measurements: (1e4 * 1 + 1 * 2) / (1e4 + 1).
  EXPECT_NEAR(x, (1e4 + 2.0) / (1e4 + 1.0), 1e-6);
}

TEST(PoseGraph, BadInputIsAnInputError) {
  const std::vector<SE3> poses(3);
  EXPECT_THROW(optimize_pose_graph(poses, {true, false}, {}), InputError);
  EXPECT_THROW(optimize_pose_graph(poses, {true, false, false}, {{0, 3, SE3(), geometry::Matrix6d::Identity()}}), InputError);
  EXPECT_THROW(optimize_pose_graph(poses, {true, false, false}, {{0, 1, SE3(), -geometry::Matrix6d::Identity()}}), InputError);
}

// A z-up world: a circle of radius 10 m in the xy plane, the camera level and looking along it
// (z forward horizontal, y down = -z of the world).
std::vector<SE3> level_loop(int n) {
  std::vector<SE3> T_cw;
  for (int k = 0; k < n; ++k) {
    const double a = 2.0 * M_PI * k / n;
    const Eigen::Vector3d forward(std::cos(a), std::sin(a), 0), down(0, 0, -1);
    Eigen::Matrix3d R_wc;
    R_wc.col(1) = down;
    R_wc.col(2) = forward;
    R_wc.col(0) = R_wc.col(1).cross(R_wc.col(2));
    T_cw.push_back(SE3(R_wc, Eigen::Vector3d(10 * std::sin(a), 10 * (1 - std::cos(a)), 0.2 * std::sin(2 * a))).inverse());
  }
  return T_cw;
}

// Where the world's up axis lies in the camera: what roll and pitch are.
Eigen::Vector3d up_in_camera(const SE3& T_cw) { return T_cw.rotation() * Eigen::Vector3d::UnitZ(); }

TEST(YawTranslationManifold, JacobianIsTheLeftDeltaOfPlusAndMinusInvertsIt) {
  std::mt19937 rng(4);
  const YawTranslationManifold m;
  for (int trial = 0; trial < 5; ++trial) {
    const SE3 T = test::random_pose(rng, 3.0, 0.8);
    const PoseParams x = to_params(T);
    Eigen::Matrix<double, 7, 4, Eigen::RowMajor> J;
    ASSERT_TRUE(m.PlusJacobian(x.data(), J.data()));
    EXPECT_EQ(J.row(6).norm(), 0.0);
    const double h = 1e-6;
    for (int c = 0; c < 4; ++c) {
      double d[4] = {0, 0, 0, 0};
      PoseParams plus, minus;
      d[c] = h;
      m.Plus(x.data(), d, plus.data());
      d[c] = -h;
      m.Plus(x.data(), d, minus.data());
      const geometry::Vector6d numeric = ((from_params(plus.data()) * T.inverse()).log() -
                                          (from_params(minus.data()) * T.inverse()).log()) / (2 * h);
      EXPECT_LT((J.col(c).head<6>() - numeric).norm(), 1e-6 * std::max(1.0, numeric.norm())) << "column " << c;
    }
    const double d[4] = {0.3, -0.2, 0.5, 0.4};
    PoseParams y;
    m.Plus(x.data(), d, y.data());
    double back[4];
    m.Minus(y.data(), x.data(), back);
    for (int c = 0; c < 4; ++c) EXPECT_NEAR(back[c], d[c], 1e-12);
    // The move leaves the up axis where the camera saw it.
    EXPECT_LT((up_in_camera(from_params(y.data())) - up_in_camera(T)).norm(), 1e-12);
  }
}

// Odometry drift in yaw and translation, closed by a loop edge: the 4-DoF graph removes it and
// leaves every node's roll and pitch exactly as they were; the 6-DoF graph tilts them.
TEST(PoseGraph, FourDofClosesYawAndTranslationDriftAndKeepsTheTilt) {
  const int n = 40;
  const auto gt = level_loop(n);
  std::vector<PoseGraphEdge> edges;
  for (int k = 0; k + 1 < n; ++k) edges.push_back({k, k + 1, gt[k] * gt[k + 1].inverse(), geometry::Matrix6d::Identity()});
  edges.push_back({0, n - 1, gt[0] * gt[n - 1].inverse(), geometry::Matrix6d::Identity()});
  std::vector<SE3> init = gt;
  for (int k = 0; k < n; ++k) {
    const double s = static_cast<double>(k) / n;
    // 5 deg of yaw about the world's z and 1 m of drift by the end.
    const SE3 drift(Eigen::AngleAxisd(0.09 * s, Eigen::Vector3d::UnitZ()).toRotationMatrix(), Eigen::Vector3d(0.6, -0.8, 0.1) * s);
    init[static_cast<std::size_t>(k)] = (drift * gt[static_cast<std::size_t>(k)].inverse()).inverse();
  }
  std::vector<bool> fixed(n, false);
  fixed[0] = true;
  PoseGraphOptions o;
  o.four_dof = true;
  const auto r = optimize_pose_graph(init, fixed, edges, o);
  ASSERT_TRUE(r.usable);
  double worst = 0, worst_tilt = 0;
  for (int k = 0; k < n; ++k) {
    worst = std::max(worst, test::centre_error(r.poses[k], gt[k]));
    worst_tilt = std::max(worst_tilt, (up_in_camera(r.poses[k]) - up_in_camera(init[k])).norm());
  }
  EXPECT_LT(worst, 1e-6);
  EXPECT_LT(worst_tilt, 1e-12);
  // One edge measured with 1 deg of roll: the 6-DoF graph tilts the nodes to share it out, the
  // 4-DoF one cannot.
  std::vector<PoseGraphEdge> rolled = edges;
  rolled[20].Z_ij = SE3::exp((geometry::Vector6d() << 0, 0, 0, 0, 0, 0.0175).finished()) * rolled[20].Z_ij;
  const auto r6 = optimize_pose_graph(init, fixed, rolled);
  const auto r4 = optimize_pose_graph(init, fixed, rolled, o);
  EXPECT_GT((up_in_camera(r6.poses[10]) - up_in_camera(init[10])).norm(), 1e-3);
  for (int k = 0; k < n; ++k) EXPECT_LT((up_in_camera(r4.poses[k]) - up_in_camera(init[k])).norm(), 1e-12) << k;
}

}  // namespace
}  // namespace plslam::optim
