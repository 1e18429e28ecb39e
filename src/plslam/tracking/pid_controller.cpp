#include "plslam/tracking/pid_controller.h"

#include <algorithm>
#include <cmath>

namespace plslam::tracking {

PidController::PidController(PidGains gains, double integral_limit, double output_limit)
    : gains_(gains), integral_limit_(std::max(0.0, integral_limit)), output_limit_(std::max(0.0, output_limit)) {}

double PidController::update(double error, double dt) {
  const bool timed = dt > 0 && std::isfinite(dt);
  if (timed) integral_ = std::clamp(integral_ + error * dt, -integral_limit_, integral_limit_);
  // No derivative kick on the first sample after a reset: there is no previous error yet.
  const double derivative = has_previous_ && timed ? (error - previous_error_) / dt : 0.0;
  previous_error_ = error;
  has_previous_ = true;
  const double out = gains_.kp * error + gains_.ki * integral_ + gains_.kd * derivative;
  return std::clamp(out, -output_limit_, output_limit_);
}

void PidController::reset() {
  integral_ = 0.0;
  previous_error_ = 0.0;
  has_previous_ = false;
}

}  // namespace plslam::tracking
