#include "plslam/synth/sequence.h"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "plslam/core/error.h"
#include "plslam/synth/calibration_scene.h"

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

CameraKind parse_camera_kind(const std::string& name) {
  if (name == "pinhole") return CameraKind::kPinhole;
  if (name == "radtan" || name == "radial-tangential") return CameraKind::kRadialTangential;
  if (name == "equidistant" || name == "fisheye") return CameraKind::kEquidistant;
  throw InputError("", "unknown camera '" + name + "' (expected pinhole, radtan or equidistant)");
}

const char* to_string(CameraKind kind) {
  switch (kind) {
    case CameraKind::kPinhole: return "pinhole";
    case CameraKind::kRadialTangential: return "radtan";
    case CameraKind::kEquidistant: return "equidistant";
  }
  return "?";
}

namespace {

// Radius in focal units at which a ray `angle` radians off the axis lands, without the focal length.
double lens_radius(const geometry::LensCamera& lens, double angle) {
  if (lens.model == geometry::LensModel::kEquidistant) {
    const auto p = lens.project({std::sin(angle), 0, std::cos(angle)});
    return p ? (p->x() - lens.cx) / lens.fx : -1;
  }
  const double t = std::tan(angle), t2 = t * t;
  return t * (1 + lens.coeffs[0] * t2 + lens.coeffs[1] * t2 * t2);
}

// The two lenses of the rig: the preset's focal length, or the one giving --fov along the diagonal.
std::array<geometry::LensCamera, 2> make_lenses(const SequenceOptions& o) {
  const auto& p = o.preset;
  using geometry::LensModel;
  std::array<geometry::LensCamera, 2> lens;
  for (auto& l : lens) l = {LensModel::kRadialTangential, p.width, p.height, p.fx, p.fy, p.cx, p.cy, {}};
  if (o.camera == CameraKind::kRadialTangential) {  // EuRoC MH01's cameras
    lens[0].coeffs = {-0.28, 0.075, 2.0e-4, 1.8e-5};
    lens[1].coeffs = {-0.283, 0.0745, -1.0e-4, -3.6e-5};
  } else if (o.camera == CameraKind::kEquidistant) {  // TUM-VI's cameras
    for (auto& l : lens) l.model = LensModel::kEquidistant;
    lens[0].coeffs = {0.0034823894, 0.00071520687, -0.0020532361, 0.00020293673};
    lens[1].coeffs = {0.0034003170, 0.0017067460, -0.0026303960, 0.00036140430};
  }
  if (o.fov_deg != 0) {
    const double max_fov = o.camera == CameraKind::kEquidistant ? 220 : 160;
    if (!(o.fov_deg >= 20 && o.fov_deg <= max_fov)) {
      throw InputError("", fmt::format("--fov must be in [20, {}] degrees for a {} camera, got {}", max_fov,
                                       to_string(o.camera), o.fov_deg));
    }
    const double radius = lens_radius(lens[0], o.fov_deg * M_PI / 360.0);
    if (!(radius > 0)) throw InputError("", fmt::format("--fov {} is beyond what the lens model can map", o.fov_deg));
    const double f = 0.5 * std::hypot(p.width, p.height) / radius;
    for (auto& l : lens) l.fx = l.fy = f;
  }
  if (o.camera != CameraKind::kPinhole) {
    // Not quite square pixels and off-centre principal points, per camera, as a calibration finds.
    lens[0].fy *= 0.997;
    lens[0].cx -= 8.3;
    lens[0].cy += 8.9;
    lens[1].fx *= 0.9977;
    lens[1].fy *= 0.9947;
    lens[1].cx += 4.5;
    lens[1].cy += 15.7;
  }
  return lens;
}

Eigen::Isometry3d make_rig(const SequenceOptions& o) {
  Eigen::Isometry3d T_lr = Eigen::Isometry3d::Identity();
  T_lr.translation().x() = o.preset.baseline;
  if (o.camera != CameraKind::kPinhole) {
    T_lr.translation() += Eigen::Vector3d(0, -0.0009, 0.0012);
    T_lr.linear() = Eigen::AngleAxisd(0.4 * M_PI / 180, Eigen::Vector3d(0.3, 1.0, -0.2).normalized()).toRotationMatrix();
  }
  return T_lr;
}

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
      scene_(options.scene == SceneKind::kCalibration ? calibration_scene(options.board, options.seed)
                                                       : build_scene(options.scene, options.seed)),
      path_(scene_, choose_speed(scene_, options), options.seed, options.path_seed, options.motion),
      sensor_(options.preset.width, options.preset.height, options.seed),
      lens_(make_lenses(options)),
      T_lr_(make_rig(options)) {
  // Fail here, not in the first frame's renderer, on a lens that folds over inside the image.
  for (const auto& l : lens_) {
    if (!l.max_ray_angle()) {
      throw InputError("", fmt::format("the {} lens with --fov {} folds over inside the image", to_string(options.camera),
                                       options.fov_deg));
    }
  }
  if (options.scene == SceneKind::kCalibration) {
    if (options.motion_blur) throw InputError("--motion-blur", "the calibration scene's frames are still views");
    views_ = calibration_views(options.board, lens_[0], options.frames, options.seed);
  }
}

StereoCalibration Sequence::calibration() const {
  if (options_.camera != CameraKind::kPinhole) {
    throw InputError("", fmt::format("a {} camera has raw images: only the EuRoC layout (sensor.yaml) holds its "
                                     "calibration", to_string(options_.camera)));
  }
  const auto& l = lens_[0];
  StereoCalibration c;
  c.width = l.width;
  c.height = l.height;
  c.fx = l.fx;
  c.fy = l.fy;
  c.cx = l.cx;
  c.cy = l.cy;
  c.baseline = options_.preset.baseline;
  return c;
}

geometry::LensCamera Sequence::lens(int cam) const { return lens_.at(static_cast<std::size_t>(cam)); }

Eigen::Isometry3d Sequence::right_pose(std::size_t i) const { return left_pose(i) * T_lr_; }

StereoRenderer::StereoRenderer(const Sequence& sequence)
    : seq_(sequence), renderers_{LensRenderer(sequence.scene(), sequence.lens(0)), LensRenderer(sequence.scene(), sequence.lens(1))} {}

void StereoRenderer::render_camera(int cam, std::size_t i, cv::Mat& radiance, cv::Mat* depth) {
  const Eigen::Isometry3d T_lr = cam == 0 ? Eigen::Isometry3d::Identity() : seq_.T_left_right();
  LensRenderer& renderer = renderers_[static_cast<std::size_t>(cam)];
  const double t = seq_.time(i);
  if (!seq_.options().motion_blur) {
    renderer.render(seq_.left_pose(i) * T_lr, radiance, depth);
    return;
  }
  // Shutter open for 12 ms around t; as many sub-frames as the fastest image point moves
  // pixels (one per pixel, up to 8), so the blur length follows the motion.
  constexpr double kShutter = 0.012;
  const Eigen::Isometry3d a = seq_.path().pose(t - kShutter / 2), b = seq_.path().pose(t + kShutter / 2);
  const Eigen::Isometry3d d = a.inverse() * b;
  const double angle = Eigen::AngleAxisd(d.rotation()).angle();
  const double pixels = renderer.lens().fx * (angle + d.translation().norm() / 1.5);
  const int n = std::clamp(static_cast<int>(std::ceil(pixels)), 1, 8);
  if (n == 1) {
    renderer.render(seq_.path().pose(t) * T_lr, radiance, depth);
    return;
  }
  renderer.render(seq_.path().pose(t) * T_lr, accum_, depth);  // depth from the mid-exposure pose
  accum_.setTo(0);
  for (int k = 0; k < n; ++k) {
    const double tk = t + kShutter * ((k + 0.5) / n - 0.5);
    renderer.render(seq_.path().pose(tk) * T_lr, radiance, nullptr);
    accum_ += radiance;
  }
  radiance = accum_ * (1.0 / n);
}

StereoImages StereoRenderer::render(std::size_t i, bool with_depth) {
  StereoImages out;
  const double exposure = seq_.sensor().exposure(seq_.time(i));
  // Another path through the scene gets its own sensor noise too.
  const std::uint64_t base = (seq_.options().seed ^ (seq_.options().path_seed << 32)) * 0x100000001B3ULL + i * 2;
  render_camera(0, i, radiance_, with_depth ? &out.left_depth : nullptr);
  seq_.sensor().expose(radiance_, exposure, base, out.left);
  render_camera(1, i, radiance_, with_depth ? &out.right_depth : nullptr);
  seq_.sensor().expose(radiance_, exposure, base + 1, out.right);
  return out;
}

}  // namespace plslam::synth
