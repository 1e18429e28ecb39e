#include "plslam/tracking/motion_model.h"

#include <cmath>

namespace plslam::tracking {

geometry::SE3 scale_motion(const geometry::SE3& velocity, double velocity_dt, double dt) {
  const double ratio = dt / velocity_dt;
  if (!std::isfinite(ratio) || ratio <= 0) return velocity;
  if (ratio == 1.0) return velocity;  // the usual case, bit-identical to the unscaled model
  return geometry::SE3::exp(ratio * velocity.log());
}

geometry::SE3 predict_pose(const geometry::SE3& velocity, double velocity_dt, double dt,
                           const geometry::SE3& last_T_cw) {
  return (scale_motion(velocity, velocity_dt, dt) * last_T_cw).normalized();
}

}  // namespace plslam::tracking
