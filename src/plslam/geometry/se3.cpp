#include "plslam/geometry/se3.h"

#include <cmath>

namespace plslam::geometry {
namespace {

// Below this angle the closed forms lose digits to cancellation; their Taylor series take over.
constexpr double kSmallAngle = 1e-4;

// Barfoot's Q(rho, phi): the off-diagonal block of the SE(3) left Jacobian.
Eigen::Matrix3d se3_q_block(const Eigen::Vector3d& rho, const Eigen::Vector3d& phi) {
  const double th2 = phi.squaredNorm();
  const double th = std::sqrt(th2);
  const Eigen::Matrix3d P = hat(phi);
  const Eigen::Matrix3d Rh = hat(rho);
  const Eigen::Matrix3d PR = P * Rh;
  const Eigen::Matrix3d RP = Rh * P;
  const Eigen::Matrix3d PRP = PR * P;
  double c1, c2, c3;
  // The c3 numerator cancels to ~th^5, so its series is used well above kSmallAngle.
  if (th < 0.1) {
    const double th4 = th2 * th2;
    c1 = 1.0 / 6.0 - th2 / 120.0 + th4 / 5040.0;
    c2 = 1.0 / 24.0 - th2 / 720.0 + th4 / 40320.0;
    c3 = 1.0 / 120.0 - th2 / 2520.0 + th4 / 120960.0;
  } else {
    const double s = std::sin(th), c = std::cos(th);
    const double th3 = th2 * th, th4 = th2 * th2, th5 = th4 * th;
    c1 = (th - s) / th3;
    c2 = (0.5 * th2 + c - 1.0) / th4;
    c3 = (2.0 * th - 3.0 * s + th * c) / (2.0 * th5);
  }
  return 0.5 * Rh + c1 * (PR + RP + PRP) + c2 * (P * PR + RP * P - 3.0 * PRP) +
         c3 * (PRP * P + P * PRP);
}

}  // namespace

Eigen::Matrix3d hat(const Eigen::Vector3d& v) {
  Eigen::Matrix3d m;
  m << 0.0, -v.z(), v.y(), v.z(), 0.0, -v.x(), -v.y(), v.x(), 0.0;
  return m;
}

Eigen::Matrix3d so3_exp(const Eigen::Vector3d& phi) {
  const double th2 = phi.squaredNorm();
  const double th = std::sqrt(th2);
  const Eigen::Matrix3d P = hat(phi);
  double a, b;  // R = I + a P + b P^2
  if (th < kSmallAngle) {
    a = 1.0 - th2 / 6.0;
    b = 0.5 - th2 / 24.0;
  } else {
    a = std::sin(th) / th;
    b = (1.0 - std::cos(th)) / th2;
  }
  return Eigen::Matrix3d::Identity() + a * P + b * P * P;
}

Eigen::Vector3d so3_log(const Eigen::Matrix3d& R) {
  // The quaternion route stays accurate near pi, where acos((tr - 1) / 2) loses the axis.
  Eigen::Quaterniond q(R);
  q.normalize();
  if (q.w() < 0.0) q.coeffs() = -q.coeffs();
  const Eigen::Vector3d v = q.vec();
  const double n = v.norm();
  const double w = q.w();
  double scale;  // phi = scale * v
  if (n < 1e-8) {
    scale = 2.0 / w * (1.0 - n * n / (3.0 * w * w));
  } else {
    scale = 2.0 * std::atan2(n, w) / n;
  }
  return scale * v;
}

Eigen::Matrix3d so3_left_jacobian(const Eigen::Vector3d& phi) {
  const double th2 = phi.squaredNorm();
  const double th = std::sqrt(th2);
  const Eigen::Matrix3d P = hat(phi);
  double a, b;
  if (th < kSmallAngle) {
    a = 0.5 - th2 / 24.0;
    b = 1.0 / 6.0 - th2 / 120.0;
  } else {
    a = (1.0 - std::cos(th)) / th2;
    b = (th - std::sin(th)) / (th2 * th);
  }
  return Eigen::Matrix3d::Identity() + a * P + b * P * P;
}

Eigen::Matrix3d so3_left_jacobian_inverse(const Eigen::Vector3d& phi) {
  const double th2 = phi.squaredNorm();
  const double th = std::sqrt(th2);
  const Eigen::Matrix3d P = hat(phi);
  double b;  // (1 - (th/2) cot(th/2)) / th^2, finite up to and including th = pi
  if (th < 1e-3) {
    b = 1.0 / 12.0 + th2 / 720.0;
  } else {
    const double half = 0.5 * th;
    b = (1.0 - half * std::cos(half) / std::sin(half)) / th2;
  }
  return Eigen::Matrix3d::Identity() - 0.5 * P + b * P * P;
}

SE3 SE3::exp(const Vector6d& xi) {
  const Eigen::Vector3d rho = xi.head<3>();
  const Eigen::Vector3d phi = xi.tail<3>();
  return SE3(so3_exp(phi), so3_left_jacobian(phi) * rho);
}

Vector6d SE3::log() const {
  Vector6d xi;
  const Eigen::Vector3d phi = so3_log(R_);
  xi.head<3>() = so3_left_jacobian_inverse(phi) * t_;
  xi.tail<3>() = phi;
  return xi;
}

SE3 SE3::from_matrix(const Eigen::Matrix4d& M) {
  const Eigen::Quaterniond q(Eigen::Matrix3d(M.topLeftCorner<3, 3>()));
  return SE3(q, M.topRightCorner<3, 1>());
}

Matrix6d SE3::adjoint() const {
  Matrix6d A;
  A.topLeftCorner<3, 3>() = R_;
  A.topRightCorner<3, 3>() = hat(t_) * R_;
  A.bottomLeftCorner<3, 3>().setZero();
  A.bottomRightCorner<3, 3>() = R_;
  return A;
}

Eigen::Matrix4d SE3::matrix() const {
  Eigen::Matrix4d M = Eigen::Matrix4d::Identity();
  M.topLeftCorner<3, 3>() = R_;
  M.topRightCorner<3, 1>() = t_;
  return M;
}

Eigen::Isometry3d SE3::isometry() const {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = R_;
  T.translation() = t_;
  return T;
}

Matrix6d se3_left_jacobian(const Vector6d& xi) {
  const Eigen::Vector3d rho = xi.head<3>();
  const Eigen::Vector3d phi = xi.tail<3>();
  const Eigen::Matrix3d J = so3_left_jacobian(phi);
  Matrix6d out;
  out.topLeftCorner<3, 3>() = J;
  out.topRightCorner<3, 3>() = se3_q_block(rho, phi);
  out.bottomLeftCorner<3, 3>().setZero();
  out.bottomRightCorner<3, 3>() = J;
  return out;
}

Matrix6d se3_left_jacobian_inverse(const Vector6d& xi) {
  const Eigen::Vector3d rho = xi.head<3>();
  const Eigen::Vector3d phi = xi.tail<3>();
  const Eigen::Matrix3d Ji = so3_left_jacobian_inverse(phi);
  Matrix6d out;
  out.topLeftCorner<3, 3>() = Ji;
  out.topRightCorner<3, 3>() = -Ji * se3_q_block(rho, phi) * Ji;
  out.bottomLeftCorner<3, 3>().setZero();
  out.bottomRightCorner<3, 3>() = Ji;
  return out;
}

Matrix6d se3_right_jacobian_inverse(const Vector6d& xi) { return se3_left_jacobian_inverse(-xi); }

PoseParams to_pose_params(const SE3& T) {
  const Eigen::Quaterniond q = T.quaternion();
  const Eigen::Vector3d& t = T.translation();
  return {t.x(), t.y(), t.z(), q.x(), q.y(), q.z(), q.w()};
}

SE3 from_pose_params(const double* p) {
  return SE3(Eigen::Quaterniond(p[6], p[3], p[4], p[5]), Eigen::Vector3d(p[0], p[1], p[2]));
}

}  // namespace plslam::geometry
