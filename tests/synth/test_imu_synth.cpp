// The synthetic IMU: the camera path is smooth to second order, its analytic derivatives are the
// derivatives of its poses, dead-reckoning the noise-free samples reproduces the ground truth, and
// the noise, biases and clock offset follow the options.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "plslam/inertial/strapdown.h"
#include "plslam/synth/imu_synth.h"
#include "plslam/synth/writer.h"

namespace plslam::synth {
namespace {

constexpr MotionProfile kProfiles[] = {MotionProfile::kWalk, MotionProfile::kHandheld, MotionProfile::kDrone};

// 12.95 s of the office at its nominal speed (the test's 10 s start 2 s in).
SequenceOptions office(MotionProfile motion, int frames = 260, std::uint64_t seed = 1) {
  SequenceOptions o;
  o.scene = SceneKind::kOffice;
  o.preset = euroc_preset();
  o.frames = frames;
  o.seed = seed;
  o.motion = motion;
  return o;
}

Eigen::Vector3d vee(const Eigen::Matrix3d& W) { return 0.5 * Eigen::Vector3d(W(2, 1) - W(1, 2), W(0, 2) - W(2, 0), W(1, 0) - W(0, 1)); }

TEST(SynthImu, KinematicsAreTheDerivativesOfThePoses) {
  for (const MotionProfile m : kProfiles) {
    const Sequence seq(office(m));
    double worst_v = 0, worst_a = 0, worst_w = 0;
    for (double t = 0.13; t < 12.9; t += 0.37) {
      const CameraKinematics k = seq.path().kinematics(t);
      EXPECT_LE((k.T_wc.matrix() - seq.path().pose(t).matrix()).cwiseAbs().maxCoeff(), 1e-12);
      const double h = 1e-4, h2 = 2e-3;
      const Eigen::Isometry3d a = seq.path().pose(t - h), b = seq.path().pose(t + h);
      const Eigen::Vector3d v = (b.translation() - a.translation()) / (2 * h);
      const Eigen::Vector3d acc = (seq.path().pose(t + h2).translation() - 2 * k.T_wc.translation() +
                                   seq.path().pose(t - h2).translation()) / (h2 * h2);
      const Eigen::Matrix3d R_dot = (b.linear() - a.linear()) / (2 * h);
      worst_v = std::max(worst_v, (v - k.velocity).norm());
      worst_a = std::max(worst_a, (acc - k.acceleration).norm());
      worst_w = std::max(worst_w, (vee(k.T_wc.linear().transpose() * R_dot) - vee(k.T_wc.linear().transpose() * k.R_dot)).norm());
    }
    std::printf("%s: analytic vs central differences: velocity %.2e m/s, acceleration %.2e m/s^2, rate %.2e rad/s\n",
                to_string(m), worst_v, worst_a, worst_w);
    EXPECT_LT(worst_v, 1e-5) << to_string(m);
    EXPECT_LT(worst_a, 0.05) << to_string(m);
    EXPECT_LT(worst_w, 1e-5) << to_string(m);
  }
}

// A jump in acceleration or angular velocity (a path pieced together from straight chords, or a
// turn that starts abruptly) shows as a huge change between neighbouring instants.
TEST(SynthImu, MotionIsSmoothToSecondOrderAndProfilesAreAsFastAsSaid) {
  for (const MotionProfile m : kProfiles) {
    const Sequence seq(office(m));
    const Eigen::Isometry3d T_bc = euroc_T_BS_cam0();
    const SyntheticImu imu(seq, T_bc, {}, 1);
    const double dt = 2e-4;
    ImuSample prev = imu.ideal(0);
    double jerk = 0, angular_acc = 0, max_rate = 0, max_acc = 0;
    for (double t = dt; t < seq.time(seq.size() - 1); t += dt) {
      const ImuSample s = imu.ideal(t);
      jerk = std::max(jerk, (s.acc - prev.acc).norm() / dt);
      angular_acc = std::max(angular_acc, (s.gyro - prev.gyro).norm() / dt);
      max_rate = std::max(max_rate, s.gyro.norm());
      max_acc = std::max(max_acc, seq.path().kinematics(t).acceleration.norm());
      prev = s;
    }
    std::printf("%s: max rate %.2f rad/s, max acceleration %.2f m/s^2 (camera), max jerk %.0f m/s^3, max angular "
                "acceleration %.0f rad/s^2\n", to_string(m), max_rate, max_acc, jerk, angular_acc);
    EXPECT_LT(jerk, 3000) << to_string(m);
    EXPECT_LT(angular_acc, 300) << to_string(m);
    if (m == MotionProfile::kWalk) {
      EXPECT_LT(max_rate, 1.5);
      EXPECT_LT(max_acc, 4.0);
    } else {
      EXPECT_GT(max_rate, 2.5) << to_string(m);
      EXPECT_LE(max_rate, 3.1) << to_string(m);
      EXPECT_GT(max_acc, 7.0) << to_string(m);
      EXPECT_LE(max_acc, 12.0) << to_string(m);
    }
  }
}

// Dead reckoning from the true state with the noise-free samples (fourth-order Runge-Kutta over
// pairs of sample intervals, inertial/strapdown.h) stays on the ground truth for 10 s.
TEST(SynthImu, DeadReckoningTheExactSamplesReproducesTheGroundTruth) {
  for (const MotionProfile m : kProfiles) {
    const Sequence seq(office(m));
    for (const double rate : {200.0, 1000.0}) {
      ImuSynthOptions o;
      o.rate_hz = rate;
      const SyntheticImu imu(seq, euroc_T_BS_cam0(), o, 1);
      const auto& s = imu.samples();
      std::size_t first = 0;
      while (s[first].t < 2.0 - 1e-9) ++first;  // start 2 s in, end 10 s later
      const std::size_t last = first + static_cast<std::size_t>(std::llround(10 * rate));
      const ImuTrueState a = imu.true_state(s[first].t), b = imu.true_state(s[last].t);
      inertial::NavState n{a.T_wb.linear(), a.v_wb, a.T_wb.translation()};
      n = inertial::integrate_strapdown(n, s, first, last);
      const double dp = (n.p - b.T_wb.translation()).norm();
      const double dr = Eigen::AngleAxisd(n.R.transpose() * b.T_wb.linear()).angle();
      std::printf("%s at %.0f Hz: after 10 s, position error %.3g m, velocity %.3g m/s, rotation %.3g rad\n",
                  to_string(m), rate, dp, (n.v - b.v_wb).norm(), dr);
      EXPECT_LT(dp, rate < 500 ? 0.01 : 0.001) << to_string(m) << " at " << rate << " Hz";
    }
  }
}

TEST(SynthImu, NoiseBiasesAndClockOffsetFollowTheOptions) {
  const Sequence seq(office(MotionProfile::kHandheld, 260, 2));
  ImuSynthOptions o;
  o.noise_scale = 1;
  o.time_offset = 0.013;
  const SyntheticImu imu(seq, euroc_T_BS_cam0(), o, 7);
  EXPECT_GT(imu.initial_gyro_bias().norm(), 1e-3);
  EXPECT_GT(imu.initial_acc_bias().norm(), 1e-2);
  const double dt = 1 / o.rate_hz;
  // Measurement - ideal - true bias is the white noise: its spread is density / sqrt(dt).
  double sg = 0, sa = 0, drift_g = 0;
  const auto& s = imu.samples();
  for (const ImuSample& x : s) {
    const ImuSample ideal = imu.ideal(x.t + o.time_offset);  // the IMU's clock reads sequence time - offset
    const ImuTrueState st = imu.true_state(x.t + o.time_offset);
    sg += (x.gyro - ideal.gyro - st.bg).squaredNorm();
    sa += (x.acc - ideal.acc - st.ba).squaredNorm();
  }
  sg = std::sqrt(sg / (3.0 * static_cast<double>(s.size())));
  sa = std::sqrt(sa / (3.0 * static_cast<double>(s.size())));
  const ImuNoise n = kEurocAdis16448Noise;
  std::printf("white noise: gyro %.4g (expected %.4g), acc %.4g (expected %.4g); %zu samples\n", sg,
              n.gyro_noise_density / std::sqrt(dt), sa, n.acc_noise_density / std::sqrt(dt), s.size());
  EXPECT_NEAR(sg, n.gyro_noise_density / std::sqrt(dt), 0.05 * n.gyro_noise_density / std::sqrt(dt));
  EXPECT_NEAR(sa, n.acc_noise_density / std::sqrt(dt), 0.05 * n.acc_noise_density / std::sqrt(dt));
  // The biases wander as random walks: over 13 s, about density * sqrt(13 s) per axis.
  drift_g = (imu.true_state(seq.time(seq.size() - 1)).bg - imu.true_state(0).bg).norm();
  EXPECT_GT(drift_g, 0);
  EXPECT_LT(drift_g, 5 * n.gyro_random_walk * std::sqrt(13.0 * 3.0));
  EXPECT_EQ(imu.true_state(s.front().t + o.time_offset).bg, imu.initial_gyro_bias());  // at the first sample
  // The samples cover the images with their margin, on the IMU's clock.
  EXPECT_LE(s.front().t + o.time_offset, -0.5 + 1e-9);
  EXPECT_GE(s.back().t + o.time_offset, seq.time(seq.size() - 1) + 0.5 - 1e-9);

  EXPECT_EQ(parse_imu_noise("none"), 0);
  EXPECT_EQ(parse_imu_noise("euroc"), 1);
  EXPECT_EQ(parse_imu_noise("2.5"), 2.5);
  EXPECT_THROW(parse_imu_noise("-1"), InputError);
  EXPECT_THROW(parse_imu_noise("loud"), InputError);
}

}  // namespace
}  // namespace plslam::synth
