#pragma once
// The Levenberg-Marquardt damping and stopping rules of the single-frame optimisations
// (pose_only.cpp, inertial/inertial_pose.cpp): Marquardt's scaled damping starts at 1e-5, falls by
// 3 after a step that lowers the cost and rises by 4 after one that does not.
#include <algorithm>

namespace plslam::optim {

struct LmDamping {
  double lambda = 1e-5;

  // A step of squared norm `step_sq` lowered the cost: true when it has converged (a sub-micrometre
  // / sub-microradian step, or a negligible decrease).
  bool accepted(double step_sq, double old_cost, double new_cost) {
    lambda = std::max(lambda / 3.0, 1e-9);
    return step_sq < 1e-12 || old_cost - new_cost < 1e-9 * old_cost;
  }
  // It did not: true when to stop. A sub-micrometre / sub-microradian step that does not lower the
  // cost is at the optimum, where the change is rounding noise and more damping would only repeat it.
  bool rejected(double step_sq) {
    if (step_sq < 1e-12) return true;
    lambda *= 4.0;
    return lambda > 1e8;
  }
};

}  // namespace plslam::optim
