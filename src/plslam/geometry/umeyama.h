#pragma once
// Closed-form least-squares alignment of two point sets (Umeyama, PAMI 1991):
// finds R, t (and s) minimising sum_i || dst_i - (s R src_i + t) ||^2.
#include <Eigen/Core>

namespace plslam::geometry {

struct AlignmentResult {
  Eigen::Matrix3d R = Eigen::Matrix3d::Identity();
  Eigen::Vector3d t = Eigen::Vector3d::Zero();
  double s = 1.0;  // 1 unless solved with scale

  // s R p + t: maps a source point into the destination frame.
  Eigen::Vector3d apply(const Eigen::Vector3d& p) const { return s * (R * p) + t; }
};

// src and dst hold corresponding points column by column. With `with_scale` the result is a
// Sim(3), otherwise an SE(3) (s = 1). Throws std::invalid_argument when the sizes differ, there
// are fewer than 3 points, or (with scale) all source points coincide.
AlignmentResult umeyama(const Eigen::Matrix3Xd& src, const Eigen::Matrix3Xd& dst, bool with_scale);

}  // namespace plslam::geometry
