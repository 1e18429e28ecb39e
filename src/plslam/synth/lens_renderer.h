#pragma once
// Renders what a camera with a lens model (radial-tangential, or an equidistant fisheye of up to
// about 270 degrees) sees. The rasteriser draws pinhole views only, so the camera's rays are split
// among the six 90-degree faces of a cube around it; each face used is rendered as a pinhole view
// cropped to its rays, with a little more resolution than the lens has anywhere, and each output
// pixel reads its ray's face bilinearly. A lens without distortion is rendered directly.
#include <memory>
#include <vector>

#include <Eigen/Geometry>
#include <opencv2/core.hpp>

#include "plslam/geometry/lens_model.h"
#include "plslam/synth/renderer.h"
#include "plslam/synth/scene.h"

namespace plslam::synth {

class LensRenderer {
 public:
  // Throws InputError when a pixel of the lens has no ray (a distortion that folds over).
  LensRenderer(const Scene& scene, const geometry::LensCamera& lens);
  ~LensRenderer();
  LensRenderer(const LensRenderer&) = delete;
  LensRenderer& operator=(const LensRenderer&) = delete;

  // As Renderer::render, for the lens camera with pose T_wc: `radiance` CV_32F of the lens's size,
  // `depth` (optional) CV_32F metres along the optical axis, 0 where the ray hits nothing.
  void render(const Eigen::Isometry3d& T_wc, cv::Mat& radiance, cv::Mat* depth = nullptr);

  const geometry::LensCamera& lens() const { return lens_; }
  int faces() const { return static_cast<int>(faces_.size()); }

 private:
  struct Face;
  geometry::LensCamera lens_;
  std::unique_ptr<Renderer> direct_;  // a lens without distortion
  std::vector<std::unique_ptr<Face>> faces_;
  // Per output pixel: the face its ray falls on, and the position in that face's image.
  std::vector<std::uint8_t> face_of_;
  std::vector<float> fx_, fy_;
  std::vector<float> ray_z_scale_;  // face depth -> depth along the lens's optical axis
};

}  // namespace plslam::synth
