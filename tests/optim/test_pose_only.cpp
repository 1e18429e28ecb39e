// Motion-only BA on synthetic stereo frames: 1 px noise, 20 % gross outliers.
#include <cstdio>
#include <random>

#include <gtest/gtest.h>

#include "optim/synthetic_scene.h"
#include "plslam/optim/pose_only.h"

namespace plslam::optim {
namespace {

using geometry::SE3;

struct Stats {
  double worst_trans = 0.0, worst_rot = 0.0, min_recall = 1.0, max_false_positive = 0.0;
};

// Recall of the gross outliers and the share of true inliers wrongly flagged.
void score_flags(const std::vector<bool>& truth, const std::vector<bool>& flagged, int* tp,
                 int* outliers, int* fp, int* inliers) {
  for (std::size_t i = 0; i < truth.size(); ++i) {
    if (truth[i]) {
      ++*outliers;
      *tp += flagged[i] ? 1 : 0;
    } else {
      ++*inliers;
      *fp += flagged[i] ? 1 : 0;
    }
  }
}

Stats run_trials(int n_points, int n_lines, int trials, unsigned seed, double init_trans,
                 double init_rot) {
  const auto cam = test::kitti_like_camera();
  std::mt19937 rng(seed);
  Stats st;
  for (int t = 0; t < trials; ++t) {
    const SE3 T_true = test::random_pose(rng, 5.0, 1.0);
    const auto scene = test::make_pose_only_scene(cam, T_true, n_points, n_lines, 1.0, 0.2, rng);
    // Tracking starts from a constant-velocity prediction a few cm / a degree off.
    const SE3 T_init = test::random_pose(rng, init_trans, init_rot) * T_true;
    const PoseOnlyResult res = optimize_pose(cam, T_init, scene.points, scene.lines);
    st.worst_trans = std::max(st.worst_trans, test::centre_error(res.T_cw, T_true));
    st.worst_rot = std::max(st.worst_rot, test::rotation_error_deg(res.T_cw, T_true));
    int tp = 0, outliers = 0, fp = 0, inliers = 0;
    score_flags(scene.point_is_outlier, res.point_outlier, &tp, &outliers, &fp, &inliers);
    score_flags(scene.line_is_outlier, res.line_outlier, &tp, &outliers, &fp, &inliers);
    if (outliers > 0) st.min_recall = std::min(st.min_recall, static_cast<double>(tp) / outliers);
    st.max_false_positive = std::max(st.max_false_positive, static_cast<double>(fp) / inliers);
    EXPECT_GT(res.final_cost, 0.0);
    EXPECT_EQ(res.num_point_inliers + res.num_line_inliers,
              std::count(res.point_outlier.begin(), res.point_outlier.end(), false) +
                  std::count(res.line_outlier.begin(), res.line_outlier.end(), false));
  }
  std::printf("%4d points %4d lines: worst error %.2f mm %.4f deg, min outlier recall %.3f, "
              "max inliers flagged %.3f\n",
              n_points, n_lines, st.worst_trans * 1e3, st.worst_rot, st.min_recall,
              st.max_false_positive);
  return st;
}

void expect_accurate(const Stats& st) {
  EXPECT_LT(st.worst_trans, 0.01);
  EXPECT_LT(st.worst_rot, 0.1);
  EXPECT_GE(st.min_recall, 0.95);
  EXPECT_LT(st.max_false_positive, 0.15);  // the 95 % gates alone flag ~5 % (~10 % for lines)
}

TEST(PoseOnly, PointsAlone) { expect_accurate(run_trials(300, 0, 20, 1, 0.1, 0.03)); }
TEST(PoseOnly, LinesAlone) { expect_accurate(run_trials(0, 150, 20, 2, 0.1, 0.03)); }
TEST(PoseOnly, PointsAndLines) { expect_accurate(run_trials(300, 150, 20, 3, 0.1, 0.03)); }

// Outliers flagged in the first rounds (because the initial pose is far off) must come back.
TEST(PoseOnly, FarInitialGuessReincludesInliers) {
  expect_accurate(run_trials(300, 100, 10, 4, 0.4, 0.06));
}

// The covariance from the information matrix is consistent: over many frames with 1 px of
// Gaussian noise (the noise the information assumes), the NEES of the pose error averages the 6
// degrees of freedom. The 95 % gates drop the tail of the inliers, which lowers it a little.
double mean_pose_nees(int n_points, int n_lines, unsigned seed) {
  const auto cam = test::kitti_like_camera();
  std::mt19937 rng(seed);
  PoseOnlyOptions o;
  o.covariance = true;
  double sum = 0;
  const int trials = 300;
  for (int t = 0; t < trials; ++t) {
    const SE3 T_true = test::random_pose(rng, 5.0, 1.0);
    const auto scene = test::make_pose_only_scene(cam, T_true, n_points, n_lines, 1.0, 0.0, rng);
    const PoseOnlyResult res = optimize_pose(cam, test::random_pose(rng, 0.05, 0.01) * T_true, scene.points,
                                             scene.lines, o);
    EXPECT_FALSE(res.covariance.isZero(0));
    EXPECT_TRUE(res.covariance.isApprox(res.covariance.transpose()));
    // T_cw_true = exp(delta) T_cw: the perturbation the covariance is of.
    const geometry::Vector6d delta = (T_true * res.T_cw.inverse()).log();
    sum += delta.dot(res.covariance.inverse() * delta);
  }
  const double mean = sum / trials;
  std::printf("%d points %d lines: mean NEES %.2f over %d frames (6 expected)\n", n_points, n_lines, mean, trials);
  return mean;
}

TEST(PoseOnly, CovarianceOfStereoPointsIsConsistent) {
  const double m = mean_pose_nees(80, 0, 11);
  EXPECT_GT(m, 5.0);
  EXPECT_LT(m, 7.0);
}

TEST(PoseOnly, CovarianceIsZeroWhenADirectionIsUnobserved) {
  const auto cam = test::kitti_like_camera();
  std::mt19937 rng(5);
  const auto scene = test::make_pose_only_scene(cam, SE3(), 1, 0, 0.0, 0.0, rng);  // one point: rank 3
  PoseOnlyOptions o;
  o.covariance = true;
  EXPECT_TRUE(optimize_pose(cam, SE3(), scene.points, {}, o).covariance.isZero(0));
  o.covariance = false;
  const auto full = test::make_pose_only_scene(cam, SE3(), 50, 0, 1.0, 0.0, rng);
  EXPECT_TRUE(optimize_pose(cam, SE3(), full.points, {}, o).covariance.isZero(0));  // not asked for
}

TEST(PoseOnly, ExactObservationsGiveExactPose) {
  const auto cam = test::kitti_like_camera();
  std::mt19937 rng(5);
  const SE3 T_true = test::random_pose(rng, 5.0, 1.0);
  const auto scene = test::make_pose_only_scene(cam, T_true, 100, 50, 0.0, 0.0, rng);
  const auto res = optimize_pose(cam, test::random_pose(rng, 0.1, 0.03) * T_true, scene.points, scene.lines);
  EXPECT_LT(test::centre_error(res.T_cw, T_true), 1e-8);
  EXPECT_LT(test::rotation_error_deg(res.T_cw, T_true), 1e-8);
  EXPECT_EQ(res.num_point_inliers, 100);
  EXPECT_EQ(res.num_line_inliers, 50);
  EXPECT_LT(res.final_cost, 1e-12);
}

// Low texture: with fewer than 15 points, adding lines makes the pose more accurate.
TEST(PoseOnly, LinesHelpWhenFewPoints) {
  const auto cam = test::kitti_like_camera();
  std::mt19937 rng(6);
  double sum_points_only = 0.0, sum_with_lines = 0.0;
  int lines_better = 0;
  const int trials = 100;
  for (int t = 0; t < trials; ++t) {
    const SE3 T_true = test::random_pose(rng, 5.0, 1.0);
    const auto scene = test::make_pose_only_scene(cam, T_true, 12, 40, 1.0, 0.0, rng);
    const SE3 T_init = test::random_pose(rng, 0.05, 0.02) * T_true;
    const auto only = optimize_pose(cam, T_init, scene.points, {});
    const auto both = optimize_pose(cam, T_init, scene.points, scene.lines);
    // Combined translation (m) + rotation (rad) error.
    const auto err = [&](const SE3& T) {
      return test::centre_error(T, T_true) + test::rotation_error_deg(T, T_true) * M_PI / 180.0;
    };
    sum_points_only += err(only.T_cw);
    sum_with_lines += err(both.T_cw);
    lines_better += err(both.T_cw) < err(only.T_cw) ? 1 : 0;
  }
  std::printf("12 points: mean error %.2f mm+rad*1e3 alone, %.2f with 40 lines; lines better in "
              "%d/%d frames\n",
              1e3 * sum_points_only / trials, 1e3 * sum_with_lines / trials, lines_better, trials);
  EXPECT_LT(sum_with_lines, 0.7 * sum_points_only);
  EXPECT_GT(lines_better, trials * 0.6);
}

TEST(PoseOnly, EmptyInputKeepsPose) {
  const auto cam = test::kitti_like_camera();
  const SE3 T = SE3::exp((geometry::Vector6d() << 1, 2, 3, 0.1, 0.2, 0.3).finished());
  const auto res = optimize_pose(cam, T, {}, {});
  EXPECT_LT((res.T_cw.matrix() - T.matrix()).norm(), 1e-15);
  EXPECT_EQ(res.final_cost, 0.0);
}

}  // namespace
}  // namespace plslam::optim
