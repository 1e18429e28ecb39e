#pragma once
// Constant-velocity prediction on real time: the last measured motion T_cur_last spans
// `velocity_dt` seconds; over a gap of `dt` seconds the camera moves along the same screw by
// exp(dt / velocity_dt · log(T_cur_last)). With a dropped frame (dt twice the usual interval) the
// prediction then lands where the camera is, instead of one interval short.
#include "plslam/geometry/se3.h"

namespace plslam::tracking {

// The motion `velocity` (spanning velocity_dt seconds) scaled to last `dt` seconds. A ratio that
// is not finite or not positive (missing or broken timestamps) keeps the motion as it is.
geometry::SE3 scale_motion(const geometry::SE3& velocity, double velocity_dt, double dt);

// The predicted T_cw of a frame `dt` seconds after `last_T_cw`.
geometry::SE3 predict_pose(const geometry::SE3& velocity, double velocity_dt, double dt,
                           const geometry::SE3& last_T_cw);

}  // namespace plslam::tracking
