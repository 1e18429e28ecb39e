#pragma once
// The visual terms of a single-pose optimisation (pose_only.h): the map points' and lines' stereo
// reprojection errors in one frame, with their information from the pyramid level. Shared by the
// pose-only optimisation and the inertial one (inertial/inertial_pose.h), which adds velocity, bias
// and the IMU to the same terms.
#include <vector>

#include "plslam/geometry/se3.h"
#include "plslam/geometry/stereo_camera.h"
#include "plslam/optim/pose_only.h"

namespace plslam::optim {

class PoseTerms {
 public:
  // Keeps references: the camera, terms and options must outlive it.
  PoseTerms(const geometry::StereoCamera& cam, const std::vector<PosePointTerm>& points,
            const std::vector<PoseLineTerm>& lines, const PoseOnlyOptions& options);

  // The cost at T_cw of the terms not flagged out (robust: under the Huber kernels), sum of
  // information * squared error; with H and g, adds the (IRLS-weighted) normal equations J' W J
  // and J' W r for the left perturbation T_cw <- exp(delta) T_cw, delta = (translation, rotation).
  double evaluate(const geometry::SE3& T_cw, const std::vector<bool>& point_out, const std::vector<bool>& line_out,
                  bool robust, geometry::Matrix6d* H, geometry::Vector6d* g) const;
  // Flags every term by its chi-square gate at T_cw; returns the kernel-free cost of the inliers.
  double classify(const geometry::SE3& T_cw, std::vector<bool>* point_out, std::vector<bool>* line_out) const;
  // The inverse of the inliers' information J' W J at T_cw (no kernels): the pose's covariance as
  // vision alone gives it (PoseOnlyResult::covariance); zero when a direction is unobserved.
  geometry::Matrix6d covariance(const geometry::SE3& T_cw, const std::vector<bool>& point_out,
                                const std::vector<bool>& line_out) const;

  std::size_t num_points() const { return points_.size(); }
  std::size_t num_lines() const { return lines_.size(); }

 private:
  const geometry::StereoCamera& cam_;
  const std::vector<PosePointTerm>& points_;
  const std::vector<PoseLineTerm>& lines_;
  const PoseOnlyOptions& options_;
  std::vector<double> point_info_;  // per term, precomputed
  std::vector<double> line_info_;
};

}  // namespace plslam::optim
