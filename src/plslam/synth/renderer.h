#pragma once
// Rasterises a Scene into a radiance image with a z-buffer. Each quad is scanned over its
// projected, near-clipped outline; coverage and texture coordinates at a pixel come from the
// plane homography (exact perspective). Shading is deferred (one texture lookup per visible
// pixel, trilinear mip filtering), and pixels on a boundary between surfaces are re-shaded with
// 4 rotated-grid sub-samples for anti-aliasing.
#include <cstdint>
#include <utility>
#include <vector>

#include <Eigen/Geometry>
#include <opencv2/core.hpp>

#include "plslam/synth/scene.h"

namespace plslam::synth {

struct PinholeCamera {
  int width = 0, height = 0;
  double fx = 0, fy = 0, cx = 0, cy = 0;
};

class Renderer {
 public:
  Renderer(const Scene& scene, const PinholeCamera& camera);

  // Renders the view of a camera with pose T_wc (camera to world; camera x right, y down, z
  // forward). `radiance` becomes CV_32F; `depth` (optional) CV_32F metres along z, 0 where the
  // pixel centre hits nothing.
  void render(const Eigen::Isometry3d& T_wc, cv::Mat& radiance, cv::Mat* depth = nullptr);

  const PinholeCamera& camera() const { return cam_; }

 private:
  // Per-quad linear functions of the pixel position (x, y, 1) in the current view.
  struct QuadView {
    Eigen::Vector3f a, b, w;  // s = a.p / w.p, t = b.p / w.p
    float inv_depth_scale;    // 1/z = (w.p) * inv_depth_scale
  };
  struct Sample {
    float value;
    float inv_depth;
  };

  bool setup_quad(int qi, const Eigen::Matrix3d& R_cw, const Eigen::Vector3d& t_cw, QuadView& qv) const;
  void rasterize(int qi, const Eigen::Matrix3d& R_cw, const Eigen::Vector3d& t_cw);
  struct PointShading {
    float s, t, light;
    int level;
  };
  PointShading point_shading(int qi, float x, float y) const;
  float shade(int qi, float x, float y) const;
  // Shades the pixels [x0, x1) of row y, all showing quad qi.
  void shade_run(int qi, int y, int x0, int x1, float* out) const;
  // Covers (x, y) with quad qi? Returns inverse depth (> 0) or 0.
  float coverage(int qi, float x, float y) const;

  const Scene& scene_;
  PinholeCamera cam_;
  std::vector<QuadView> views_;
  std::vector<std::uint8_t> visible_;
  std::vector<float> inv_depth_;
  std::vector<std::int32_t> id_;
  std::vector<std::uint8_t> edge_;
  std::vector<std::pair<double, int>> order_;
};

}  // namespace plslam::synth
