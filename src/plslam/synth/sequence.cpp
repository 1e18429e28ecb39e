#include "plslam/synth/sequence.h"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "plslam/core/error.h"

namespace plslam::synth {

// Square pixels and the principal point at the image centre: exactly what stereo rectification
// of an ideal pair produces, so a reader that rectifies sees the images unchanged.
CameraPreset euroc_preset() { return {"euroc", 752, 480, 20.0, 458.0, 458.0, 375.5, 239.5, 0.11}; }
CameraPreset kitti_preset() { return {"kitti", 1241, 376, 10.0, 718.856, 718.856, 620.0, 187.5, 0.54}; }

CameraPreset parse_preset(const std::string& name) {
  if (name == "euroc") return euroc_preset();
  if (name == "kitti") return kitti_preset();
  throw InputError("", "unknown preset '" + name + "' (expected euroc or kitti)");
}

namespace {

double choose_speed(const Scene& scene, const SequenceOptions& o) {
  if (o.frames < 2) throw InputError("", "need at least 2 frames");
  if (!o.loop) return scene.nominal_speed;
  // The whole closed path plus the overlap, travelled again after the return, is covered.
  if (!(o.loop_overlap >= 0 && o.loop_overlap <= 1)) throw InputError("", "--loop-overlap must be in [0, 1]");
  const double covered = 1 + o.loop_overlap;
  const double length = CameraPath(scene, 1.0, o.seed).length();
  const double duration = (o.frames - 1) / o.preset.fps;
  const double speed = length * covered / duration;
  // Leave headroom for the hand-held sway and bobbing on top of the path speed.
  const double limit = scene.vehicle ? scene.max_speed : scene.max_speed - 0.1;
  if (speed > limit) {
    const int needed = static_cast<int>(std::ceil(length * covered / limit * o.preset.fps)) + 1;
    throw InputError("", fmt::format("--loop on the {} scene ({:.0f} m) needs at least {} frames at {} Hz",
                                     to_string(scene.kind), length, needed, o.preset.fps));
  }
  return std::max(speed, scene.vehicle ? 5.0 : 0.6);
}

}  // namespace

Sequence::Sequence(const SequenceOptions& options)
    : options_(options),
      scene_(build_scene(options.scene, options.seed)),
      path_(scene_, choose_speed(scene_, options), options.seed, options.path_seed, options.motion),
      sensor_(options.preset.width, options.preset.height, options.seed) {}

StereoCalibration Sequence::calibration() const {
  const auto& p = options_.preset;
  StereoCalibration c;
  c.width = p.width;
  c.height = p.height;
  c.fx = p.fx;
  c.fy = p.fy;
  c.cx = p.cx;
  c.cy = p.cy;
  c.baseline = p.baseline;
  return c;
}

PinholeCamera Sequence::camera() const {
  const auto& p = options_.preset;
  return {p.width, p.height, p.fx, p.fy, p.cx, p.cy};
}

Eigen::Isometry3d Sequence::right_pose(std::size_t i) const {
  Eigen::Isometry3d T_lr = Eigen::Isometry3d::Identity();
  T_lr.translation().x() = options_.preset.baseline;
  return left_pose(i) * T_lr;
}

StereoRenderer::StereoRenderer(const Sequence& sequence) : seq_(sequence), renderer_(sequence.scene(), sequence.camera()) {}

void StereoRenderer::render_camera(const Eigen::Isometry3d& T_lr, std::size_t i, cv::Mat& radiance, cv::Mat* depth) {
  const double t = seq_.time(i);
  if (!seq_.options().motion_blur) {
    renderer_.render(seq_.path().pose(t) * T_lr, radiance, depth);
    return;
  }
  // Shutter open for 12 ms around t; as many sub-frames as the fastest image point moves
  // pixels (one per pixel, up to 8), so the blur length follows the motion.
  constexpr double kShutter = 0.012;
  const Eigen::Isometry3d a = seq_.path().pose(t - kShutter / 2), b = seq_.path().pose(t + kShutter / 2);
  const Eigen::Isometry3d d = a.inverse() * b;
  const double angle = Eigen::AngleAxisd(d.rotation()).angle();
  const double pixels = seq_.options().preset.fx * (angle + d.translation().norm() / 1.5);
  const int n = std::clamp(static_cast<int>(std::ceil(pixels)), 1, 8);
  if (n == 1) {
    renderer_.render(seq_.path().pose(t) * T_lr, radiance, depth);
    return;
  }
  renderer_.render(seq_.path().pose(t) * T_lr, accum_, depth);  // depth from the mid-exposure pose
  accum_.setTo(0);
  for (int k = 0; k < n; ++k) {
    const double tk = t + kShutter * ((k + 0.5) / n - 0.5);
    renderer_.render(seq_.path().pose(tk) * T_lr, radiance, nullptr);
    accum_ += radiance;
  }
  radiance = accum_ * (1.0 / n);
}

StereoImages StereoRenderer::render(std::size_t i, bool with_depth) {
  StereoImages out;
  Eigen::Isometry3d T_lr = Eigen::Isometry3d::Identity();
  const double exposure = seq_.sensor().exposure(seq_.time(i));
  // Another path through the scene gets its own sensor noise too.
  const std::uint64_t base = (seq_.options().seed ^ (seq_.options().path_seed << 32)) * 0x100000001B3ULL + i * 2;
  render_camera(T_lr, i, radiance_, with_depth ? &out.left_depth : nullptr);
  seq_.sensor().expose(radiance_, exposure, base, out.left);
  T_lr.translation().x() = seq_.options().preset.baseline;
  render_camera(T_lr, i, radiance_, with_depth ? &out.right_depth : nullptr);
  seq_.sensor().expose(radiance_, exposure, base + 1, out.right);
  return out;
}

}  // namespace plslam::synth
