// The IMU as a factor of the bundle adjustment (inertial/imu_ba_factor.h, optim's keyframe factors):
// its Jacobian over both keyframes' camera tangents and extra states against central differences,
// and visual-inertial BAs of keyframes along a smooth body motion with exact IMU samples and
// noise-free stereo points: from perturbed poses, velocities and biases back to the truth; a
// keyframe that sees nothing (a black frame) placed by the IMU alone; a map tilted as a whole
// brought back level with the 4-DoF gauge (GaugePriorFactor); and the problems the backends refuse.
#include <cmath>
#include <memory>
#include <random>
#include <stdexcept>

#include <gtest/gtest.h>

#include "inertial/imu_motion.h"
#include "inertial/numeric_jacobian.h"
#include "plslam/core/error.h"
#include "plslam/inertial/gauge_prior_factor.h"
#include "plslam/inertial/imu_ba_factor.h"
#include "plslam/optim/bundle_adjustment.h"

namespace plslam::inertial {
namespace {

using geometry::SE3;
using geometry::Vector6d;
using optim::Vector9d;

struct Sequence {
  test::SinusoidMotion motion;
  ImuBias true_bias{Eigen::Vector3d(0.004, -0.003, 0.002), Eigen::Vector3d(0.05, -0.08, 0.03)};
  SE3 T_imu_cam{(Eigen::Matrix3d() << 0, 0, 1, -1, 0, 0, 0, -1, 0).finished(), Eigen::Vector3d(0.06, -0.01, 0.02)};
  geometry::StereoCamera cam{450, 450, 376, 240, 0.11 * 450, 752, 480};
  std::vector<double> times;  // of the keyframes
  std::vector<ImuSample> samples;

  explicit Sequence(int keyframes, double spacing = 0.2) {
    for (int k = 0; k < keyframes; ++k) times.push_back(0.4 + spacing * k);
    samples = test::sample_motion(motion, 0.3, times.back() + 0.1, 0.001, true_bias);
  }
  SE3 T_wb(double t) const {
    const auto s = motion.at(t);
    return SE3(s.R, s.p);
  }
  SE3 T_cw(double t) const { return (T_wb(t) * T_imu_cam).inverse(); }
  Vector9d extra(double t) const { return ba_extra_state(motion.at(t).v, true_bias); }
  Preintegration between(std::size_t i, std::size_t j, const ImuBias& linearisation = {}) const {
    return {samples, times[i], times[j], linearisation, kEurocAdis16448Noise};
  }

  // Every keyframe at its true pose and state, 60 true points in view of each (also seen by the
  // others where they project into the image), and an IMU factor between each consecutive pair.
  optim::BaProblem problem(const std::vector<bool>& blind = {}) const {
    optim::BaProblem p;
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> u(-1, 1), depth(2, 8);
    for (std::size_t k = 0; k < times.size(); ++k) {
      p.keyframes.push_back({T_cw(times[k]), false});
      p.keyframe_extra.push_back(extra(times[k]));
    }
    for (std::size_t k = 0; k < times.size(); ++k) {
      if (!blind.empty() && blind[k]) continue;
      for (int n = 0; n < 60; ++n) {
        const double z = depth(rng);
        const Eigen::Vector3d Xc(u(rng) * 300 * z / cam.fx(), u(rng) * 200 * z / cam.fy(), z);
        p.points.push_back({T_cw(times[k]).inverse() * Xc, false});
      }
    }
    for (std::size_t i = 0; i < p.points.size(); ++i) {
      for (std::size_t k = 0; k < times.size(); ++k) {
        if (!blind.empty() && blind[k]) continue;
        const Eigen::Vector3d Xc = p.keyframes[k].T_cw * p.points[i].position;
        if (Xc.z() < 0.5) continue;
        const Eigen::Vector3d m = cam.project_stereo(Xc);
        if (m.x() < 0 || m.x() >= cam.width() || m.y() < 0 || m.y() >= cam.height() || m.z() < 0) continue;
        optim::StereoPointObservation o;
        o.keyframe = static_cast<int>(k);
        o.point = static_cast<int>(i);
        o.measurement = m;
        p.point_observations.push_back(o);
      }
    }
    for (std::size_t k = 1; k < times.size(); ++k) {
      p.keyframe_factors.push_back(
          std::make_shared<ImuBaFactor>(static_cast<int>(k - 1), static_cast<int>(k), between(k - 1, k), T_imu_cam));
    }
    return p;
  }
};

double rotation_error_deg(const SE3& a, const SE3& b) {
  return Eigen::AngleAxisd(a.rotation() * b.rotation().transpose()).angle() * 180 / M_PI;
}
double centre_error(const SE3& a, const SE3& b) { return (a.inverse().translation() - b.inverse().translation()).norm(); }

TEST(ImuBaFactor, JacobianMatchesNumericDifferentiationOverBothKeyframes) {
  const Sequence s(2, 0.1);
  const ImuBaFactor factor(0, 1, s.between(0, 1), s.T_imu_cam);
  // Away from the truth, so that no block's residual is zero.
  std::vector<SE3> T = {
      SE3::exp((Vector6d() << 0.02, -0.01, 0.03, 0.01, -0.02, 0.015).finished()) * s.T_cw(s.times[0]),
      SE3::exp((Vector6d() << -0.01, 0.02, 0.01, -0.015, 0.01, 0.02).finished()) * s.T_cw(s.times[1])};
  std::vector<Vector9d> x = {s.extra(s.times[0]), s.extra(s.times[1])};
  x[0] += (Vector9d() << 0.1, -0.05, 0.02, 0.002, 0.001, -0.003, -0.02, 0.03, 0.01).finished();
  x[1] += (Vector9d() << -0.05, 0.04, 0.1, -0.001, 0.002, 0.001, 0.03, -0.01, 0.02).finished();
  Eigen::MatrixXd J;
  const Eigen::VectorXd r = factor.evaluate(T, x, &J);
  ASSERT_EQ(r.size(), 15);
  ASSERT_EQ(J.rows(), 15);
  ASSERT_EQ(J.cols(), 30);
  const Eigen::MatrixXd numeric = test::central_differences(
      [&](const Eigen::VectorXd& d) -> Eigen::VectorXd {
        const std::vector<SE3> Td = {SE3::exp(d.segment<6>(0)) * T[0], SE3::exp(d.segment<6>(15)) * T[1]};
        const std::vector<Vector9d> xd = {x[0] + d.segment<9>(6), x[1] + d.segment<9>(21)};
        return factor.evaluate(Td, xd, nullptr);
      },
      30, 1e-6);
  // Block by block: pose, velocity, biases of each keyframe (the IMU rows and the walk's).
  for (const int block : {0, 6, 9, 15, 21, 24}) {
    const int cols = block == 6 || block == 21 ? 3 : 6;
    const double err = test::relative_error(J.middleCols(block, cols), numeric.middleCols(block, cols));
    EXPECT_LT(err, 1e-6) << "columns " << block << "..";
  }
}

class VisualInertialBackends : public ::testing::TestWithParam<optim::BaBackend> {};
INSTANTIATE_TEST_SUITE_P(Backends, VisualInertialBackends,
                         ::testing::Values(optim::BaBackend::kSchurLM, optim::BaBackend::kCeres),
                         [](const auto& info) { return info.param == optim::BaBackend::kSchurLM ? "SchurLM" : "Ceres"; });

// Keyframes 0.2 s apart, the first held (pose, velocity, biases) as the keyframe before a local
// window is; every other one starts 3-5 cm and ~1 deg off, 0.2 m/s off, with zero biases.
TEST_P(VisualInertialBackends, ConvergeToTheTrueStatesAndBiases) {
  const Sequence s(8);
  optim::BaProblem p = s.problem();
  p.keyframes[0].fixed = true;
  std::mt19937 rng(3);
  std::normal_distribution<double> g(0, 1);
  for (std::size_t k = 1; k < p.keyframes.size(); ++k) {
    Vector6d d;
    for (int c = 0; c < 3; ++c) d(c) = 0.03 * g(rng);
    for (int c = 3; c < 6; ++c) d(c) = 0.015 * g(rng);
    p.keyframes[k].T_cw = SE3::exp(d) * p.keyframes[k].T_cw;
    p.keyframe_extra[k].head<3>() += 0.12 * Eigen::Vector3d(g(rng), g(rng), g(rng));
    p.keyframe_extra[k].tail<6>().setZero();
  }
  optim::BaOptions options;
  options.backend = GetParam();
  const auto r = optim::local_bundle_adjustment(s.cam, p, options);
  ASSERT_TRUE(r.usable) << r.message;
  ASSERT_EQ(r.keyframe_extra.size(), p.keyframes.size());
  for (std::size_t k = 1; k < p.keyframes.size(); ++k) {
    const SE3 truth = s.T_cw(s.times[k]);
    EXPECT_LT(centre_error(r.poses[k], truth), 1e-5) << "keyframe " << k;
    EXPECT_LT(rotation_error_deg(r.poses[k], truth), 1e-4) << "keyframe " << k;
    EXPECT_LT((velocity_of(r.keyframe_extra[k]) - s.motion.at(s.times[k]).v).norm(), 1e-4) << "keyframe " << k;
    const ImuBias b = bias_of(r.keyframe_extra[k]);
    EXPECT_LT((b.gyro - s.true_bias.gyro).norm(), 1e-4) << "keyframe " << k;
    EXPECT_LT((b.acc - s.true_bias.acc).norm(), 5e-3) << "keyframe " << k;
  }
  // The fixed keyframe's state is returned as it was.
  EXPECT_EQ(r.keyframe_extra[0], p.keyframe_extra[0]);
  // The truth's own cost is not zero: the deltas, integrated at zero bias, are corrected for the
  // true one to first order only. The minimum found is at most that.
  optim::BaProblem at_truth = s.problem();
  for (auto& kf : at_truth.keyframes) kf.fixed = true;
  const double truth_cost = optim::bundle_adjust(s.cam, at_truth, {}).initial_cost;
  EXPECT_GT(r.initial_cost, 1e3 * truth_cost);
  EXPECT_LE(r.final_cost, truth_cost * (1 + 1e-9));
}

// A keyframe with no observation at all (a black frame) between two that see: vision alone
// leaves it anywhere, the IMU factors to both neighbours place it.
TEST(VisualInertialBundleAdjustment, ImuPlacesAKeyframeThatSeesNothing) {
  const Sequence s(5);
  std::vector<bool> blind(5, false);
  blind[2] = true;
  optim::BaProblem p = s.problem(blind);
  p.keyframes[0].fixed = true;
  p.keyframes[2].T_cw = SE3::exp((Vector6d() << 0.2, -0.1, 0.15, 0.05, 0.03, -0.04).finished()) * p.keyframes[2].T_cw;
  p.keyframe_extra[2].head<3>() += Eigen::Vector3d(0.3, -0.2, 0.1);
  const auto r = optim::local_bundle_adjustment(s.cam, p, {});
  ASSERT_TRUE(r.usable) << r.message;
  const SE3 truth = s.T_cw(s.times[2]);
  EXPECT_LT(centre_error(r.poses[2], truth), 1e-5);
  EXPECT_LT(rotation_error_deg(r.poses[2], truth), 1e-4);
  EXPECT_LT((velocity_of(r.keyframe_extra[2]) - s.motion.at(s.times[2]).v).norm(), 1e-4);

  // Without its IMU factors the same keyframe has nothing to move it: it stays where it started.
  optim::BaProblem vision = p;
  vision.keyframe_factors.clear();
  vision.keyframe_extra.clear();
  const auto rv = optim::local_bundle_adjustment(s.cam, vision, {});
  EXPECT_GT(centre_error(rv.poses[2], truth), 0.1);
}

TEST(GaugePriorFactor, JacobianMatchesNumericDifferentiation) {
  const Sequence s(1);
  const SE3 held = s.T_cw(s.times[0]);
  const GaugePriorFactor factor(0, held);
  // Away from the held pose, so that the heading's Jacobian is not at delta = 0.
  const std::vector<SE3> T = {SE3::exp((Vector6d() << 0.02, -0.01, 0.03, 0.05, -0.04, 0.06).finished()) * held};
  const std::vector<Vector9d> x = {s.extra(s.times[0])};
  Eigen::MatrixXd J;
  const Eigen::VectorXd r = factor.evaluate(T, x, &J);
  ASSERT_EQ(r.size(), 4);
  ASSERT_EQ(J.rows(), 4);
  ASSERT_EQ(J.cols(), 15);
  EXPECT_GT(r.norm(), 1e3);
  const Eigen::MatrixXd numeric = test::central_differences(
      [&](const Eigen::VectorXd& d) -> Eigen::VectorXd {
        const std::vector<SE3> Td = {SE3::exp(d.head<6>()) * T[0]};
        const std::vector<Vector9d> xd = {x[0] + d.tail<9>()};
        return factor.evaluate(Td, xd, nullptr);
      },
      15, 1e-7);
  EXPECT_LT(test::relative_error(J, numeric), 1e-6);
  EXPECT_EQ(J.rightCols<9>().norm(), 0.0);
  // At the held pose: zero, and turning it about world x or y (roll, pitch) costs nothing to first order.
  EXPECT_LT(factor.evaluate(std::vector<SE3>{held}, x, nullptr).norm(), 1e-9);
  const Eigen::Matrix3d R_wc = held.inverse().rotation();
  for (const Eigen::Vector3d axis : {Eigen::Vector3d::UnitX(), Eigen::Vector3d::UnitY()}) {
    // A world-frame turn w of the camera about its centre is phi = -R_cw w, rho = 0 on T_cw.
    Eigen::MatrixXd J0;
    factor.evaluate(std::vector<SE3>{held}, x, &J0);
    EXPECT_LT((J0.middleCols<3>(3) * (-R_wc.transpose() * axis)).norm(), 1e-9);
  }
}

// The whole map turned by 0.5 deg of roll and pitch about the first keyframe's centre: vision alone
// cannot tell, gravity in the IMU factors can. Holding the first keyframe's whole pose keeps the
// tilt (the IMU factors fight it); the 4-DoF gauge lets the BA bring the map back level, with the
// first keyframe's centre and heading where they were.
TEST_P(VisualInertialBackends, FourDofGaugeLevelsATiltedMap) {
  const Sequence s(8);
  const optim::BaProblem truth = s.problem();
  const Eigen::Vector3d centre = truth.keyframes[0].T_cw.inverse().translation();
  const Eigen::Matrix3d tilt = geometry::so3_exp(Eigen::Vector3d(0.5, -0.4, 0.0) * M_PI / 180);
  const SE3 W = SE3(Eigen::Matrix3d::Identity(), centre) * SE3(tilt, Eigen::Vector3d::Zero()) *
                SE3(Eigen::Matrix3d::Identity(), -centre);  // x -> tilt (x - centre) + centre
  optim::BaProblem tilted = truth;
  for (auto& kf : tilted.keyframes) kf.T_cw = kf.T_cw * W.inverse();
  for (auto& pt : tilted.points) pt.position = W * pt.position;
  for (auto& x : tilted.keyframe_extra) x.head<3>() = tilt * x.head<3>();
  optim::BaOptions options;
  options.backend = GetParam();

  optim::BaProblem held = tilted;
  held.keyframes[0].fixed = true;
  const auto rh = optim::bundle_adjust(s.cam, held, options);
  ASSERT_TRUE(rh.usable) << rh.message;
  EXPECT_GT(rotation_error_deg(rh.poses[7], truth.keyframes[7].T_cw), 0.3);

  optim::BaProblem gauge = tilted;
  gauge.keyframe_factors.push_back(std::make_shared<GaugePriorFactor>(0, tilted.keyframes[0].T_cw));
  const auto r = optim::bundle_adjust(s.cam, gauge, options);
  ASSERT_TRUE(r.usable) << r.message;
  // Back to the truth but for ~0.0007 deg of tilt: over 1.4 s of motion, a tilt that small is hardly
  // told from an accelerometer bias, and the deltas' bias correction is first order only.
  for (std::size_t k = 0; k < truth.keyframes.size(); ++k) {
    EXPECT_LT(centre_error(r.poses[k], truth.keyframes[k].T_cw), 5e-5) << "keyframe " << k;
    EXPECT_LT(rotation_error_deg(r.poses[k], truth.keyframes[k].T_cw), 2e-3) << "keyframe " << k;
    EXPECT_LT((velocity_of(r.keyframe_extra[k]) - velocity_of(truth.keyframe_extra[k])).norm(), 1e-3) << "keyframe " << k;
  }
  // The first keyframe's centre and heading stay where they were held.
  EXPECT_LT(centre_error(r.poses[0], tilted.keyframes[0].T_cw), 1e-6);
  EXPECT_LT(r.final_cost, 1e-3 * rh.final_cost);
}

TEST(VisualInertialBundleAdjustment, BadFactorsAreInputErrors) {
  const Sequence s(3);
  optim::BaProblem p = s.problem();
  p.keyframes[0].fixed = true;
  optim::BaProblem no_extra = p;
  no_extra.keyframe_extra.pop_back();
  EXPECT_THROW(optim::bundle_adjust(s.cam, no_extra, {}), InputError);
  optim::BaProblem bad_index = p;
  bad_index.keyframe_factors.push_back(std::make_shared<ImuBaFactor>(1, 7, s.between(1, 2), s.T_imu_cam));
  EXPECT_THROW(optim::bundle_adjust(s.cam, bad_index, {}), InputError);
}

}  // namespace
}  // namespace plslam::inertial
