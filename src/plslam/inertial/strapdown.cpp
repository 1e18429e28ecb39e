#include "plslam/inertial/strapdown.h"

#include <Eigen/Geometry>

#include "plslam/geometry/se3.h"

namespace plslam::inertial {
namespace {

const Eigen::Vector3d kGravityVector(0, 0, -kGravity);

struct Rates {
  Eigen::Matrix3d R_dot;
  Eigen::Vector3d v_dot, p_dot;
};

Rates rates(const Eigen::Matrix3d& R, const Eigen::Vector3d& v, const Eigen::Vector3d& gyro, const Eigen::Vector3d& acc) {
  return {R * geometry::hat(gyro), R * acc + kGravityVector, v};
}

Eigen::Matrix3d orthonormalised(const Eigen::Matrix3d& R) { return Eigen::Quaterniond(R).normalized().toRotationMatrix(); }

}  // namespace

NavState integrate_strapdown(const NavState& state, const std::vector<ImuSample>& samples, std::size_t first,
                             std::size_t last, const Eigen::Vector3d& gyro_bias, const Eigen::Vector3d& acc_bias) {
  NavState s = state;
  std::size_t k = first;
  const auto gyro = [&](std::size_t i) -> Eigen::Vector3d { return samples[i].gyro - gyro_bias; };
  const auto acc = [&](std::size_t i) -> Eigen::Vector3d { return samples[i].acc - acc_bias; };
  for (; k + 2 <= last; k += 2) {
    const double h = samples[k + 2].t - samples[k].t;
    const Rates k1 = rates(s.R, s.v, gyro(k), acc(k));
    const Rates k2 = rates(s.R + 0.5 * h * k1.R_dot, s.v + 0.5 * h * k1.v_dot, gyro(k + 1), acc(k + 1));
    const Rates k3 = rates(s.R + 0.5 * h * k2.R_dot, s.v + 0.5 * h * k2.v_dot, gyro(k + 1), acc(k + 1));
    const Rates k4 = rates(s.R + h * k3.R_dot, s.v + h * k3.v_dot, gyro(k + 2), acc(k + 2));
    s.R = orthonormalised(s.R + h / 6 * (k1.R_dot + 2 * k2.R_dot + 2 * k3.R_dot + k4.R_dot));
    s.p += h / 6 * (k1.p_dot + 2 * k2.p_dot + 2 * k3.p_dot + k4.p_dot);
    s.v += h / 6 * (k1.v_dot + 2 * k2.v_dot + 2 * k3.v_dot + k4.v_dot);
  }
  if (k < last) {  // one interval left: trapezoidal (Heun)
    const double h = samples[last].t - samples[k].t;
    const Eigen::Matrix3d R1 = s.R * geometry::so3_exp(0.5 * h * (gyro(k) + gyro(last)));
    const Eigen::Vector3d a = 0.5 * (s.R * acc(k) + R1 * acc(last)) + kGravityVector;
    s.p += h * s.v + 0.5 * h * h * a;
    s.v += h * a;
    s.R = R1;
  }
  return s;
}

}  // namespace plslam::inertial
