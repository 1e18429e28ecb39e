#include "plslam/geometry/umeyama.h"

#include <Eigen/LU>
#include <Eigen/SVD>
#include <stdexcept>

namespace plslam::geometry {

AlignmentResult umeyama(const Eigen::Matrix3Xd& src, const Eigen::Matrix3Xd& dst, bool with_scale) {
  if (src.cols() != dst.cols()) throw std::invalid_argument("umeyama: point sets differ in size");
  const Eigen::Index n = src.cols();
  if (n < 3) throw std::invalid_argument("umeyama: need at least 3 point pairs");

  const Eigen::Vector3d mean_src = src.rowwise().mean();
  const Eigen::Vector3d mean_dst = dst.rowwise().mean();
  const Eigen::Matrix3Xd src_c = src.colwise() - mean_src;
  const Eigen::Matrix3Xd dst_c = dst.colwise() - mean_dst;

  // Cross-covariance of the centred sets (Umeyama eq. 38) and the source variance (eq. 36).
  const Eigen::Matrix3d sigma = dst_c * src_c.transpose() / static_cast<double>(n);
  const double var_src = src_c.squaredNorm() / static_cast<double>(n);

  Eigen::JacobiSVD<Eigen::Matrix3d> svd(sigma, Eigen::ComputeFullU | Eigen::ComputeFullV);
  // The sign flip keeps R a proper rotation when the best orthogonal fit would be a reflection.
  Eigen::Vector3d S = Eigen::Vector3d::Ones();
  if (svd.matrixU().determinant() * svd.matrixV().determinant() < 0.0) S(2) = -1.0;

  AlignmentResult result;
  result.R = svd.matrixU() * S.asDiagonal() * svd.matrixV().transpose();
  if (with_scale) {
    if (!(var_src > 0.0)) throw std::invalid_argument("umeyama: source points all coincide");
    result.s = svd.singularValues().dot(S) / var_src;
  }
  result.t = mean_dst - result.s * result.R * mean_src;
  return result;
}

}  // namespace plslam::geometry
