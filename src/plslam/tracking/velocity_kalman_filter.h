#pragma once
// Constant-velocity Kalman filter on the camera's displacement from the reference keyframe.
// State x = [d; v] (displacement since the reference keyframe and velocity, metres and m/s, in
// world axes); measurement z = d, the tracked position of the current frame minus the reference
// keyframe's. Its speed |v| is the paper's "velocity between the reference keyframe and the
// current frame": far points make the translation poorly observed per frame, and filtering the
// displacement over several frames gives a speed that can force a keyframe.
#include <Eigen/Core>

namespace plslam::tracking {

struct VelocityKalmanOptions {
  double accel_noise = 5.0;         // m/s^2, white-acceleration process noise (spectral density sqrt)
  double position_noise = 0.02;     // m, standard deviation of a tracked position
  double initial_velocity_std = 10.0;  // m/s, prior on the velocity before any measurement
};

class VelocityKalmanFilter {
 public:
  explicit VelocityKalmanFilter(VelocityKalmanOptions options = {});

  // Starts measuring from a new reference keyframe: the displacement restarts at zero (exactly
  // known), the velocity estimate and its uncertainty carry over.
  void reset_reference();
  // The world's axes turned by R_new_old: the displacement, the velocity and their covariance
  // turn with them.
  void rotate(const Eigen::Matrix3d& R_new_old);
  // Predicts over dt seconds and fuses the measured displacement from the reference keyframe.
  void update(double dt, const Eigen::Vector3d& displacement);

  Eigen::Vector3d velocity() const { return x_.tail<3>(); }
  double speed() const { return x_.tail<3>().norm(); }
  Eigen::Vector3d displacement() const { return x_.head<3>(); }
  const Eigen::Matrix<double, 6, 6>& covariance() const { return P_; }

 private:
  VelocityKalmanOptions options_;
  Eigen::Matrix<double, 6, 1> x_;
  Eigen::Matrix<double, 6, 6> P_;
};

}  // namespace plslam::tracking
