#include "plslam/inertial/gauge_prior_factor.h"

#include <stdexcept>

namespace plslam::inertial {

GaugePriorFactor::GaugePriorFactor(int keyframe, const geometry::SE3& T_cw, double sigma_m, double sigma_rad)
    : keyframes_{keyframe}, centre_(T_cw.inverse().translation()), R_cw_(T_cw.rotation()) {
  if (!(sigma_m > 0) || !(sigma_rad > 0)) throw std::invalid_argument("GaugePriorFactor: sigmas must be positive");
  w_position_ = 1.0 / sigma_m;
  w_heading_ = 1.0 / sigma_rad;
}

Eigen::VectorXd GaugePriorFactor::evaluate(std::span<const geometry::SE3> T_cw, std::span<const optim::Vector9d> extra,
                                           Eigen::MatrixXd* J) const {
  if (T_cw.size() != 1 || extra.size() != 1) throw std::invalid_argument("GaugePriorFactor: one keyframe");
  const geometry::SE3 T_wc = T_cw[0].inverse();
  // World-frame rotation from the held orientation to the current one: R_wc = exp(delta) R_wc_held.
  const Eigen::Vector3d delta = geometry::so3_log(T_wc.rotation() * R_cw_);
  Eigen::VectorXd r(4);
  r.head<3>() = w_position_ * (T_wc.translation() - centre_);
  r(3) = w_heading_ * delta.z();
  if (J) {
    // T_cw <- exp([rho; phi]) T_cw moves the centre by -R_wc rho (to first order) and turns R_wc by
    // exp(-R_wc phi) on the left, which moves delta by -J_l^-1(delta) R_wc phi.
    J->setZero(4, kColumnsPerKeyframe);
    J->block<3, 3>(0, 0) = -w_position_ * T_wc.rotation();
    J->block<1, 3>(3, 3) = -w_heading_ * (geometry::so3_left_jacobian_inverse(delta) * T_wc.rotation()).row(2);
  }
  return r;
}

}  // namespace plslam::inertial
