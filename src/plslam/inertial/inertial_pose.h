#pragma once
// Tracking's pose optimisation with the IMU (as ORB-SLAM3's PoseInertialOptimizationLastKeyFrame):
// a frame's pose, velocity and IMU biases are estimated together from the map points and lines it
// matched (optim/pose_terms.h) and from the IMU preintegrated since an earlier state i that is held
// fixed (a keyframe's, or the last frame's). The IMU terms are the residual between state i and the
// frame (inertial/imu_residual.h; its deltas corrected for the frame's bias estimate) and the bias
// random walk from state i's bias. Where vision holds the pose loosely (few matches, or matches in
// one part of the image), the IMU holds it; velocity and bias come from the IMU's agreement with
// the visual pose. State i is held fixed, so its own error passes to the frame: it must be a
// state the local BA has settled (ORB-SLAM3 uses the last keyframe's after its BA).
//
// The pose is that of the left camera, perturbed as in optim/pose_only.h (T_cw <- exp(delta) T_cw,
// delta = (translation, rotation)); the body (IMU) pose follows as T_wb = T_cw^-1 T_imu_cam^-1, so
// a camera perturbation moves the body by T_wb <- T_wb exp(-Ad(T_imu_cam) delta).
#include <span>
#include <vector>

#include <Eigen/Core>

#include "plslam/geometry/se3.h"
#include "plslam/geometry/stereo_camera.h"
#include "plslam/inertial/bias_random_walk_residual.h"
#include "plslam/inertial/imu_bias.h"
#include "plslam/inertial/imu_residual.h"
#include "plslam/inertial/preintegration.h"
#include "plslam/optim/pose_only.h"

namespace plslam::inertial {

using Vector15d = Eigen::Matrix<double, 15, 1>;
using Matrix15d = Eigen::Matrix<double, 15, 15>;

// The IMU's state at a frame.
struct InertialState {
  geometry::SE3 T_wb;                           // the body (IMU) in the world
  Eigen::Vector3d v = Eigen::Vector3d::Zero();  // the body's velocity, world frame
  ImuBias bias;
};

// Where the IMU puts state i after the preintegrated interval (Forster et al. 2017, eq. 33), with
// the deltas corrected for i's bias, which it keeps: R_j = R_i dR, v_j = v_i + g dt + R_i dv,
// p_j = p_i + v_i dt + g dt^2 / 2 + R_i dp. Tracking's prediction of the next frame.
InertialState predict(const InertialState& i, const Preintegration& i_to_j);

// Velocity seeds for body poses in time order that the IMU connects, `from_previous[k]` from pose
// k-1 to pose k (null for k = 0 or where no samples join them): from each pose and its successor,
// v_i = (p_j - p_i - g dt^2 / 2 - R_i delta_p) / dt (delta_p at `bias`); a pose with no successor
// (the last, or one before a gap) takes the velocity predict() gives at the end of the interval
// before it. Exact for exact poses and IMU, where differences of positions alone miss by the
// acceleration times the interval. A pose the IMU joins to neither neighbour keeps zero.
std::vector<Eigen::Vector3d> seed_velocities(std::span<const geometry::SE3> T_wb,
                                             std::span<const Preintegration* const> from_previous,
                                             const ImuBias& bias);

// The IMU terms between a fixed state i and a frame: 9 whitened IMU residual rows and 6 whitened
// bias walk rows, with their Jacobian over the frame's tangent [delta (6, of T_cw); dv (3); dbias
// (6, [bg; ba])].
class InertialTerms {
 public:
  // `i_to_frame` from state i's time to the frame's; `T_imu_cam` places the left camera in the IMU
  // frame (ImuData::T_imu_cam). Throws std::invalid_argument as ImuCost and BiasRandomWalkCost do.
  InertialTerms(const Preintegration& i_to_frame, const InertialState& i, const geometry::SE3& T_imu_cam);

  // The residual at the frame state (T_cw, v, bias); with J, its Jacobian.
  Vector15d evaluate(const geometry::SE3& T_cw, const Eigen::Vector3d& v, const ImuBias& bias,
                     Matrix15d* J = nullptr) const;
  geometry::SE3 body_pose(const geometry::SE3& T_cw) const { return T_cw.inverse() * T_cam_imu_; }

 private:
  ImuCost imu_;
  BiasRandomWalkCost walk_;
  InertialState i_;
  geometry::SE3 T_cam_imu_;
  geometry::Matrix6d body_from_camera_;  // -Ad(T_imu_cam): the body's tangent per camera delta
};

struct InertialPoseResult {
  optim::PoseOnlyResult visual;  // T_cw, the outlier flags and inlier counts, the visual cost
  InertialState state;           // the frame's (T_wb from T_cw)
  double imu_cost = 0;           // squared norm of the 15 whitened IMU rows at the end
  // J' W J of every inlier term at the end, without kernels, over [delta; dv; dbias]: what the
  // frame's state is known to, for a later optimisation's prior or a check of observability.
  Matrix15d information = Matrix15d::Zero();
};

// The frame's state from the initial guess (the IMU's prediction, or the motion model's), rounds
// and outlier classification as optimize_pose (the same options; with `covariance`,
// visual.covariance is vision's alone, as optimize_pose gives it: the IMU's share depends on state
// i's own error, which `information` leaves out).
InertialPoseResult optimize_pose_inertial(const geometry::StereoCamera& cam, const InertialTerms& imu,
                                          const geometry::SE3& T_cw_init, const Eigen::Vector3d& v_init,
                                          const ImuBias& bias_init, const std::vector<optim::PosePointTerm>& points,
                                          const std::vector<optim::PoseLineTerm>& lines,
                                          const optim::PoseOnlyOptions& options = {});

}  // namespace plslam::inertial
