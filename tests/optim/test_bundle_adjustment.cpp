// Local and global BA on a synthetic 10-keyframe stereo window with exact observations, for both
// backends (hand-written Schur LM and Ceres), and agreement between the two.
#include <algorithm>
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

const char* backend_name(BaBackend b) { return b == BaBackend::kSchurLM ? "SchurLM" : "Ceres"; }

class BundleAdjustmentBackends : public ::testing::TestWithParam<BaBackend> {
 protected:
  BaOptions options() const {
    BaOptions opt;
    opt.backend = GetParam();
    return opt;
  }
};

INSTANTIATE_TEST_SUITE_P(Backends, BundleAdjustmentBackends,
                         ::testing::Values(BaBackend::kSchurLM, BaBackend::kCeres),
                         [](const auto& info) { return std::string(backend_name(info.param)); });

TEST_P(BundleAdjustmentBackends, LocalWindowConvergesToGroundTruth) {
  const auto cam = test::kitti_like_camera();
  std::mt19937 rng(1);
  auto scene = test::make_ba_scene(cam, 10, 600, 80, rng);
  // Keyframes 0 and 1 play the covisible keyframes outside the window: fixed at ground truth.
  scene.problem.keyframes[0].fixed = scene.problem.keyframes[1].fixed = true;
  test::perturb(&scene.problem, 0.05, 0.01, 0.05, rng);
  BaOptions opt = options();
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

TEST_P(BundleAdjustmentBackends, LocalWindowRemovesGrossOutliers) {
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
  BaOptions opt = options();
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

TEST_P(BundleAdjustmentBackends, GlobalConvergesWithFirstKeyframeFixed) {
  const auto cam = test::kitti_like_camera();
  std::mt19937 rng(3);
  auto scene = test::make_ba_scene(cam, 10, 600, 80, rng);
  test::perturb(&scene.problem, 0.05, 0.01, 0.05, rng);
  scene.problem.keyframes[0].T_cw = scene.poses_true[0];  // the gauge: the first keyframe
  BaOptions opt = options();
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

TEST_P(BundleAdjustmentBackends, BadIndexIsAnInputError) {
  const auto cam = test::kitti_like_camera();
  BaProblem p;
  p.keyframes.push_back({});
  p.point_observations.push_back({});  // point 0 does not exist
  EXPECT_THROW(bundle_adjust(cam, p, options()), InputError);
}

TEST_P(BundleAdjustmentBackends, EmptyProblemIsNotUsable) {
  const auto cam = test::kitti_like_camera();
  BaProblem p;
  p.keyframes.push_back({});
  const BaResult r = bundle_adjust(cam, p, options());
  EXPECT_FALSE(r.usable);
  ASSERT_EQ(r.poses.size(), 1u);
  EXPECT_LT((r.poses[0].matrix() - Eigen::Matrix4d::Identity()).norm(), 1e-15);
}

// Fixed landmarks stay exactly where they are and still constrain the free keyframes.
TEST_P(BundleAdjustmentBackends, FixedLandmarksStayAndConstrain) {
  const auto cam = test::kitti_like_camera();
  std::mt19937 rng(4);
  auto scene = test::make_ba_scene(cam, 6, 300, 40, rng);
  scene.problem.keyframes[0].fixed = true;
  for (std::size_t i = 0; i < scene.problem.points.size(); i += 3) scene.problem.points[i].fixed = true;
  for (std::size_t i = 0; i < scene.problem.lines.size(); i += 3) scene.problem.lines[i].fixed = true;
  test::perturb(&scene.problem, 0.03, 0.005, 0.0, rng);  // landmarks exact, poses off
  // Perturb only the free landmarks.
  std::normal_distribution<double> g(0.0, 0.03);
  for (auto& pt : scene.problem.points) {
    if (!pt.fixed) pt.position += Eigen::Vector3d(g(rng), g(rng), g(rng));
  }
  for (auto& l : scene.problem.lines) {
    if (!l.fixed) l.start += Eigen::Vector3d(g(rng), g(rng), g(rng));
  }
  BaOptions opt = options();
  opt.iterations = 20;
  const BaResult r = bundle_adjust(cam, scene.problem, opt);
  ASSERT_TRUE(r.usable) << r.message;
  const Errors e = errors(scene, r);
  EXPECT_LT(e.pose_trans, 1e-3);
  EXPECT_LT(e.line, 0.01);
  for (std::size_t i = 0; i < scene.problem.points.size(); i += 3) {
    EXPECT_EQ(r.points[i], scene.problem.points[i].position);
  }
  for (std::size_t i = 0; i < scene.problem.lines.size(); i += 3) {
    EXPECT_EQ(r.lines[i].start, scene.problem.lines[i].start);
    EXPECT_EQ(r.lines[i].end, scene.problem.lines[i].end);
  }
}

// Endpoints displaced ALONG their 3D line cost nothing (the 2-D gauge of each line block): with
// the endpoints slid along the true lines and the poses and points perturbed, the damped system
// must neither blow up nor let the endpoints wander along their line.
TEST_P(BundleAdjustmentBackends, LineEndpointsSlidingAlongTheLineStayWellConditioned) {
  const auto cam = test::kitti_like_camera();
  std::mt19937 rng(5);
  auto scene = test::make_ba_scene(cam, 8, 300, 60, rng);
  scene.problem.keyframes[0].fixed = true;
  std::uniform_real_distribution<double> slide(-0.3, 0.3);
  std::normal_distribution<double> g(0.0, 0.02);
  std::vector<Eigen::Vector3d> start_along, end_along;  // initial endpoints, on the true line
  for (auto& l : scene.problem.lines) {
    const Eigen::Vector3d d = (l.end - l.start).normalized();
    l.start += slide(rng) * d;
    l.end += slide(rng) * d;
    start_along.push_back(l.start);
    end_along.push_back(l.end);
  }
  test::perturb(&scene.problem, 0.02, 0.005, 0.0, rng);
  for (auto& pt : scene.problem.points) pt.position += Eigen::Vector3d(g(rng), g(rng), g(rng));
  BaOptions opt = options();
  opt.iterations = 50;  // long enough for the damping to reach its floor
  const BaResult r = bundle_adjust(cam, scene.problem, opt);
  ASSERT_TRUE(r.usable) << r.message;
  const Errors e = errors(scene, r);
  EXPECT_LT(e.pose_trans, 1e-3);
  EXPECT_LT(e.line, 1e-3);
  double drift = 0.0;  // along-line motion of the endpoints, relative to their start on the line
  for (std::size_t i = 0; i < r.lines.size(); ++i) {
    ASSERT_TRUE(r.lines[i].start.allFinite() && r.lines[i].end.allFinite());
    const Eigen::Vector3d d = (scene.lines_true[i].end - scene.lines_true[i].start).normalized();
    drift = std::max({drift, std::abs(d.dot(r.lines[i].start - start_along[i])),
                      std::abs(d.dot(r.lines[i].end - end_along[i]))});
  }
  std::printf("max endpoint drift along the line %.3g m\n", drift);
  EXPECT_LT(drift, 0.05);  // vs. slides of up to 0.3 m
}

// The two backends minimise the same cost: identical initial cost, and after convergence on
// noisy observations (a unique optimum up to the line gauge) the same poses and final cost.
TEST(BundleAdjustment, BackendsAgreeOnNoisyProblem) {
  const auto cam = test::kitti_like_camera();
  std::mt19937 rng(6);
  auto scene = test::make_ba_scene(cam, 8, 400, 60, rng);
  scene.problem.keyframes[0].fixed = scene.problem.keyframes[1].fixed = true;
  std::normal_distribution<double> noise(0.0, 1.0);
  for (auto& o : scene.problem.point_observations) {
    o.measurement += Eigen::Vector3d(noise(rng), noise(rng), noise(rng));
    o.level = static_cast<int>(rng() % 4);
  }
  for (auto& o : scene.problem.line_observations) {
    o.left_line(2) += 3.0 * noise(rng);  // some pairs beyond the Huber threshold
    o.right_line(2) += noise(rng);
  }
  scene.problem.point_observations[7].has_right = false;
  test::perturb(&scene.problem, 0.02, 0.005, 0.02, rng);
  BaOptions opt;
  opt.iterations = 50;
  // To convergence: the lines' endpoints move only across the lines, a slower valley for both.
  opt.function_tolerance = 1e-12;
  opt.backend = BaBackend::kSchurLM;
  const BaResult a = bundle_adjust(cam, scene.problem, opt);
  opt.backend = BaBackend::kCeres;
  const BaResult b = bundle_adjust(cam, scene.problem, opt);
  ASSERT_TRUE(a.usable && b.usable) << a.message << " / " << b.message;
  std::printf("cost %.9g -> %.9g (Schur LM), %.9g -> %.9g (Ceres)\n", a.initial_cost,
              a.final_cost, b.initial_cost, b.final_cost);
  EXPECT_NEAR(a.initial_cost, b.initial_cost, 1e-9 * b.initial_cost);
  EXPECT_NEAR(a.final_cost, b.final_cost, 1e-6 * b.final_cost);
  double pose_diff = 0.0, point_diff = 0.0;
  for (std::size_t k = 0; k < a.poses.size(); ++k) {
    pose_diff = std::max(pose_diff, test::centre_error(a.poses[k], b.poses[k]));
  }
  for (std::size_t i = 0; i < a.points.size(); ++i) {
    point_diff = std::max(point_diff, (a.points[i] - b.points[i]).norm());
  }
  EXPECT_LT(pose_diff, 1e-6);
  EXPECT_LT(point_diff, 1e-4);
  EXPECT_EQ(a.point_observation_outlier, b.point_observation_outlier);
  EXPECT_EQ(a.line_observation_outlier, b.line_observation_outlier);
}

TEST(BundleAdjustment, LineEndpointsMoveOnlyAcrossTheLine) {
  // Along its 3D line an endpoint is unobservable: with noisy observed lines both endpoints used
  // to drift onto the one point that fits the planes best, and segments collapsed to length 0.
  const auto cam = test::kitti_like_camera();
  std::mt19937 rng(8);
  auto scene = test::make_ba_scene(cam, 8, 200, 60, rng);
  scene.problem.keyframes[0].fixed = true;
  std::normal_distribution<double> noise(0.0, 1.0);
  for (auto& o : scene.problem.line_observations) {
    o.left_line(2) += noise(rng);
    o.right_line(2) += noise(rng);
  }
  test::perturb(&scene.problem, 0.02, 0.005, 0.02, rng);
  for (const auto backend : {BaBackend::kSchurLM, BaBackend::kCeres}) {
    BaOptions opt;
    opt.iterations = 50;
    opt.function_tolerance = 1e-12;
    opt.backend = backend;
    const BaResult r = bundle_adjust(cam, scene.problem, opt);
    ASSERT_TRUE(r.usable) << r.message;
    for (std::size_t l = 0; l < r.lines.size(); ++l) {
      const auto& in = scene.problem.lines[l];
      const Eigen::Vector3d d = (in.end - in.start).normalized();
      EXPECT_NEAR(d.dot(r.lines[l].start - in.start), 0.0, 1e-6) << "line " << l;
      EXPECT_NEAR(d.dot(r.lines[l].end - in.end), 0.0, 1e-6) << "line " << l;
      EXPECT_GT((r.lines[l].end - r.lines[l].start).norm(), 0.9 * (in.end - in.start).norm()) << "line " << l;
    }
  }
}

// Threads only split the sums: the result matches the single-thread one to rounding.
TEST(BundleAdjustment, SchurLmThreadsGiveTheSameResult) {
  const auto cam = test::kitti_like_camera();
  std::mt19937 rng(7);
  auto scene = test::make_ba_scene(cam, 10, 600, 80, rng);
  scene.problem.keyframes[0].fixed = true;
  test::perturb(&scene.problem, 0.03, 0.005, 0.03, rng);
  BaOptions opt;
  opt.iterations = 5;
  const BaResult one = bundle_adjust(cam, scene.problem, opt);
  opt.num_threads = 2;
  const BaResult two = bundle_adjust(cam, scene.problem, opt);
  EXPECT_EQ(one.iterations, two.iterations);
  EXPECT_NEAR(one.final_cost, two.final_cost, 1e-9 * one.initial_cost);
  for (std::size_t k = 0; k < one.poses.size(); ++k) {
    EXPECT_LT(test::centre_error(one.poses[k], two.poses[k]), 1e-9);
  }
}

// A landmark behind one of its cameras at the start: Ceres cannot evaluate the problem, the
// Schur LM backend drops that observation from the pass and flags it.
TEST(BundleAdjustment, SchurLmDropsObservationsBehindTheCamera) {
  const auto cam = test::kitti_like_camera();
  std::mt19937 rng(8);
  auto scene = test::make_ba_scene(cam, 6, 300, 40, rng);
  scene.problem.keyframes[0].fixed = true;
  // A fixed keyframe turned around (180 degrees about its y axis) with a bogus observation of
  // the first observation's point, which is therefore behind it.
  BaKeyframe behind{geometry::SE3::exp((geometry::Vector6d() << 0, 0, 0, 0, M_PI, 0).finished()) *
                        scene.poses_true[0],
                    true};
  scene.problem.keyframes.push_back(behind);
  StereoPointObservation bogus = scene.problem.point_observations[0];
  bogus.keyframe = static_cast<int>(scene.problem.keyframes.size()) - 1;
  scene.problem.point_observations.push_back(bogus);
  scene.poses_true.push_back(behind.T_cw);
  test::perturb(&scene.problem, 0.02, 0.005, 0.02, rng);
  BaOptions opt;
  opt.iterations = 20;
  const BaResult r = bundle_adjust(cam, scene.problem, opt);
  ASSERT_TRUE(r.usable) << r.message;
  EXPECT_NE(r.message.find("1 observations dropped"), std::string::npos) << r.message;
  EXPECT_TRUE(r.point_observation_outlier.back());
  EXPECT_EQ(std::count(r.point_observation_outlier.begin(), r.point_observation_outlier.end(), true), 1);
  EXPECT_LT(errors(scene, r).pose_trans, 1e-3);
}

}  // namespace
}  // namespace plslam::optim
