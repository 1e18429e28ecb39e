#pragma once
// SO(3)/SE(3) on Eigen. Tangent vectors of SE(3) are ordered xi = [rho; phi] (translation part
// first, rotation second), and all optimisers perturb poses on the LEFT: T <- exp(delta) * T.
// Every function is safe near zero rotation (Taylor branches) and near pi (quaternion-based log).
#include <array>

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace plslam::geometry {

using Vector6d = Eigen::Matrix<double, 6, 1>;
using Matrix6d = Eigen::Matrix<double, 6, 6>;

// Skew-symmetric matrix: hat(a) * b == a.cross(b).
Eigen::Matrix3d hat(const Eigen::Vector3d& v);

Eigen::Matrix3d so3_exp(const Eigen::Vector3d& phi);
// Rotation vector with angle in [0, pi]; R must be a rotation matrix.
Eigen::Vector3d so3_log(const Eigen::Matrix3d& R);
// Left Jacobian of SO(3): exp(phi + d) ~= exp(J_l(phi) d) exp(phi).
Eigen::Matrix3d so3_left_jacobian(const Eigen::Vector3d& phi);
Eigen::Matrix3d so3_left_jacobian_inverse(const Eigen::Vector3d& phi);

class SE3 {
 public:
  SE3() : R_(Eigen::Matrix3d::Identity()), t_(Eigen::Vector3d::Zero()) {}
  SE3(const Eigen::Matrix3d& R, const Eigen::Vector3d& t) : R_(R), t_(t) {}
  SE3(const Eigen::Quaterniond& q, const Eigen::Vector3d& t)
      : R_(q.normalized().toRotationMatrix()), t_(t) {}
  explicit SE3(const Eigen::Isometry3d& T) : R_(T.linear()), t_(T.translation()) {}

  static SE3 exp(const Vector6d& xi);
  Vector6d log() const;
  // 4x4 homogeneous matrix; the rotation block is re-orthonormalised.
  static SE3 from_matrix(const Eigen::Matrix4d& M);

  SE3 operator*(const SE3& o) const { return SE3(R_ * o.R_, R_ * o.t_ + t_); }
  Eigen::Vector3d operator*(const Eigen::Vector3d& p) const { return R_ * p + t_; }
  SE3 inverse() const {
    const Eigen::Matrix3d Rt = R_.transpose();
    return SE3(Rt, -(Rt * t_));
  }
  // Ad(T) with exp(Ad(T) xi) == T exp(xi) T^-1.
  Matrix6d adjoint() const;

  const Eigen::Matrix3d& rotation() const { return R_; }
  const Eigen::Vector3d& translation() const { return t_; }
  Eigen::Quaterniond quaternion() const { return Eigen::Quaterniond(R_).normalized(); }
  // The same pose with its rotation projected back onto SO(3). Products of rotations drift off
  // SO(3) by rounding; where poses are composed over and over (a constant-velocity model feeds its
  // own output back), that drift grows geometrically and must be removed.
  SE3 normalized() const { return SE3(quaternion(), t_); }
  Eigen::Matrix4d matrix() const;
  Eigen::Isometry3d isometry() const;

 private:
  Eigen::Matrix3d R_;
  Eigen::Vector3d t_;
};

// A pose as the 7 doubles of a Ceres pose block, [t_x t_y t_z q_x q_y q_z q_w] (optim/'s T_cw
// blocks, inertial/'s T_wb blocks).
using PoseParams = std::array<double, 7>;
PoseParams to_pose_params(const SE3& T);
SE3 from_pose_params(const double* p);

// SE(3) Jacobians (Barfoot's convention, xi = [rho; phi]):
// exp(xi + d) ~= exp(J_l(xi) d) exp(xi) ~= exp(xi) exp(J_r(xi) d), with J_r(xi) = J_l(-xi).
Matrix6d se3_left_jacobian(const Vector6d& xi);
Matrix6d se3_left_jacobian_inverse(const Vector6d& xi);
Matrix6d se3_right_jacobian_inverse(const Vector6d& xi);

}  // namespace plslam::geometry
