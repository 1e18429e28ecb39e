#include "plslam/inertial/bias_random_walk_residual.h"

#include <stdexcept>

namespace plslam::inertial {

BiasRandomWalkCost::BiasRandomWalkCost(const Preintegration& preintegration) {
  const geometry::Vector6d variance = preintegration.bias_random_walk_covariance().diagonal();
  if (!(variance.minCoeff() > 0.0)) {
    throw std::invalid_argument("bias random walk: the random-walk densities must be positive");
  }
  weights_ = variance.cwiseSqrt().cwiseInverse();
}

bool BiasRandomWalkCost::Evaluate(double const* const* params, double* residuals,
                                  double** jacobians) const {
  const Eigen::Map<const geometry::Vector6d> bi(params[0]);
  const Eigen::Map<const geometry::Vector6d> bj(params[1]);
  Eigen::Map<geometry::Vector6d> r(residuals);
  r = weights_.cwiseProduct(bj - bi);
  if (!jacobians) return true;
  using RowMajor6d = Eigen::Matrix<double, 6, 6, Eigen::RowMajor>;
  for (const int k : {0, 1}) {
    if (!jacobians[k]) continue;
    Eigen::Map<RowMajor6d> J(jacobians[k]);
    J = (k == 0 ? -weights_ : weights_).asDiagonal();
  }
  return true;
}

}  // namespace plslam::inertial
