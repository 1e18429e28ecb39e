// Visual-inertial initialisation on rendered motion with EuRoC's IMU noise and non-zero biases:
// keyframe poses from the ground truth with a tracker's errors added, gravity and biases compared
// with the truth; and the refusal when nothing rotates.
#include <gtest/gtest.h>

#include <cstdio>

#include "plslam/inertial/vi_initializer.h"
#include "plslam/synth/imu_synth.h"
#include "plslam/synth/texture.h"
#include "plslam/synth/writer.h"

namespace plslam::inertial {
namespace {

using synth::MotionProfile;

struct Case {
  ViInitResult result;
  Eigen::Vector3d true_gravity, true_bg, true_ba;
};

// Keyframes every 0.2 s over `seconds` from 1 s into a handheld office walk; poses perturbed by
// up to 4 mm and 1 mrad, as stereo tracking leaves them.
Case initialise(MotionProfile motion, std::uint64_t seed, double seconds) {
  synth::SequenceOptions o;
  o.scene = synth::SceneKind::kOffice;
  o.frames = 80;
  o.seed = seed;
  o.motion = motion;
  const synth::Sequence seq(o);
  synth::ImuSynthOptions io;
  io.noise_scale = 1;
  const Eigen::Isometry3d T_bc = synth::euroc_T_BS_cam0();
  const synth::SyntheticImu imu(seq, T_bc, io, seed);
  ImuData data;
  data.T_imu_cam = T_bc;
  data.calibration.noise = imu.noise();
  data.samples = imu.samples();
  synth::Rng rng(seed + 100);
  std::vector<ViKeyframe> kfs;
  for (double t = 1.0; t <= 1.0 + seconds + 1e-9; t += 0.2) {
    Eigen::Isometry3d T = seq.path().pose(t);
    const Eigen::Vector3d dr(rng.uniform(-1, 1), rng.uniform(-1, 1), rng.uniform(-1, 1));
    const Eigen::Vector3d dp(rng.uniform(-1, 1), rng.uniform(-1, 1), rng.uniform(-1, 1));
    T.linear() = T.linear() * Eigen::AngleAxisd(1e-3 * dr.norm(), dr.normalized()).toRotationMatrix();
    T.translation() += 0.004 * dp;
    kfs.push_back({t, T});
  }
  Case c;
  c.result = initialize_visual_inertial(kfs, data);
  c.true_gravity = Eigen::Vector3d(0, 0, -1);  // the synthetic world is gravity-aligned
  const synth::ImuTrueState s = imu.true_state(1.0);
  c.true_bg = s.bg;
  c.true_ba = s.ba;
  return c;
}

double angle_deg(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return std::atan2(a.cross(b).norm(), a.dot(b)) * 180 / M_PI;
}

TEST(ViInitializer, FindsGravityAndBiasesWithinTwoSecondsOfMotion) {
  for (const MotionProfile m : {MotionProfile::kWalk, MotionProfile::kHandheld, MotionProfile::kDrone}) {
    for (std::uint64_t seed : {11, 12}) {
      const Case c = initialise(m, seed, 2.0);
      const ViInitResult& r = c.result;
      const double g_err = angle_deg(r.gravity_direction, c.true_gravity);
      const double bg_err = (r.bias.gyro - c.true_bg).norm();
      std::printf("%s seed %lu: %s%s; gravity %.3f deg (sigma %.3f), bg error %.2e of %.2e (sigma %.1e), ba error "
                  "%.3f of %.3f, rotation %.0f deg, rms %.2f, %.1f ms\n",
                  synth::to_string(m), static_cast<unsigned long>(seed), r.accepted ? "accepted" : "refused: ",
                  r.reason.c_str(), g_err, r.gravity_sigma_deg, bg_err, c.true_bg.norm(), r.gyro_bias_sigma.norm(),
                  (r.bias.acc - c.true_ba).norm(), c.true_ba.norm(), r.rotation_deg, r.rms_residual, r.solve_ms);
      ASSERT_TRUE(r.solved);
      if (r.accepted) {
        EXPECT_LT(g_err, 0.5);
        EXPECT_LT(bg_err, std::max(0.1 * c.true_bg.norm(), 2e-4));
      }
    }
  }
}

// Nothing moves: the gyro bias is what the gyro reads, but the accelerometer bias and the tilt of
// gravity cannot be told apart, so the initialisation is refused.
TEST(ViInitializer, RefusesWithoutRotationButReportsTheGyroBias) {
  ImuData data;
  data.calibration.noise = kEurocAdis16448Noise;
  const Eigen::Vector3d bg(0.01, -0.02, 0.03), ba(0.05, -0.08, 0.02);
  const Eigen::Matrix3d R_wb = Eigen::AngleAxisd(0.3, Eigen::Vector3d(1, 2, 0).normalized()).toRotationMatrix();
  synth::Rng rng(5);
  for (int k = 0; k <= 600; ++k) {
    ImuSample s;
    s.t = k * 0.005;
    s.gyro = bg + 1e-4 * Eigen::Vector3d(rng.uniform(-1, 1), rng.uniform(-1, 1), rng.uniform(-1, 1));
    s.acc = R_wb.transpose() * Eigen::Vector3d(0, 0, kGravity) + ba +
            1e-3 * Eigen::Vector3d(rng.uniform(-1, 1), rng.uniform(-1, 1), rng.uniform(-1, 1));
    data.samples.push_back(s);
  }
  std::vector<ViKeyframe> kfs;
  for (int k = 0; k <= 10; ++k) {
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.linear() = R_wb;  // camera = IMU here
    kfs.push_back({0.25 + 0.2 * k, T});
  }
  const ViInitResult r = initialize_visual_inertial(kfs, data);
  std::printf("static: %s; bg error %.2e, gravity sigma %.2f deg\n", r.reason.c_str(), (r.bias.gyro - bg).norm(),
              r.gravity_sigma_deg);
  EXPECT_FALSE(r.accepted);
  ASSERT_TRUE(r.solved);
  EXPECT_NE(r.reason.find("not observable"), std::string::npos) << r.reason;
  EXPECT_LT((r.bias.gyro - bg).norm(), 2e-4);

  const ViInitResult few = initialize_visual_inertial(std::span(kfs).first(3), data);
  EXPECT_FALSE(few.accepted);
  EXPECT_FALSE(few.solved);
}

}  // namespace
}  // namespace plslam::inertial
