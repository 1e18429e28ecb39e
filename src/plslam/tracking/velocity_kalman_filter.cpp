#include "plslam/tracking/velocity_kalman_filter.h"

#include <Eigen/Dense>

namespace plslam::tracking {

VelocityKalmanFilter::VelocityKalmanFilter(VelocityKalmanOptions options) : options_(options) {
  x_.setZero();
  P_.setZero();
  P_.bottomRightCorner<3, 3>().diagonal().setConstant(options_.initial_velocity_std * options_.initial_velocity_std);
}

void VelocityKalmanFilter::reset_reference() {
  x_.head<3>().setZero();
  P_.topRows<3>().setZero();
  P_.leftCols<3>().setZero();
}

void VelocityKalmanFilter::rotate(const Eigen::Matrix3d& R_new_old) {
  Eigen::Matrix<double, 6, 6> R = Eigen::Matrix<double, 6, 6>::Zero();
  R.topLeftCorner<3, 3>() = R_new_old;
  R.bottomRightCorner<3, 3>() = R_new_old;
  x_ = (R * x_).eval();
  P_ = (R * P_ * R.transpose()).eval();
}

void VelocityKalmanFilter::update(double dt, const Eigen::Vector3d& displacement) {
  if (dt > 0) {
    // x' = F x with F = [I dt·I; 0 I]; Q from white acceleration: [dt^3/3 dt^2/2; dt^2/2 dt]·q.
    Eigen::Matrix<double, 6, 6> F = Eigen::Matrix<double, 6, 6>::Identity();
    F.topRightCorner<3, 3>().diagonal().setConstant(dt);
    const double q = options_.accel_noise * options_.accel_noise;
    Eigen::Matrix<double, 6, 6> Q = Eigen::Matrix<double, 6, 6>::Zero();
    Q.topLeftCorner<3, 3>().diagonal().setConstant(q * dt * dt * dt / 3.0);
    Q.topRightCorner<3, 3>().diagonal().setConstant(q * dt * dt / 2.0);
    Q.bottomLeftCorner<3, 3>().diagonal().setConstant(q * dt * dt / 2.0);
    Q.bottomRightCorner<3, 3>().diagonal().setConstant(q * dt);
    x_ = F * x_;
    P_ = F * P_ * F.transpose() + Q;
  }
  // H = [I 0]: the displacement is measured directly.
  const Eigen::Matrix3d R = Eigen::Matrix3d::Identity() * options_.position_noise * options_.position_noise;
  const Eigen::Matrix3d S = P_.topLeftCorner<3, 3>() + R;
  const Eigen::Matrix<double, 6, 3> K = P_.leftCols<3>() * S.inverse();
  x_ += K * (displacement - x_.head<3>());
  // Joseph form keeps P symmetric positive semi-definite.
  Eigen::Matrix<double, 6, 6> IKH = Eigen::Matrix<double, 6, 6>::Identity();
  IKH.leftCols<3>() -= K;
  P_ = IKH * P_ * IKH.transpose() + K * R * K.transpose();
}

}  // namespace plslam::tracking
