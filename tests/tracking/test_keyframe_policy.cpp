#include <algorithm>
#include <cmath>
#include <random>

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include "plslam/core/error.h"
#include "plslam/tracking/keyframe_policy.h"

namespace plslam::tracking {
namespace {

TEST(PidController, MatchesHandComputedSequence) {
  PidController pid({0.5, 0.1, 0.2}, 100.0, 1000.0);
  // e: -10, -20, -20, 0
  // 1: P=-5, I=-1 (sum -10), D=0 (first sample)      -> -6
  // 2: P=-10, I=-3 (sum -30), D=0.2*(-10)=-2         -> -15
  // 3: P=-10, I=-5 (sum -50), D=0                    -> -15
  // 4: P=0,  I=-5 (sum -50),  D=0.2*(20)=4           -> -1
  EXPECT_DOUBLE_EQ(pid.update(-10, 1.0), -6.0);
  EXPECT_DOUBLE_EQ(pid.update(-20, 1.0), -15.0);
  EXPECT_DOUBLE_EQ(pid.update(-20, 1.0), -15.0);
  EXPECT_DOUBLE_EQ(pid.update(0, 1.0), -1.0);
  pid.reset();
  EXPECT_DOUBLE_EQ(pid.integral(), 0.0);
  EXPECT_DOUBLE_EQ(pid.update(-10, 1.0), -6.0);  // no derivative kick after a reset
}

TEST(PidController, WorksOnSecondsSoADroppedSampleChangesNothing) {
  // Error ramp e(t) = -100 t, sampled every 0.1 s, or with the sample at 0.2 s dropped.
  PidController every({0.2, 0.1, 0.005}, 1e9, 1e9), dropped({0.2, 0.1, 0.005}, 1e9, 1e9);
  double out_every = 0, out_dropped = 0;
  for (int k = 1; k <= 4; ++k) out_every = every.update(-10.0 * k, 0.1);
  out_dropped = dropped.update(-10.0, 0.1);
  out_dropped = dropped.update(-30.0, 0.2);
  out_dropped = dropped.update(-40.0, 0.1);
  // Rectangle rule: the integral over a gap takes the error at its end. Every: -(10+20+30+40)·0.1;
  // dropped: -(10·0.1 + 30·0.2 + 40·0.1); the derivative (-100/s) and P term agree exactly.
  EXPECT_NEAR(every.integral(), -10.0, 1e-12);
  EXPECT_NEAR(dropped.integral(), -11.0, 1e-12);
  EXPECT_NEAR(out_every, 0.2 * -40 + 0.1 * -10.0 + 0.005 * -100, 1e-12);
  EXPECT_NEAR(out_dropped, 0.2 * -40 + 0.1 * -11.0 + 0.005 * -100, 1e-12);
  EXPECT_NEAR(out_dropped, out_every, 0.1 * std::abs(out_every));
}

TEST(PidController, NoTimeNoIntegralNoDerivative) {
  PidController pid({1.0, 1.0, 1.0}, 100.0, 100.0);
  EXPECT_DOUBLE_EQ(pid.update(-10, 0.0), -10.0);  // first sample: P only
  EXPECT_DOUBLE_EQ(pid.update(-20, -0.1), -20.0);  // time going back: P only
  EXPECT_DOUBLE_EQ(pid.integral(), 0.0);
}

TEST(PidController, ClampsIntegralAndOutput) {
  PidController pid({1.0, 1.0, 0.0}, 25.0, 30.0);
  for (int i = 0; i < 10; ++i) pid.update(-10, 1.0);
  EXPECT_DOUBLE_EQ(pid.integral(), -25.0);       // anti-windup
  EXPECT_DOUBLE_EQ(pid.update(-10, 1.0), -30.0);      // -10 - 25 = -35, clamped
  // integral -25 + 40 = 15; P 40 + I 15 = 55, clamped to +30.
  EXPECT_DOUBLE_EQ(pid.update(+40, 1.0), 30.0);
}

TEST(VelocityKalmanFilter, ConvergesToConstantSpeed) {
  VelocityKalmanFilter kf;
  std::mt19937 rng(3);
  std::normal_distribution<double> noise(0.0, 0.02);
  const Eigen::Vector3d v(6.0, 0.0, 8.0);  // 10 m/s
  const double dt = 0.1;
  for (int k = 1; k <= 30; ++k) {
    const Eigen::Vector3d d = v * (k * dt) + Eigen::Vector3d(noise(rng), noise(rng), noise(rng));
    kf.update(dt, d);
  }
  EXPECT_NEAR(kf.speed(), 10.0, 0.3);
  EXPECT_LT((kf.velocity() - v).norm(), 0.4);
}

TEST(VelocityKalmanFilter, KeepsVelocityAcrossReferenceChange) {
  VelocityKalmanFilter kf;
  const Eigen::Vector3d v(0, 0, 2.0);
  for (int k = 1; k <= 20; ++k) kf.update(0.05, v * (k * 0.05));
  const double before = kf.speed();
  kf.reset_reference();
  EXPECT_NEAR(kf.displacement().norm(), 0.0, 1e-12);
  for (int k = 1; k <= 5; ++k) kf.update(0.05, v * (k * 0.05));
  EXPECT_NEAR(before, 2.0, 0.05);
  EXPECT_NEAR(kf.speed(), 2.0, 0.05);
}

KeyframeInputs frame(long id, double t, double x, int inliers, int ref) {
  KeyframeInputs in;
  in.frame_id = id;
  in.timestamp = t;
  in.position = Eigen::Vector3d(0, 0, x);
  in.tracked_inliers = inliers;
  in.reference_tracked = ref;
  in.tracked_close = 200;     // plenty of close points: no "need close" keyframes
  in.untracked_close = 0;
  in.keyframes_in_map = 5;
  in.local_mapping_idle = true;
  return in;
}

// A scripted inlier sequence: inliers decay linearly from the reference's 400. Without PID the
// keyframe comes when inliers fall below 0.75·400 = 300; with the PID offset it comes later.
int first_keyframe(bool pid) {
  KeyframePolicyOptions o;
  o.pid = pid;
  o.kalman = false;
  KeyframePolicy policy(o);
  for (int k = 1; k < 60; ++k) {
    const auto d = policy.decide(frame(k, 0.05 * k, 0.0, 400 - 5 * k, 400));
    if (d.insert) return k;
  }
  return -1;
}

TEST(KeyframePolicy, OrbSlam2RuleWithoutPid) {
  // 400 - 5k < 300  <=>  k > 20.
  EXPECT_EQ(first_keyframe(false), 21);
}

TEST(KeyframePolicy, PidOffsetDelaysKeyframesDuringSmoothDecay) {
  const int with_pid = first_keyframe(true);
  EXPECT_GT(with_pid, 21);
  EXPECT_LT(with_pid, 40);  // bounded by the output clamp: at most 0.2·KF_ref
}

TEST(KeyframePolicy, PidOffsetIsClampedAndReported) {
  KeyframePolicyOptions o;
  o.kalman = false;
  KeyframePolicy policy(o);
  KeyframeDecision d;
  for (int k = 1; k < 10; ++k) d = policy.decide(frame(k, 0.05 * k, 0, 320, 400));
  EXPECT_LT(d.delta_pid, 0.0);
  EXPECT_GE(d.delta_pid, -0.2 * 400);
  EXPECT_NEAR(d.threshold, (400 + d.delta_pid) * 0.75, 1e-9);
}

TEST(KeyframePolicy, KalmanForcesKeyframeAboveSevenMetresPerSecond) {
  for (double speed : {5.0, 9.0}) {
    KeyframePolicyOptions o;
    o.pid = false;
    KeyframePolicy policy(o);
    int inserted_by_velocity = 0;
    for (int k = 1; k <= 40; ++k) {
      // Plenty of inliers: only the velocity rule can fire.
      const auto in = frame(k, 0.1 * k, speed * 0.1 * k, 390, 400);
      const auto d = policy.decide(in);
      if (d.insert) {
        EXPECT_EQ(d.reason, KeyframeReason::kVelocity);
        ++inserted_by_velocity;
        policy.keyframe_inserted(in);
      }
    }
    if (speed < 7.0) {
      EXPECT_EQ(inserted_by_velocity, 0) << speed;
    } else {
      // At most every velocity_min_frames (2) frames, and from the first frames on.
      EXPECT_GE(inserted_by_velocity, 18) << speed;
      EXPECT_LE(inserted_by_velocity, 20) << speed;
    }
  }
}

// A camera walking at 1.4 m/s, 5 m from the world's origin, when the world is turned by 90 deg to
// gravity (System::align_world_with_gravity): the positions jump by 7 m between two frames, which
// the policy must not read as a speed.
TEST(KeyframePolicy, TheWorldTurningUnderTheMapIsNoSpeed) {
  for (const bool told : {true, false}) {
    KeyframePolicyOptions o;
    o.pid = false;
    KeyframePolicy policy(o);
    const geometry::SE3 T_new_old(Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitX()).toRotationMatrix(),
                                  Eigen::Vector3d::Zero());
    KeyframeInputs first = frame(1, 0.05, 5.0, 390, 400);
    policy.decide(first);
    policy.keyframe_inserted(first);
    double max_speed = 0;
    int velocity_keyframes = 0;
    for (int k = 2; k <= 40; ++k) {
      KeyframeInputs in = frame(k, 0.05 * k, 5.0 + 1.4 * 0.05 * (k - 1), 390, 400);
      if (k == 20 && told) policy.transform_world(T_new_old);
      if (k >= 20) in.position = T_new_old * in.position;
      const auto d = policy.decide(in);
      if (k > 10) max_speed = std::max(max_speed, d.speed);
      if (d.insert && d.reason == KeyframeReason::kVelocity) ++velocity_keyframes;
    }
    if (told) {
      EXPECT_NEAR(max_speed, 1.4, 0.1);
      EXPECT_EQ(velocity_keyframes, 0);
    } else {
      EXPECT_GT(max_speed, 7.0);  // what the turn looked like before
    }
  }
}

TEST(KeyframePolicy, KalmanCanBeSwitchedOff) {
  KeyframePolicyOptions o;
  o.pid = false;
  o.kalman = false;
  o.max_frames = 1000;
  KeyframePolicy policy(o);
  for (int k = 1; k <= 40; ++k) EXPECT_FALSE(policy.decide(frame(k, 0.1 * k, 20.0 * 0.1 * k, 390, 400)).insert);
}

TEST(KeyframePolicy, NeverInsertsWithTooFewInliers) {
  KeyframePolicy policy;
  EXPECT_FALSE(policy.decide(frame(30, 1.5, 0, 10, 400)).insert);
}

TEST(KeyframePolicy, CloseDepthNeedTriggersKeyframe) {
  KeyframePolicyOptions o;
  o.kalman = false;
  KeyframePolicy policy(o);
  auto in = frame(2, 0.1, 0, 390, 400);
  in.tracked_close = 50;
  in.untracked_close = 120;
  const auto d = policy.decide(in);
  EXPECT_TRUE(d.insert);
  EXPECT_EQ(d.reason, KeyframeReason::kCloseDepth);
}

// A keyframe the rules want is not made while max_queued keyframes wait for local mapping, and
// the decision says why; one fewer waiting and it is made.
TEST(KeyframePolicy, AFullMappingQueueHoldsTheKeyframeBack) {
  for (int queued : {3, 2}) {
    KeyframePolicyOptions o;
    o.kalman = false;
    KeyframePolicy policy(o);
    auto in = frame(2, 0.1, 0, 390, 400);
    in.tracked_close = 50;
    in.untracked_close = 120;  // the close-depth rule fires whether mapping is idle or not
    in.local_mapping_idle = false;
    in.keyframes_queued = queued;
    const auto d = policy.decide(in);
    EXPECT_EQ(d.insert, queued < 3) << queued;
    EXPECT_EQ(d.queue_full, queued == 3) << queued;
    EXPECT_EQ(d.reason, queued < 3 ? KeyframeReason::kCloseDepth : KeyframeReason::kNone) << queued;
  }
}

TEST(KeyframePolicy, RejectsInvalidOptions) {
  KeyframePolicyOptions o;
  o.ratio = 1.5;
  EXPECT_THROW(o.validate(), InputError);
  o = {};
  o.max_speed = -1;
  EXPECT_THROW(o.validate(), InputError);
  o = {};
  o.max_queued = 0;
  EXPECT_THROW(o.validate(), InputError);
}

}  // namespace
}  // namespace plslam::tracking
