#pragma once
// Two-view triangulation of points (linear DLT) and of line segments (back-projected rays of
// one view intersected with the back-projected plane of the other). Poses are T_cw.
#include <optional>
#include <utility>

#include <Eigen/Core>

#include "plslam/geometry/se3.h"
#include "plslam/geometry/stereo_camera.h"

namespace plslam::geometry {

struct Segment2d {
  Eigen::Vector2d start;
  Eigen::Vector2d end;
};

struct Segment3d {
  Eigen::Vector3d start;
  Eigen::Vector3d end;
};

// World point seen at pixel uv1 in view 1 and uv2 in view 2; nullopt when the rays are
// (near) parallel or the point lies behind either camera.
std::optional<Eigen::Vector3d> triangulate_point(const StereoCamera& cam, const SE3& T1_cw,
                                                 const SE3& T2_cw, const Eigen::Vector2d& uv1,
                                                 const Eigen::Vector2d& uv2);

// 3D segment whose endpoints lie on the rays through seg1's endpoints (view 1) and on the plane
// spanned by camera 2's centre and seg2. nullopt when a ray is (near) parallel to that plane
// (|cos| below min_ray_plane_sine: the line is close to the epipolar plane) or the endpoints lie
// behind either camera.
std::optional<Segment3d> triangulate_line(const StereoCamera& cam, const SE3& T1_cw,
                                          const SE3& T2_cw, const Segment2d& seg1,
                                          const Segment2d& seg2,
                                          double min_ray_plane_sine = 1e-3);

// The same for a rectified stereo pair: returns the segment in the left camera frame.
std::optional<Segment3d> triangulate_stereo_line(const StereoCamera& cam, const Segment2d& left,
                                                 const Segment2d& right,
                                                 double min_ray_plane_sine = 1e-3);

}  // namespace plslam::geometry
