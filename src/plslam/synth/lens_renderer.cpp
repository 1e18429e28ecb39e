#include "plslam/synth/lens_renderer.h"

#include <algorithm>
#include <array>
#include <cmath>

#include <fmt/format.h>

#include "plslam/core/error.h"

namespace plslam::synth {
namespace {

// Face resolution over the lens's: a fisheye's periphery has up to theta / sin(theta) times its
// centre's pixels per radian across the radius (1.36 at 75 degrees), which a face edge gives back.
constexpr double kOversample = 1.4;
constexpr int kPad = 2;  // pixels around each face's rays: the bilinear footprint at its edge

// Rotations from each cube face's camera frame to the lens camera's frame; face k looks along
// the lens frame's axis kAxes[k].
std::array<Eigen::Matrix3d, 6> face_rotations() {
  std::array<Eigen::Matrix3d, 6> R;
  const Eigen::Vector3d axes[6] = {Eigen::Vector3d::UnitZ(),  Eigen::Vector3d::UnitX(),  -Eigen::Vector3d::UnitX(),
                                   Eigen::Vector3d::UnitY(),  -Eigen::Vector3d::UnitY(), -Eigen::Vector3d::UnitZ()};
  for (int k = 0; k < 6; ++k) {
    const Eigen::Vector3d z = axes[k];
    // Keep the lens's y (down) as the face's y where possible, so faces are upright.
    const Eigen::Vector3d up = std::abs(z.y()) > 0.5 ? Eigen::Vector3d::UnitZ() : Eigen::Vector3d::UnitY();
    const Eigen::Vector3d x = up.cross(z).normalized();
    const Eigen::Vector3d y = z.cross(x);
    R[k].col(0) = x;
    R[k].col(1) = y;
    R[k].col(2) = z;
  }
  return R;
}

int face_of_ray(const Eigen::Vector3d& r) {
  const Eigen::Vector3d a = r.cwiseAbs();
  if (a.z() >= a.x() && a.z() >= a.y()) return r.z() >= 0 ? 0 : 5;
  if (a.x() >= a.y()) return r.x() >= 0 ? 1 : 2;
  return r.y() >= 0 ? 3 : 4;
}

bool has_distortion(const geometry::LensCamera& lens) {
  return lens.model == geometry::LensModel::kEquidistant ||
         std::any_of(lens.coeffs.begin(), lens.coeffs.end(), [](double c) { return c != 0; });
}

}  // namespace

struct LensRenderer::Face {
  Eigen::Matrix3d R_lens_face;
  std::unique_ptr<Renderer> renderer;
  cv::Mat radiance, depth;
};

LensRenderer::LensRenderer(const Scene& scene, const geometry::LensCamera& lens) : lens_(lens) {
  if (!has_distortion(lens)) {
    direct_ = std::make_unique<Renderer>(scene, PinholeCamera{lens.width, lens.height, lens.fx, lens.fy, lens.cx, lens.cy});
    return;
  }
  const auto R = face_rotations();
  const double f = kOversample * std::max(lens.fx, lens.fy);
  const std::size_t n = static_cast<std::size_t>(lens.width) * lens.height;
  std::vector<Eigen::Vector2d> on_face(n);
  face_of_.resize(n);
  ray_z_scale_.resize(n);
  std::array<Eigen::AlignedBox2d, 6> box;
  for (int y = 0; y < lens.height; ++y) {
    for (int x = 0; x < lens.width; ++x) {
      const std::size_t i = static_cast<std::size_t>(y) * lens.width + x;
      const auto ray = lens.unproject({x, y});
      if (!ray) {
        throw InputError("", fmt::format("the {} lens has no ray at pixel ({}, {}): its distortion folds over inside "
                                         "the image", geometry::to_string(lens.model), x, y));
      }
      const int k = face_of_ray(*ray);
      const Eigen::Vector3d rf = R[k].transpose() * *ray;  // rf.z() >= |rf.x()|, |rf.y()|
      face_of_[i] = static_cast<std::uint8_t>(k);
      on_face[i] = f * rf.head<2>() / rf.z();
      ray_z_scale_[i] = static_cast<float>(ray->z() / rf.z());
      box[k].extend(on_face[i]);
    }
  }
  // One renderer per face that some ray falls on, cropped to those rays.
  std::array<int, 6> index{};
  index.fill(-1);
  std::array<Eigen::Vector2d, 6> origin;
  for (int k = 0; k < 6; ++k) {
    if (box[k].isEmpty()) continue;
    origin[k] = box[k].min().array().floor() - kPad;
    const Eigen::Vector2d size = box[k].max().array().ceil() - origin[k].array() + kPad + 1;
    auto face = std::make_unique<Face>();
    face->R_lens_face = R[k];
    face->renderer = std::make_unique<Renderer>(
        scene, PinholeCamera{static_cast<int>(size.x()), static_cast<int>(size.y()), f, f, -origin[k].x(), -origin[k].y()});
    index[k] = static_cast<int>(faces_.size());
    faces_.push_back(std::move(face));
  }
  fx_.resize(n);
  fy_.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    const int k = face_of_[i];
    face_of_[i] = static_cast<std::uint8_t>(index[k]);
    fx_[i] = static_cast<float>(on_face[i].x() - origin[k].x());
    fy_[i] = static_cast<float>(on_face[i].y() - origin[k].y());
  }
}

LensRenderer::~LensRenderer() = default;

void LensRenderer::render(const Eigen::Isometry3d& T_wc, cv::Mat& radiance, cv::Mat* depth) {
  if (direct_) {
    direct_->render(T_wc, radiance, depth);
    return;
  }
  for (auto& face : faces_) {
    Eigen::Isometry3d T_lens_face = Eigen::Isometry3d::Identity();
    T_lens_face.linear() = face->R_lens_face;
    face->renderer->render(T_wc * T_lens_face, face->radiance, depth ? &face->depth : nullptr);
  }
  const int W = lens_.width, H = lens_.height;
  radiance.create(H, W, CV_32F);
  if (depth) depth->create(H, W, CV_32F);
  for (int y = 0; y < H; ++y) {
    float* out = radiance.ptr<float>(y);
    float* dout = depth ? depth->ptr<float>(y) : nullptr;
    for (int x = 0; x < W; ++x) {
      const std::size_t i = static_cast<std::size_t>(y) * W + x;
      const Face& face = *faces_[face_of_[i]];
      // Pixel centres are at integer positions: bilinear between the four around (fx, fy).
      const float u = fx_[i], v = fy_[i];
      const int u0 = static_cast<int>(u), v0 = static_cast<int>(v);  // non-negative: faces are padded
      const float a = u - static_cast<float>(u0), b = v - static_cast<float>(v0);
      const float* r0 = face.radiance.ptr<float>(v0) + u0;
      const float* r1 = face.radiance.ptr<float>(v0 + 1) + u0;
      out[x] = (1 - b) * ((1 - a) * r0[0] + a * r0[1]) + b * ((1 - a) * r1[0] + a * r1[1]);
      if (dout) {
        // Bilinear on one surface; nearest across an occlusion edge, where interpolating would
        // invent a surface between the two.
        const float* d0 = face.depth.ptr<float>(v0) + u0;
        const float* d1 = face.depth.ptr<float>(v0 + 1) + u0;
        const auto [lo, hi] = std::minmax({d0[0], d0[1], d1[0], d1[1]});
        const float d = lo > 0 && hi < 1.02f * lo
                            ? (1 - b) * ((1 - a) * d0[0] + a * d0[1]) + b * ((1 - a) * d1[0] + a * d1[1])
                            : (b < 0.5f ? d0 : d1)[a < 0.5f ? 0 : 1];
        dout[x] = d * ray_z_scale_[i];
      }
    }
  }
}

}  // namespace plslam::synth
