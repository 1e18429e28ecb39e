#include "plslam/geometry/triangulation.h"

#include <cmath>

#include <Eigen/SVD>

namespace plslam::geometry {

std::optional<Eigen::Vector3d> triangulate_point(const StereoCamera& cam, const SE3& T1_cw,
                                                 const SE3& T2_cw, const Eigen::Vector2d& uv1,
                                                 const Eigen::Vector2d& uv2) {
  // DLT on normalised coordinates: x * (P row 3) - (P row 1) = 0, etc.
  const Eigen::Vector3d x1 = cam.ray(uv1), x2 = cam.ray(uv2);
  Eigen::Matrix<double, 3, 4> P1, P2;
  P1 << T1_cw.rotation(), T1_cw.translation();
  P2 << T2_cw.rotation(), T2_cw.translation();
  Eigen::Matrix4d A;
  A.row(0) = x1.x() * P1.row(2) - P1.row(0);
  A.row(1) = x1.y() * P1.row(2) - P1.row(1);
  A.row(2) = x2.x() * P2.row(2) - P2.row(0);
  A.row(3) = x2.y() * P2.row(2) - P2.row(1);
  const Eigen::JacobiSVD<Eigen::Matrix4d> svd(A, Eigen::ComputeFullV);
  const Eigen::Vector4d h = svd.matrixV().col(3);
  if (std::abs(h(3)) < 1e-12) return std::nullopt;  // point at infinity: parallel rays
  const Eigen::Vector3d X = h.head<3>() / h(3);
  if ((T1_cw * X).z() <= 0.0 || (T2_cw * X).z() <= 0.0) return std::nullopt;
  return X;
}

std::optional<Segment3d> triangulate_line(const StereoCamera& cam, const SE3& T1_cw,
                                          const SE3& T2_cw, const Segment2d& seg1,
                                          const Segment2d& seg2, double min_ray_plane_sine) {
  // Plane through camera 2's centre containing seg2, expressed in the world frame: n.X + d = 0.
  const Eigen::Vector3d n2c = cam.ray(seg2.start).cross(cam.ray(seg2.end));
  if (n2c.norm() < 1e-12) return std::nullopt;
  const SE3 T2_wc = T2_cw.inverse();
  const Eigen::Vector3d n = (T2_wc.rotation() * n2c).normalized();
  const double d = -n.dot(T2_wc.translation());

  const SE3 T1_wc = T1_cw.inverse();
  const Eigen::Vector3d c1 = T1_wc.translation();
  auto intersect = [&](const Eigen::Vector2d& uv) -> std::optional<Eigen::Vector3d> {
    const Eigen::Vector3d dir = (T1_wc.rotation() * cam.ray(uv)).normalized();
    const double denom = n.dot(dir);
    if (std::abs(denom) < min_ray_plane_sine) return std::nullopt;
    const double s = -(n.dot(c1) + d) / denom;
    const Eigen::Vector3d X = c1 + s * dir;
    if ((T1_cw * X).z() <= 0.0 || (T2_cw * X).z() <= 0.0) return std::nullopt;
    return X;
  };
  const auto a = intersect(seg1.start);
  const auto b = intersect(seg1.end);
  if (!a || !b) return std::nullopt;
  return Segment3d{*a, *b};
}

std::optional<Segment3d> triangulate_stereo_line(const StereoCamera& cam, const Segment2d& left,
                                                 const Segment2d& right,
                                                 double min_ray_plane_sine) {
  // The right camera frame is the left one shifted by -baseline along x.
  const SE3 T_right_left(Eigen::Matrix3d::Identity(), Eigen::Vector3d(-cam.baseline(), 0.0, 0.0));
  return triangulate_line(cam, SE3(), T_right_left, left, right, min_ray_plane_sine);
}

}  // namespace plslam::geometry
