#include "plslam/inertial/preintegration.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace plslam::inertial {
namespace {

ImuSample interpolated_sample(const ImuSample& a, const ImuSample& b, double t) {
  const double s = (t - a.t) / (b.t - a.t);
  return {t, a.gyro + s * (b.gyro - a.gyro), a.acc + s * (b.acc - a.acc)};
}

// [t_i, t_j]'s ends, interpolated, with the samples strictly between them.
std::vector<ImuSample> samples_over(std::span<const ImuSample> samples, double t_i, double t_j) {
  if (!(std::isfinite(t_i) && std::isfinite(t_j) && t_i < t_j)) {
    throw std::invalid_argument("preintegration: the interval needs finite t_i < t_j");
  }
  if (samples.empty() || samples.front().t > t_i || samples.back().t < t_j) {
    throw std::invalid_argument("preintegration: the IMU samples do not cover [t_i, t_j]");
  }
  const auto by_time = [](double t, const ImuSample& s) { return t < s.t; };
  // The first sample after t_i and the first at or after t_j; both exist and have a predecessor,
  // as the samples cover [t_i, t_j].
  const auto first_inside = std::upper_bound(samples.begin(), samples.end(), t_i, by_time);
  const auto end_inside = std::partition_point(first_inside, samples.end(),
                                               [&](const ImuSample& s) { return s.t < t_j; });
  std::vector<ImuSample> out;
  out.reserve(static_cast<size_t>(end_inside - first_inside) + 2);
  out.push_back(interpolated_sample(*(first_inside - 1), *first_inside, t_i));
  out.insert(out.end(), first_inside, end_inside);
  out.push_back(end_inside->t == t_j ? *end_inside
                                     : interpolated_sample(*(end_inside - 1), *end_inside, t_j));
  for (size_t k = 1; k < out.size(); ++k) {
    if (!(out[k].t > out[k - 1].t)) {
      throw std::invalid_argument("preintegration: IMU sample times are not strictly increasing");
    }
  }
  return out;
}

}  // namespace

Preintegration::Preintegration(std::span<const ImuSample> samples, double t_i, double t_j,
                               const ImuBias& linearisation_bias, const ImuNoise& noise)
    : samples_(samples_over(samples, t_i, t_j)), bias_(linearisation_bias), noise_(noise) {
  const double densities[] = {noise.gyro_noise_density, noise.gyro_random_walk,
                              noise.acc_noise_density, noise.acc_random_walk};
  for (const double d : densities) {
    if (!(d >= 0.0 && std::isfinite(d))) {
      throw std::invalid_argument("preintegration: IMU noise densities must be finite and >= 0");
    }
  }
  integrate();
}

void Preintegration::integrate() {
  deltas_ = PreintegratedDeltas{};
  bias_jacobian_.setZero();
  covariance_.setZero();
  const double var_g = noise_.gyro_noise_density * noise_.gyro_noise_density;
  const double var_a = noise_.acc_noise_density * noise_.acc_noise_density;
  StepTransition step;
  for (size_t k = 0; k + 1 < samples_.size(); ++k) {
    const ImuSample& s0 = samples_[k];
    const ImuSample& s1 = samples_[k + 1];
    const double dt = s1.t - s0.t;
    const Eigen::Vector3d gyro = 0.5 * (s0.gyro + s1.gyro) - bias_.gyro;
    const Eigen::Vector3d acc = 0.5 * (s0.acc + s1.acc) - bias_.acc;
    deltas_ = midpoint_step(deltas_, gyro, acc, dt, &step);
    // A bias change is the noise's opposite: it shifts both samples' readings, hence the mean.
    bias_jacobian_ = step.A_times(bias_jacobian_) - step.B;
    // A Sigma A' + B Q B', Q = diag(var_g / dt I_3, var_a / dt I_3); A Sigma A' = A (A Sigma)'
    // as Sigma is symmetric.
    const Matrix9d A_sigma = step.A_times(covariance_);
    covariance_ = step.A_times(Matrix9d(A_sigma.transpose()));
    const auto B_gyro = step.B.leftCols<3>();
    const auto B_acc = step.B.bottomRightCorner<6, 3>();  // its top block is zero
    covariance_.noalias() += (var_g / dt) * B_gyro * B_gyro.transpose();
    covariance_.bottomRightCorner<6, 6>().noalias() += (var_a / dt) * B_acc * B_acc.transpose();
  }
  covariance_ = 0.5 * (covariance_ + covariance_.transpose()).eval();
}

Eigen::Matrix3d Preintegration::corrected_delta_R(const ImuBias& b) const {
  return deltas_.R * geometry::so3_exp(dR_dbg() * (b.gyro - bias_.gyro));
}

Eigen::Vector3d Preintegration::corrected_delta_v(const ImuBias& b) const {
  return deltas_.v + dv_dbg() * (b.gyro - bias_.gyro) + dv_dba() * (b.acc - bias_.acc);
}

Eigen::Vector3d Preintegration::corrected_delta_p(const ImuBias& b) const {
  return deltas_.p + dp_dbg() * (b.gyro - bias_.gyro) + dp_dba() * (b.acc - bias_.acc);
}

bool Preintegration::bias_moved_far(const ImuBias& b,
                                    const ReintegrationThresholds& thresholds) const {
  return (b.gyro - bias_.gyro).norm() > thresholds.gyro ||
         (b.acc - bias_.acc).norm() > thresholds.acc;
}

void Preintegration::reintegrate(const ImuBias& b) {
  bias_ = b;
  integrate();
}

geometry::Matrix6d Preintegration::bias_random_walk_covariance() const {
  const double wg = noise_.gyro_random_walk * noise_.gyro_random_walk * dt();
  const double wa = noise_.acc_random_walk * noise_.acc_random_walk * dt();
  geometry::Vector6d diag;
  diag << Eigen::Vector3d::Constant(wg), Eigen::Vector3d::Constant(wa);
  return diag.asDiagonal();
}

}  // namespace plslam::inertial
