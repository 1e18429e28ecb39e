// The KITTI odometry metric on a trajectory with known drift.
#include <gtest/gtest.h>

#include <cmath>

#include "eval/synthetic_trajectories.h"
#include "plslam/core/error.h"
#include "plslam/eval/kitti_metric.h"

namespace plslam::eval {
namespace {

TEST(KittiMetric, ScaleAndHeadingDriftOnAStraightRoad) {
  // Ground truth: 1 m per frame along z (integer distances, exact in floating point). A segment
  // of length L starting at f ends at f + L + 1 (first frame with distance > L). The estimate
  // drives (1 + eps) m per frame and yaws w per frame (but keeps moving along z), so the segment's
  // rotation error is (L+1) w and its translation error follows from the poses below.
  const int n = 1000;
  const double eps = 0.01, w = 1e-4;
  Trajectory gt, est;
  for (int i = 0; i < n; ++i) {
    gt.push_back({i * 0.1, test::make_pose(Eigen::Matrix3d::Identity(), {0, 0, double(i)})});
    est.push_back({i * 0.1, test::make_pose(test::rot(w * i, {0, 1, 0}), {0, 0, i * (1 + eps)})});
  }
  const auto m = kitti_odometry_metric(gt, est);
  double t_sum = 0, r_sum = 0;
  std::size_t count = 0;
  for (int first = 0; first < n; first += 10) {
    for (int L = 100; L <= 800; L += 100) {
      const int last = first + L + 1;
      if (last >= n) continue;
      // delta_est = (R_y((L+1) w), R_y(first w)^T (0,0,(L+1)(1+eps))), delta_gt = (I, (0,0,L+1)).
      const Eigen::Matrix3d Rf = test::rot(w * first, {0, 1, 0});
      const Eigen::Vector3d te = Rf.transpose() * Eigen::Vector3d(0, 0, (L + 1) * (1 + eps));
      // error = delta_est^-1 delta_gt = (Rd^T, Rd^T ((0,0,L+1) - te)); Rd^T keeps the norm.
      const double t_err = (Eigen::Vector3d(0, 0, L + 1) - te).norm();
      t_sum += t_err / L;
      r_sum += (L + 1) * w / L;
      ++count;
    }
  }
  ASSERT_EQ(m.segments.size(), count);
  EXPECT_NEAR(m.t_rel_percent, 100 * t_sum / count, 1e-9);
  EXPECT_NEAR(m.r_rel_deg_per_100m, 100 * r_sum / count * 180 / M_PI, 1e-6);
  EXPECT_EQ(m.segments.front().last_frame, 101u);
}

TEST(KittiMetric, PerfectEstimateHasZeroError) {
  Trajectory gt = test::helix(3000, 0.1);
  for (auto& p : gt) p.T.translation() *= 10.0;  // long enough for 800 m segments
  const auto m = kitti_odometry_metric(gt, gt);
  EXPECT_GT(m.segments.size(), 100u);
  EXPECT_NEAR(m.t_rel_percent, 0.0, 1e-9);
  EXPECT_NEAR(m.r_rel_deg_per_100m, 0.0, 1e-3);  // acos of the trace: ~1e-8 rad resolution
}

TEST(KittiMetric, TooShortIsInputError) {
  const Trajectory gt = test::straight_line(50, 1.0);  // 49 m
  EXPECT_THROW(kitti_odometry_metric(gt, gt), InputError);
}

}  // namespace
}  // namespace plslam::eval
