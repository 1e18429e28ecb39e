// APE and RPE on trajectories whose errors are known in closed form.
#include <gtest/gtest.h>

#include <cmath>

#include "eval/synthetic_trajectories.h"
#include "plslam/core/error.h"
#include "plslam/eval/evaluate.h"

namespace plslam::eval {
namespace {

using test::helix;
using test::make_pose;
using test::rot;
using test::straight_line;

// est = S^-1 * gt for a known Sim(3) S = (s, R, t): positions x = R^T (p - t) / s.
Trajectory inverse_sim3(const Trajectory& gt, double s, const Eigen::Matrix3d& R, const Eigen::Vector3d& t) {
  Trajectory est = gt;
  for (auto& p : est) {
    p.T.translation() = R.transpose() * (p.T.translation() - t) / s;
    p.T.linear() = R.transpose() * p.T.linear();
  }
  return est;
}

TEST(Ape, Sim3AlignmentUndoesAKnownSimilarityExactly) {
  const Trajectory gt = helix(200);
  const Eigen::Matrix3d R = rot(1.2, {1, -1, 0.5});
  const Eigen::Vector3d t(10, -4, 2);
  const Trajectory est = inverse_sim3(gt, 0.37, R, t);
  EvalOptions o;
  o.align = AlignMode::kSim3;
  const auto r = evaluate(gt, est, o);
  EXPECT_NEAR(r.alignment.s, 0.37, 1e-12);
  EXPECT_LT((r.alignment.R - R).norm(), 1e-10);
  EXPECT_LT(r.ape_trans_stats.max, 1e-10);
  EXPECT_LT(r.rpe_trans_stats.max, 1e-10);
  EXPECT_LT(r.rpe_rot_stats.max, 1e-5);  // degrees
  EXPECT_EQ(r.pairs.size(), 200u);
}

TEST(Ape, Se3AlignmentCannotUndoScale) {
  const Trajectory gt = helix(200);
  const Trajectory est = inverse_sim3(gt, 0.5, Eigen::Matrix3d::Identity(), Eigen::Vector3d::Zero());
  EvalOptions o;  // se3
  EXPECT_GT(evaluate(gt, est, o).ape_trans_stats.rmse, 0.5);
}

TEST(Ape, KnownNoiseAfterSe3Alignment) {
  // Every ground-truth position appears twice; the estimate displaces the two copies by +n and
  // -n. The displacements cancel in the alignment's normal equations, so the known rigid transform
  // is recovered exactly and APE_i = |n_i|.
  const Trajectory base = helix(100);
  Trajectory gt;
  std::vector<double> expected;
  Trajectory est_true;
  for (std::size_t k = 0; k < base.size(); ++k) {
    const Eigen::Vector3d n = 0.01 * (1.0 + static_cast<double>(k % 5)) *
                              Eigen::Vector3d(std::cos(0.7 * k), std::sin(0.7 * k), 0.5).normalized();
    for (int sign : {1, -1}) {
      StampedPose g = base[k];
      g.t = 0.2 * static_cast<double>(k) + (sign > 0 ? 0.0 : 0.1);
      gt.push_back(g);
      StampedPose e = g;
      e.T.translation() += sign * n;
      est_true.push_back(e);
      expected.push_back(n.norm());
    }
  }
  const Eigen::Matrix3d R = rot(-2.0, {0.3, 0.3, 1});
  const Trajectory est = inverse_sim3(est_true, 1.0, R, {1, 2, 3});
  const auto r = evaluate(gt, est, EvalOptions{});
  ASSERT_EQ(r.ape_trans_m.size(), expected.size());
  for (std::size_t i = 0; i < expected.size(); ++i) EXPECT_NEAR(r.ape_trans_m[i], expected[i], 1e-12);
  const auto s = compute_statistics(expected);
  EXPECT_NEAR(r.ape_trans_stats.rmse, s.rmse, 1e-12);
  // Magnitudes 0.01..0.05 m equally often: mean 0.03, rmse sqrt(0.0011).
  EXPECT_NEAR(r.ape_trans_stats.mean, 0.03, 1e-12);
  EXPECT_NEAR(r.ape_trans_stats.rmse, std::sqrt(0.0011), 1e-12);
  EXPECT_NEAR(r.ape_trans_stats.median, 0.03, 1e-12);
  EXPECT_NEAR(r.ape_trans_stats.min, 0.01, 1e-12);
  EXPECT_NEAR(r.ape_trans_stats.max, 0.05, 1e-12);
}

TEST(Rpe, ScaleDriftOnAStraightLine) {
  // Q_i = (I, i v e_x), P_i = (I, i v (1 + eps) e_x): E = (I, k v eps e_x) for a k-frame delta.
  const double v = 0.5, eps = 0.02;
  const Trajectory gt = straight_line(101, v);
  const Trajectory est = straight_line(101, v * (1 + eps));
  EvalOptions o;
  o.align = AlignMode::kNone;
  o.rpe.delta = 4;
  const auto r = evaluate(gt, est, o);
  ASSERT_EQ(r.rpe.pairs.size(), 25u);  // (0,4), (4,8), ..., (96,100)
  EXPECT_EQ(r.rpe.pairs.front(), (std::pair<std::size_t, std::size_t>(0, 4)));
  EXPECT_EQ(r.rpe.pairs.back(), (std::pair<std::size_t, std::size_t>(96, 100)));
  EXPECT_NEAR(r.rpe_trans_stats.min, 4 * v * eps, 1e-12);
  EXPECT_NEAR(r.rpe_trans_stats.max, 4 * v * eps, 1e-12);
  EXPECT_NEAR(r.rpe_rot_stats.max, 0.0, 1e-12);
  o.rpe.all_pairs = true;
  EXPECT_EQ(evaluate(gt, est, o).rpe.pairs.size(), 97u);  // (i, i+4) for i = 0..96
}

TEST(Rpe, TurningEstimateOnAStraightLine) {
  // P_i = (R_z(i w), i v e_x): E_i = (R_z(w), R_z(-i w) v e_x - v e_x), so the rotation error is
  // w and the translation error 2 v |sin(i w / 2)| for the pair (i, i+1).
  const double v = 1.0, w = 0.01;
  const Trajectory gt = straight_line(50, v);
  Trajectory est = gt;
  for (std::size_t i = 0; i < est.size(); ++i) est[i].T.linear() = rot(w * static_cast<double>(i), {0, 0, 1});
  EvalOptions o;
  o.align = AlignMode::kNone;
  const auto r = evaluate(gt, est, o);
  ASSERT_EQ(r.rpe.pairs.size(), 49u);
  for (std::size_t k = 0; k < r.rpe.pairs.size(); ++k) {
    const double i = static_cast<double>(r.rpe.pairs[k].first);
    EXPECT_NEAR(r.rpe.trans_m[k], 2 * v * std::abs(std::sin(i * w / 2)), 1e-12);
    EXPECT_NEAR(r.rpe.rot_deg[k], w * 180.0 / M_PI, 1e-9);
  }
}

TEST(Rpe, DeltaInMetresConsecutivePairsFollowEvo) {
  // 0.3 m steps, delta 1 m: the path resets at the poses where it reaches 1 m: 4 (1.2 m), 8, ...
  // (evo starts counting at pose 0 but its first id is the first pose reaching delta).
  const Trajectory line = straight_line(41, 0.3);
  RpeOptions o;
  o.delta = 1.0;
  o.unit = DeltaUnit::kMeters;
  const auto pairs = rpe_id_pairs(line, o);
  ASSERT_EQ(pairs.size(), 9u);  // ids 4, 8, ..., 40
  EXPECT_EQ(pairs.front(), (std::pair<std::size_t, std::size_t>(4, 8)));
  EXPECT_EQ(pairs.back(), (std::pair<std::size_t, std::size_t>(36, 40)));
}

TEST(Rpe, DeltaInMetresAllPairsPicksTheNearestPathLength) {
  // 0.3 m steps, delta 1 m, tolerance 0.1 m: from i the nearest path is 0.9 m (3 steps, residual
  // 0.1 m, accepted as |0.9 - 1| <= 0.1 up to rounding) or 1.2 m (4 steps). 3 steps wins.
  const Trajectory line = straight_line(20, 0.3);
  RpeOptions o;
  o.delta = 1.0;
  o.unit = DeltaUnit::kMeters;
  o.all_pairs = true;
  o.rel_delta_tol = 0.2;
  const auto pairs = rpe_id_pairs(line, o);
  ASSERT_EQ(pairs.size(), 17u);  // i = 0..16
  for (const auto& [i, j] : pairs) EXPECT_EQ(j, i + 3);
  o.rel_delta_tol = 0.05;  // 0.1 m residual rejected
  EXPECT_THROW(rpe_id_pairs(line, o), InputError);
}

TEST(Rpe, AllPairsInMetresSkipsStandstillLikeArgmin) {
  // Poses 3..5 stand still: from 0, path 1.0 m is reached first at pose 3 (then 4 and 5 tie).
  Trajectory t = straight_line(10, 1.0 / 3.0);
  for (std::size_t i = 4; i < t.size(); ++i) t[i].T.translation().x() = t[i].T.translation().x() - (i < 6 ? (i - 3) / 3.0 : 2 / 3.0);
  RpeOptions o;
  o.delta = 1.0;
  o.unit = DeltaUnit::kMeters;
  o.all_pairs = true;
  const auto pairs = rpe_id_pairs(t, o);
  ASSERT_FALSE(pairs.empty());
  EXPECT_EQ(pairs.front(), (std::pair<std::size_t, std::size_t>(0, 3)));
}

TEST(Rpe, InvariantToARigidTransformOfTheEstimate) {
  const Trajectory gt = helix(120);
  Trajectory est = gt;
  for (std::size_t i = 0; i < est.size(); ++i) {
    est[i].T = est[i].T * make_pose(rot(0.01 * std::sin(0.3 * i), {1, 0, 0}), {0.01 * std::cos(0.2 * i), 0, 0});
  }
  const Eigen::Isometry3d A = make_pose(rot(0.9, {1, 1, 0}), {5, 5, 5});
  Trajectory moved = est;
  for (auto& p : moved) p.T = A * p.T;
  EvalOptions none;
  none.align = AlignMode::kNone;
  const auto a = evaluate(gt, est, none);
  const auto b = evaluate(gt, moved, EvalOptions{});
  EXPECT_NEAR(a.rpe_trans_stats.rmse, b.rpe_trans_stats.rmse, 1e-12);
  EXPECT_NEAR(a.rpe_rot_stats.rmse, b.rpe_rot_stats.rmse, 1e-9);
  // SE(3) alignment takes the moved estimate back: its APE equals that of the unmoved one.
  const auto c = evaluate(gt, est, EvalOptions{});
  EXPECT_NEAR(c.ape_trans_stats.rmse, b.ape_trans_stats.rmse, 1e-12);
  EXPECT_LE(c.ape_trans_stats.rmse, a.ape_trans_stats.rmse);
}

TEST(Rpe, RotationAngleIsAccurateNearZeroAndPi) {
  for (double a : {1e-9, 1e-5, 0.3, 2.0, M_PI - 1e-7, M_PI}) {
    EXPECT_NEAR(rotation_angle(rot(a, {0.2, -0.5, 1})), a, 1e-12 + 1e-9 * a) << a;
  }
}

TEST(Rpe, BadDeltaIsInputError) {
  const Trajectory gt = helix(10);
  RpeOptions o;
  o.delta = 1.5;
  EXPECT_THROW(rpe_id_pairs(gt, o), InputError);
  o.delta = 10;  // no pair in 10 poses
  EXPECT_THROW(rpe_id_pairs(gt, o), InputError);
  o.delta = 0;
  EXPECT_THROW(rpe_id_pairs(gt, o), InputError);
}

TEST(Evaluate, FewerThanThreePairsIsInputError) {
  const Trajectory gt = helix(50);
  Trajectory est(gt.begin(), gt.begin() + 2);
  EXPECT_THROW(evaluate(gt, est, EvalOptions{}), InputError);
  Trajectory far = helix(50);
  for (auto& p : far) p.t += 100.0;  // no stamp within 0.01 s
  EXPECT_THROW(evaluate(gt, far, EvalOptions{}), InputError);
  EvalOptions by_index;
  by_index.pair_by_index = true;
  EXPECT_THROW(evaluate(gt, helix(49), by_index), InputError);  // mismatched lengths
}

}  // namespace
}  // namespace plslam::eval
