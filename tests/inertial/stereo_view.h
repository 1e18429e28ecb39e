#pragma once
// Map points seen by a stereo camera, for the inertial pose tests and bench/inertial.cpp: `n`
// points 2-8 m in front of the camera at T_cw, spread over most of the image, each with its stereo
// measurement (u_l, v, u_r) plus Gaussian pixel noise. No GoogleTest in here.
#include <cstdint>
#include <random>
#include <vector>

#include "plslam/geometry/se3.h"
#include "plslam/geometry/stereo_camera.h"
#include "plslam/optim/pose_only.h"

namespace plslam::inertial::test {

inline std::vector<optim::PosePointTerm> stereo_points_in_view(const geometry::StereoCamera& cam,
                                                                const geometry::SE3& T_cw, int n, double noise_px,
                                                                std::uint32_t seed = 1) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1, 1), depth(2, 8);
  std::normal_distribution<double> noise(0, noise_px);
  std::vector<optim::PosePointTerm> out;
  while (static_cast<int>(out.size()) < n) {
    const double z = depth(rng);
    const Eigen::Vector3d Xc(u(rng) * 300 * z / cam.fx(), u(rng) * 200 * z / cam.fy(), z);
    optim::PosePointTerm t;
    t.world = T_cw.inverse() * Xc;
    t.obs.measurement = cam.project_stereo(Xc);
    if (noise_px > 0) t.obs.measurement += Eigen::Vector3d(noise(rng), noise(rng), noise(rng));
    out.push_back(t);
  }
  return out;
}

}  // namespace plslam::inertial::test
