#include "plslam/tracking/keyframe_policy.h"

#include <fmt/format.h>

#include "plslam/core/error.h"

namespace plslam::tracking {

void KeyframePolicyOptions::validate(const std::string& source) const {
  auto fail = [&](const char* key, const std::string& why) {
    throw InputError(source, fmt::format("keyframe.{}: {}", key, why));
  };
  if (!(ratio > 0 && ratio <= 1)) fail("ratio", "must be in (0, 1]");
  if (min_frames < 0) fail("min_frames", "must be >= 0");
  if (max_frames < 1) fail("max_frames", "must be >= 1");
  if (min_inliers < 0) fail("min_inliers", "must be >= 0");
  if (pid_integral_limit < 0) fail("pid_integral_limit", "must be >= 0");
  if (!(pid_output_limit >= 0 && pid_output_limit < 1)) fail("pid_output_limit", "must be in [0, 1)");
  if (!(max_speed > 0)) fail("max_speed", "must be positive");
  if (velocity_min_frames < 1) fail("velocity_min_frames", "must be >= 1");
  if (max_queued < 1) fail("max_queued", "must be >= 1");
  if (!(kalman_options.accel_noise > 0)) fail("kalman_accel_noise", "must be positive");
  if (!(kalman_options.position_noise > 0)) fail("kalman_position_noise", "must be positive");
}

const char* to_string(KeyframeReason r) {
  switch (r) {
    case KeyframeReason::kNone: return "none";
    case KeyframeReason::kInlierRatio: return "inlier-ratio";
    case KeyframeReason::kCloseDepth: return "close-depth";
    case KeyframeReason::kMaxFrames: return "max-frames";
    case KeyframeReason::kVelocity: return "velocity";
    case KeyframeReason::kImuInterval: return "imu-interval";
    case KeyframeReason::kNewView: return "new-view";
  }
  return "?";
}

KeyframePolicy::KeyframePolicy(KeyframePolicyOptions options)
    : options_(options),
      // The output limit is relative to KF_ref, applied in decide(); here only the integral is bounded.
      pid_(options.pid_gains, options.pid_integral_limit, 1e12),
      kalman_(options.kalman_options) {
  options_.validate();
}

KeyframeDecision KeyframePolicy::decide(const KeyframeInputs& in) {
  KeyframeDecision d;

  const double dt = has_last_timestamp_ ? in.timestamp - last_timestamp_ : 0.0;
  if (options_.kalman) {
    if (!reference_position_) {
      reference_position_ = in.position;
      kalman_.reset_reference();
    }
    kalman_.update(dt, in.position - *reference_position_);
    d.speed = kalman_.speed();
  }
  last_timestamp_ = in.timestamp;
  has_last_timestamp_ = true;

  const double ref = static_cast<double>(in.reference_tracked);
  const double cur = static_cast<double>(in.tracked_inliers);
  if (options_.pid) {
    const double limit = options_.pid_output_limit * ref;
    d.delta_pid = std::clamp(pid_.update(cur - ref, dt), -limit, limit);
  }
  const double ratio = in.keyframes_in_map < 2 ? 0.4 : options_.ratio;
  d.threshold = (ref + d.delta_pid) * ratio;

  const long since = in.frame_id - last_keyframe_id_;
  const bool need_close = in.tracked_close < options_.close_tracked_max &&
                          in.untracked_close > options_.close_untracked_min;
  const bool c1a = since >= options_.max_frames;
  const bool c1b = since >= options_.min_frames && in.local_mapping_idle;
  const bool c1c = cur < 0.25 * ref || need_close;
  const bool weak = cur < d.threshold;
  const bool c2 = (weak || need_close) && in.tracked_inliers > options_.min_inliers;

  if ((c1a || c1b || c1c) && c2) {
    d.insert = true;
    d.reason = weak ? KeyframeReason::kInlierRatio : KeyframeReason::kCloseDepth;
    if (c1a && !c1b && !c1c) d.reason = KeyframeReason::kMaxFrames;
  } else if (options_.kalman && d.speed > options_.max_speed && since >= options_.velocity_min_frames &&
             in.tracked_inliers > options_.min_inliers) {
    d.insert = true;
    d.reason = KeyframeReason::kVelocity;
  }
  if (d.insert && in.keyframes_queued >= options_.max_queued) {
    d.insert = false;
    d.reason = KeyframeReason::kNone;
    d.queue_full = true;
  }
  return d;
}

void KeyframePolicy::transform_world(const geometry::SE3& T_new_old) {
  if (reference_position_) reference_position_ = T_new_old * *reference_position_;
  kalman_.rotate(T_new_old.rotation());
}

void KeyframePolicy::keyframe_inserted(const KeyframeInputs& in) {
  last_keyframe_id_ = in.frame_id;
  pid_.reset();
  reference_position_ = in.position;
  kalman_.reset_reference();
}

}  // namespace plslam::tracking
