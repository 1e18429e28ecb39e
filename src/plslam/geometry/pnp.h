#pragma once
// Absolute pose from 3D-2D correspondences: OpenCV's USAC (P3P samples, EPnP on the consensus set,
// local optimisation) with a seeded sampler, followed by an iterative refinement on the inliers.
#include <cstdint>
#include <vector>

#include <Eigen/Core>

#include "plslam/geometry/se3.h"
#include "plslam/geometry/stereo_camera.h"

namespace plslam::geometry {

struct PnpOptions {
  int max_iterations = 300;
  double reprojection_error_px = 2.0;  // RANSAC inlier threshold on the left image
  double confidence = 0.99;
  int min_inliers = 10;
  // The sampler's seed: the same seed and input give the same pose (SystemOptions::seed).
  std::uint32_t seed = 1;
};

struct PnpResult {
  bool success = false;
  SE3 T_cw;
  std::vector<int> inliers;  // indices into the input correspondences
};

// world[i] (world frame) is seen at left-image pixel pixels[i]. Needs at least 4 pairs;
// success is false when RANSAC fails or finds fewer than min_inliers inliers.
PnpResult solve_pnp_ransac(const StereoCamera& cam, const std::vector<Eigen::Vector3d>& world,
                           const std::vector<Eigen::Vector2d>& pixels,
                           const PnpOptions& options = {});

}  // namespace plslam::geometry
