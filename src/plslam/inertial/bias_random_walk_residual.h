#pragma once
// The bias random-walk residual between the bias at t_i and that at t_j: r = W (b_j - b_i),
// whitened by the random walk over the preintegration's interval, W = diag(1 / (sigma_bg sqrt(dt))
// I_3, 1 / (sigma_ba sqrt(dt)) I_3). Blocks: bias_i (6, [bg; ba]), bias_j (6).
#include <ceres/sized_cost_function.h>

#include "plslam/geometry/se3.h"
#include "plslam/inertial/preintegration.h"

namespace plslam::inertial {

class BiasRandomWalkCost final : public ceres::SizedCostFunction<6, 6, 6> {
 public:
  // Throws std::invalid_argument when a random-walk density is zero.
  explicit BiasRandomWalkCost(const Preintegration& preintegration);
  bool Evaluate(double const* const* params, double* residuals, double** jacobians) const override;

  const geometry::Vector6d& sqrt_information_diagonal() const { return weights_; }

 private:
  geometry::Vector6d weights_;
};

}  // namespace plslam::inertial
