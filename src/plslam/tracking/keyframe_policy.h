#pragma once
// The keyframe decision: ORB-SLAM2's stereo rule, with the paper's two additions.
//  1. PID offset: the inlier condition becomes KF_cur < (KF_ref + Δ_PID) · ratio, where Δ_PID is
//     a PID controller's output on e = KF_cur − KF_ref (current frame's tracked inliers minus the
//     reference keyframe's tracked map points).
//  2. Kalman velocity: a constant-velocity filter on the displacement from the reference
//     keyframe; a keyframe is forced when its speed exceeds max_speed (7 m/s).
// Each addition can be switched off (keyframe.pid, keyframe.kalman) to measure what it is worth.
#include <optional>
#include <string>

#include <Eigen/Core>

#include "plslam/geometry/se3.h"
#include "plslam/tracking/pid_controller.h"
#include "plslam/tracking/velocity_kalman_filter.h"

namespace plslam::tracking {

struct KeyframePolicyOptions {
  double ratio = 0.75;          // ORB-SLAM2's thRefRatio for stereo (0.4 while the map has one keyframe)
  int min_frames = 0;           // frames since the last keyframe before an idle mapper may take one
  int max_frames = 20;          // frames after which a keyframe is due regardless (≈ the frame rate)
  int min_inliers = 15;         // never insert below this many inliers: the pose would be unreliable
  int close_tracked_max = 100;  // "need close points": fewer than this many close points tracked...
  int close_untracked_min = 70; // ...and more than this many close stereo points not in the map

  bool pid = true;
  // Gains: with e ≈ −0.25·KF_ref at ORB-SLAM2's threshold, kp = 0.2 moves the threshold from
  // 0.75·KF_ref to about 0.71·KF_ref, so during smooth motion keyframes come a little later (fewer
  // redundant keyframes, the paper's aim); ki lets a deficit that persists frame after frame move it
  // further, and kd reacts to the trend. The output is clamped to ±output_limit·KF_ref so the
  // offset can never dominate the rule, and the state is reset on every new reference keyframe.
  // The gains work on seconds (the frames' timestamps): ki = 0.1 /s and kd = 0.005 s are the
  // per-frame gains 0.01 and 0.05 at 10 Hz, and a dropped frame changes nothing.
  PidGains pid_gains{0.2, 0.1, 0.005};
  double pid_integral_limit = 200.0;  // inliers·s
  double pid_output_limit = 0.2;       // fraction of KF_ref

  bool kalman = true;
  double max_speed = 7.0;  // m/s
  // The velocity rule fires at most every this many frames: a car at 11 m/s is above 7 m/s all the
  // time, and a keyframe on every frame would only repeat the same close points.
  int velocity_min_frames = 2;
  VelocityKalmanOptions kalman_options;
  // Never more than this many keyframes waiting for local mapping: a keyframe due while the queue
  // is full is not made (ORB-SLAM2's stereo rule, KeyframesInQueue() < 3). The keyframes the rules
  // force regardless of mapping (max_frames, weak tracking, close points, velocity) would otherwise
  // pile up when mapping cannot keep up, and queued keyframes skip fusion and local BA.
  int max_queued = 3;

  // Throws InputError naming `source` and the offending option when out of range.
  void validate(const std::string& source = "keyframe options") const;
};

// What tracking knows about the current frame when it asks for a keyframe.
struct KeyframeInputs {
  long frame_id = 0;
  double timestamp = 0;             // seconds
  Eigen::Vector3d position = Eigen::Vector3d::Zero();  // camera centre in the world
  int tracked_inliers = 0;          // KF_cur: map points (and lines) tracked as inliers
  int reference_tracked = 0;        // KF_ref: the reference keyframe's well-observed map features
  int tracked_close = 0;            // close stereo points that are tracked map points
  int untracked_close = 0;          // close stereo points not yet in the map
  int keyframes_in_map = 0;
  bool local_mapping_idle = true;
  int keyframes_queued = 0;         // keyframes waiting for local mapping
};

// kImuInterval: tracking with the IMU keeps keyframes close in time (ImuTrackingOptions).
enum class KeyframeReason { kNone, kInlierRatio, kCloseDepth, kMaxFrames, kVelocity, kImuInterval, kNewView };
const char* to_string(KeyframeReason r);

struct KeyframeDecision {
  bool insert = false;
  KeyframeReason reason = KeyframeReason::kNone;
  double delta_pid = 0.0;  // the offset used this frame
  double threshold = 0.0;  // (KF_ref + Δ_PID) · ratio
  double speed = 0.0;      // Kalman speed estimate, m/s
  bool queue_full = false; // a rule asked for a keyframe, but max_queued keyframes were waiting
};

class KeyframePolicy {
 public:
  explicit KeyframePolicy(KeyframePolicyOptions options = {});

  // Call once per tracked frame, in order.
  KeyframeDecision decide(const KeyframeInputs& in);
  // Call when a keyframe was actually created from the frame passed to the last decide().
  void keyframe_inserted(const KeyframeInputs& in);
  // The world moved under the map (Map::transform_world, p_new = T_new_old p_old): the positions
  // decide() is given from now on are in the new world, and the reference keyframe's and the
  // speed estimate move with them (else the jump reads as a speed: 142 m/s when a handheld run's
  // world turned to gravity 5 m from its origin, and a keyframe for it).
  void transform_world(const geometry::SE3& T_new_old);

  const KeyframePolicyOptions& options() const { return options_; }

 private:
  KeyframePolicyOptions options_;
  PidController pid_;
  VelocityKalmanFilter kalman_;
  long last_keyframe_id_ = 0;
  std::optional<Eigen::Vector3d> reference_position_;
  double last_timestamp_ = 0;
  bool has_last_timestamp_ = false;
};

}  // namespace plslam::tracking
