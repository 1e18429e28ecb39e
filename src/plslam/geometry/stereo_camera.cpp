#include "plslam/geometry/stereo_camera.h"

#include <string>

#include "plslam/core/error.h"

namespace plslam::geometry {

StereoCamera::StereoCamera(double fx, double fy, double cx, double cy, double bf, int width,
                           int height)
    : fx_(fx), fy_(fy), cx_(cx), cy_(cy), bf_(bf), width_(width), height_(height) {
  if (!(fx > 0.0) || !(fy > 0.0) || !(bf > 0.0)) {
    throw InputError("", "stereo camera needs positive fx, fy and bf (got fx=" +
                             std::to_string(fx) + " fy=" + std::to_string(fy) +
                             " bf=" + std::to_string(bf) + ")");
  }
}

StereoCamera::StereoCamera(const StereoCalibration& c)
    : StereoCamera(c.fx, c.fy, c.cx, c.cy, c.bf(), c.width, c.height) {}

std::optional<Eigen::Vector3d> StereoCamera::unproject_stereo(const Eigen::Vector3d& obs) const {
  const double disparity = obs.x() - obs.z();
  if (!(disparity > 0.0)) return std::nullopt;
  return unproject(obs.head<2>(), bf_ / disparity);
}

Eigen::Vector3d line_through(const Eigen::Vector2d& p, const Eigen::Vector2d& q) {
  const Eigen::Vector3d l = Eigen::Vector3d(p.x(), p.y(), 1.0).cross(Eigen::Vector3d(q.x(), q.y(), 1.0));
  return l / l.head<2>().norm();
}

}  // namespace plslam::geometry
