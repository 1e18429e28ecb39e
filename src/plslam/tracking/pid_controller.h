#pragma once
// A discrete PID controller with integral clamping (anti-windup) and output clamping. Used by the
// keyframe policy to turn the inlier error between the current frame and the reference keyframe
// into the offset Δ_PID of the paper's rule KF_cur < (KF_ref + Δ_PID) · Ratio.
namespace plslam::tracking {

// Gains on real time, so dropped frames or a different frame rate do not change the controller:
// kp is unitless, ki is per second (on the error integrated over seconds), kd is in seconds (on
// the error's rate of change per second).
struct PidGains {
  double kp = 0.0;
  double ki = 0.0;
  double kd = 0.0;
};

class PidController {
 public:
  // |integral| is kept within integral_limit and |output| within output_limit (both >= 0).
  PidController(PidGains gains, double integral_limit, double output_limit);

  // Feeds one error sample taken dt seconds after the previous one and returns the clamped
  // output. dt <= 0 (the first sample, or no usable time) adds nothing to the integral and gives
  // no derivative.
  double update(double error, double dt);
  // Forgets the integral and the previous error, e.g. when the reference keyframe changes.
  void reset();

  double integral() const { return integral_; }
  const PidGains& gains() const { return gains_; }

 private:
  PidGains gains_;
  double integral_limit_;
  double output_limit_;
  double integral_ = 0.0;
  double previous_error_ = 0.0;
  bool has_previous_ = false;
};

}  // namespace plslam::tracking
