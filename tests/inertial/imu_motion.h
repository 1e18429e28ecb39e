#pragma once
// A smooth body motion in closed form, for testing the IMU code against ground truth: position
// and ZYX Euler angles are sums of sinusoids, and the gyro's angular rate and the accelerometer's
// specific force follow from their derivatives, derived by hand here (not from the code under
// test). Shared by tests/inertial and bench/inertial.cpp; no GoogleTest in here.
#include <array>
#include <cmath>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "plslam/core/imu.h"
#include "plslam/inertial/imu_bias.h"

namespace plslam::inertial::test {

// offset + sum of amplitude * sin(omega t + phase), with its first two derivatives.
struct Sinusoids {
  double offset = 0.0;
  std::array<double, 2> amplitude{}, omega{}, phase{};

  double value(double t) const {
    double s = offset;
    for (size_t k = 0; k < 2; ++k) s += amplitude[k] * std::sin(omega[k] * t + phase[k]);
    return s;
  }
  double rate(double t) const {
    double s = 0.0;
    for (size_t k = 0; k < 2; ++k) s += amplitude[k] * omega[k] * std::cos(omega[k] * t + phase[k]);
    return s;
  }
  double acceleration(double t) const {
    double s = 0.0;
    for (size_t k = 0; k < 2; ++k) {
      s -= amplitude[k] * omega[k] * omega[k] * std::sin(omega[k] * t + phase[k]);
    }
    return s;
  }
};

struct BodyState {
  Eigen::Matrix3d R;     // body to world
  Eigen::Vector3d p, v;  // world
  Eigen::Vector3d gyro;  // angular rate of the body, in the body frame
  Eigen::Vector3d acc;   // specific force R' (a - g), in the body frame
};

// A hand-held-like motion: ~1 m and ~0.5 rad swings at 0.3-1.3 Hz, up to ~2 rad/s and ~15 m/s^2.
class SinusoidMotion {
 public:
  SinusoidMotion() {
    position_[0] = {0.5, {0.8, 0.15}, {3.1, 7.3}, {0.2, 1.1}};
    position_[1] = {-0.3, {0.6, 0.1}, {2.3, 8.1}, {1.4, 0.3}};
    position_[2] = {1.2, {0.3, 0.05}, {4.7, 6.2}, {0.7, 2.2}};
    yaw_ = {0.4, {0.7, 0.1}, {1.9, 6.7}, {0.1, 0.9}};
    pitch_ = {0.1, {0.35, 0.06}, {2.9, 7.9}, {1.3, 0.4}};
    roll_ = {-0.2, {0.4, 0.08}, {3.7, 5.3}, {0.6, 2.5}};
  }

  BodyState at(double t) const {
    const double yaw = yaw_.value(t), pitch = pitch_.value(t), roll = roll_.value(t);
    const Eigen::Matrix3d Rz = Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    const Eigen::Matrix3d Ry =
        Eigen::AngleAxisd(pitch, Eigen::Vector3d::UnitY()).toRotationMatrix();
    const Eigen::Matrix3d Rx = Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitX()).toRotationMatrix();
    BodyState s;
    s.R = Rz * Ry * Rx;
    Eigen::Vector3d a;
    for (int c = 0; c < 3; ++c) {
      s.p(c) = position_[c].value(t);
      s.v(c) = position_[c].rate(t);
      a(c) = position_[c].acceleration(t);
    }
    // R' dR/dt = [w]x with R = Rz Ry Rx, dR/dt = Rz [yaw' e_z]x Ry Rx + Rz Ry [pitch' e_y]x Rx
    // + Rz Ry Rx [roll' e_x]x; since Q' [u]x Q = [Q' u]x:
    //   w = roll' e_x + Rx' pitch' e_y + Rx' Ry' yaw' e_z.
    s.gyro = roll_.rate(t) * Eigen::Vector3d::UnitX() +
             Rx.transpose() * (pitch_.rate(t) * Eigen::Vector3d::UnitY() +
                               Ry.transpose() * (yaw_.rate(t) * Eigen::Vector3d::UnitZ()));
    // Gravity is (0, 0, -kGravity), so a - g = a + kGravity e_z.
    s.acc = s.R.transpose() * (a + kGravity * Eigen::Vector3d::UnitZ());
    return s;
  }

 private:
  std::array<Sinusoids, 3> position_;
  Sinusoids yaw_, pitch_, roll_;
};

// Noise-free readings t_first + k dt up to and including the first at or after t_last, offset by
// `bias`.
inline std::vector<ImuSample> sample_motion(const SinusoidMotion& motion, double t_first,
                                            double t_last, double dt, const ImuBias& bias = {}) {
  std::vector<ImuSample> out;
  for (int k = 0;; ++k) {
    const double t = t_first + k * dt;
    const BodyState s = motion.at(t);
    out.push_back({t, s.gyro + bias.gyro, s.acc + bias.acc});
    if (t >= t_last) break;
  }
  return out;
}

// The deltas that preintegration over [t_i, t_j] must reproduce, from the states alone.
struct TrueDeltas {
  Eigen::Matrix3d R;
  Eigen::Vector3d v, p;
};

inline TrueDeltas true_deltas(const SinusoidMotion& motion, double t_i, double t_j) {
  const BodyState i = motion.at(t_i);
  const BodyState j = motion.at(t_j);
  const double dt = t_j - t_i;
  const Eigen::Vector3d g(0.0, 0.0, -kGravity);
  const Eigen::Matrix3d Rit = i.R.transpose();
  return {Rit * j.R, Rit * (j.v - i.v - g * dt), Rit * (j.p - i.p - i.v * dt - 0.5 * g * dt * dt)};
}

}  // namespace plslam::inertial::test
