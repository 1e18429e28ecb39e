// Local and global BA on a synthetic 10-keyframe stereo window with exact observations.
#include <cstdio>
#include <random>
#include <set>

#include <gtest/gtest.h>

#include "optim/synthetic_scene.h"
#include "plslam/core/error.h"
#include "plslam/optim/bundle_adjustment.h"

namespace plslam::optim {
namespace {

double distance_to_line(const Eigen::Vector3d& X, const geometry::Segment3d& l) {
  return (X - l.start).cross((l.end - l.start).normalized()).norm();
}

struct Errors {
  double pose_trans = 0, pose_rot_deg = 0, point = 0, line = 0;
};

Errors errors(const test::BaScene& s, const BaResult& r) {
  Errors e;
  for (std::size_t k = 0; k < s.poses_true.size(); ++k) {
    e.pose_trans = std::max(e.pose_trans, test::centre_error(r.poses[k], s.poses_true[k]));
    e.pose_rot_deg = std::max(e.pose_rot_deg, test::rotation_error_deg(r.poses[k], s.poses_true[k]));
  }
  for (std::size_t i = 0; i < s.points_true.size(); ++i) {
    e.point = std::max(e.point, (r.points[i] - s.points_true[i]).norm());
  }
  for (std::size_t i = 0; i < s.lines_true.size(); ++i) {
    e.line = std::max({e.line, distance_to_line(r.lines[i].start, s.lines_true[i]),
                       distance_to_line(r.lines[i].end, s.lines_true[i])});
  }
  std::printf("max pose error %.3g mm %.3g deg, point %.3g mm, line endpoint-to-line %.3g mm\n",
              e.pose_trans * 1e3, e.pose_rot_deg, e.point * 1e3, e.line * 1e3);
  return e;
}

TEST(BundleAdjustment, LocalWindowConvergesToGroundTruth) {
  const auto cam = test::kitti_like_camera();
  std::mt19937 rng(1);
  auto scene = test::make_ba_scene(cam, 10, 600, 80, rng);
  // Keyframes 0 and 1 play the covisible keyframes outside the window: fixed at ground truth.
  scene.problem.keyframes[0].fixed = scene.problem.keyframes[1].fixed = true;
  test::perturb(&scene.problem, 0.05, 0.01, 0.05, rng);
  BaOptions opt;
  opt.iterations = 15;
  const BaResult r = local_bundle_adjustment(cam, scene.problem, opt);
  ASSERT_TRUE(r.usable) << r.message;
  const Errors e = errors(scene, r);
  EXPECT_LT(e.pose_trans, 1e-3);
  EXPECT_LT(e.pose_rot_deg, 0.01);
  EXPECT_LT(e.point, 0.05);  // far points: depth is the weak direction
  EXPECT_LT(e.line, 0.01);
  EXPECT_LT(r.final_cost, 1e-6 * r.initial_cost);
  // With exact observations nothing is an outlier at the end.
  EXPECT_EQ(std::count(r.point_observation_outlier.begin(), r.point_observation_outlier.end(), true), 0);
  EXPECT_EQ(std::count(r.line_observation_outlier.begin(), r.line_observation_outlier.end(), true), 0);
}

TEST(BundleAdjustment, LocalWindowRemovesGrossOutliers) {
  const auto cam = test::kitti_like_camera();
  std::mt19937 rng(2);
  auto scene = test::make_ba_scene(cam, 10, 600, 80, rng);
  scene.problem.keyframes[0].fixed = scene.problem.keyframes[1].fixed = true;
  // Corrupt 5 % of the observations by 30 px.
  std::vector<bool> bad_point(scene.problem.point_observations.size(), false);
  std::vector<bool> bad_line(scene.problem.line_observations.size(), false);
  for (std::size_t i = 0; i < bad_point.size(); i += 20) {
    scene.problem.point_observations[i].measurement += Eigen::Vector3d(30.0, -20.0, 30.0);
    bad_point[i] = true;
  }
  for (std::size_t i = 0; i < bad_line.size(); i += 20) {
    scene.problem.line_observations[i].left_line(2) += 30.0;
    scene.problem.line_observations[i].right_line(2) += 30.0;
    bad_line[i] = true;
  }
  test::perturb(&scene.problem, 0.03, 0.005, 0.03, rng);
  BaOptions opt;
  opt.iterations = 15;
  const BaResult r = local_bundle_adjustment(cam, scene.problem, opt);
  ASSERT_TRUE(r.usable) << r.message;
  const Errors e = errors(scene, r);
  // The second pass runs without the corrupted observations: exact again.
  EXPECT_LT(e.pose_trans, 1e-3);
  // Every corrupted observation is flagged. A correct observation may only be flagged as
  // collateral: when it shares its landmark with a corrupted one (with two views, the robust
  // first pass can pull that landmark off both).
  std::set<int> tainted_points, tainted_lines;
  for (std::size_t i = 0; i < bad_point.size(); ++i) {
    if (bad_point[i]) tainted_points.insert(scene.problem.point_observations[i].point);
  }
  for (std::size_t i = 0; i < bad_line.size(); ++i) {
    if (bad_line[i]) tainted_lines.insert(scene.problem.line_observations[i].line);
  }
  int missed = 0, flagged_good = 0, flagged_innocent = 0;
  for (std::size_t i = 0; i < bad_point.size(); ++i) {
    missed += bad_point[i] && !r.point_observation_outlier[i];
    if (!bad_point[i] && r.point_observation_outlier[i]) {
      ++flagged_good;
      flagged_innocent += tainted_points.count(scene.problem.point_observations[i].point) == 0;
    }
  }
  for (std::size_t i = 0; i < bad_line.size(); ++i) {
    missed += bad_line[i] && !r.line_observation_outlier[i];
    if (!bad_line[i] && r.line_observation_outlier[i]) {
      ++flagged_good;
      flagged_innocent += tainted_lines.count(scene.problem.line_observations[i].line) == 0;
    }
  }
  std::printf("corrupted %zu+%zu observations: missed %d, correct ones flagged %d (innocent %d)\n",
              tainted_points.size(), tainted_lines.size(), missed, flagged_good, flagged_innocent);
  EXPECT_EQ(missed, 0);
  EXPECT_EQ(flagged_innocent, 0);
  EXPECT_LE(flagged_good, 10);
}

TEST(BundleAdjustment, GlobalConvergesWithFirstKeyframeFixed) {
  const auto cam = test::kitti_like_camera();
  std::mt19937 rng(3);
  auto scene = test::make_ba_scene(cam, 10, 600, 80, rng);
  test::perturb(&scene.problem, 0.05, 0.01, 0.05, rng);
  scene.problem.keyframes[0].T_cw = scene.poses_true[0];  // the gauge: the first keyframe
  BaOptions opt;
  opt.iterations = 20;
  opt.linear_solver = BaLinearSolver::kSparseSchur;
  const BaResult r = global_bundle_adjustment(cam, scene.problem, opt);
  ASSERT_TRUE(r.usable) << r.message;
  const Errors e = errors(scene, r);
  EXPECT_LT(e.pose_trans, 1e-3);
  EXPECT_LT(e.pose_rot_deg, 0.01);
  EXPECT_LT(e.line, 0.01);
  EXPECT_LT((r.poses[0].matrix() - scene.poses_true[0].matrix()).norm(), 1e-15);
}

TEST(BundleAdjustment, BadIndexIsAnInputError) {
  const auto cam = test::kitti_like_camera();
  BaProblem p;
  p.keyframes.push_back({});
  p.point_observations.push_back({});  // point 0 does not exist
  EXPECT_THROW(bundle_adjust(cam, p), InputError);
}

}  // namespace
}  // namespace plslam::optim
