#pragma once
// Synthetic stereo scenes with exact ground truth for the optimiser tests and benchmarks:
// a camera, world points and 3D segments placed in front of a given pose, and their stereo
// observations (optionally with pixel noise and gross outliers).
#include <cmath>
#include <random>
#include <vector>

#include "plslam/geometry/se3.h"
#include "plslam/geometry/stereo_camera.h"
#include "plslam/optim/observations.h"
#include "plslam/optim/pose_only.h"

namespace plslam::test {

inline geometry::StereoCamera kitti_like_camera() {
  // KITTI 00-02 intrinsics; bf = 0.537 m * fx.
  return geometry::StereoCamera(718.856, 718.856, 607.1928, 185.2157, 386.1448, 1241, 376);
}

inline geometry::SE3 random_pose(std::mt19937& rng, double trans, double rot) {
  std::normal_distribution<double> g(0.0, 1.0);
  geometry::Vector6d xi;
  for (int k = 0; k < 3; ++k) xi(k) = trans * g(rng);
  for (int k = 3; k < 6; ++k) xi(k) = rot * g(rng);
  return geometry::SE3::exp(xi);
}

// World point seen by camera T_cw at pixel uv with depth z.
inline Eigen::Vector3d world_point_at(const geometry::StereoCamera& cam, const geometry::SE3& T_cw,
                                      const Eigen::Vector2d& uv, double z) {
  return T_cw.inverse() * cam.unproject(uv, z);
}

inline Eigen::Vector2d random_pixel(const geometry::StereoCamera& cam, std::mt19937& rng,
                                    double margin = 10.0) {
  std::uniform_real_distribution<double> u(margin, cam.width() - margin);
  std::uniform_real_distribution<double> v(margin, cam.height() - margin);
  return {u(rng), v(rng)};
}

inline double random_depth(std::mt19937& rng, double zmin = 3.0, double zmax = 30.0) {
  // Uniform in inverse depth, like a real scene: many far points, some near ones.
  std::uniform_real_distribution<double> d(1.0 / zmax, 1.0 / zmin);
  return 1.0 / d(rng);
}

struct StereoSegmentObs {
  Eigen::Vector3d left_line, right_line;
};

// Observed left/right image lines of a 3D segment from its (noisy) projected endpoints.
inline optim::StereoLineObservation observe_line(const geometry::StereoCamera& cam,
                                                 const geometry::SE3& T_cw,
                                                 const Eigen::Vector3d& Ps,
                                                 const Eigen::Vector3d& Pe, double noise_px,
                                                 std::mt19937& rng) {
  std::normal_distribution<double> g(0.0, noise_px);
  const Eigen::Vector3d s = cam.project_stereo(T_cw * Ps);
  const Eigen::Vector3d e = cam.project_stereo(T_cw * Pe);
  optim::StereoLineObservation o;
  // Each image detects its own segment: independent endpoint noise left and right.
  o.left_line = geometry::line_through({s(0) + g(rng), s(1) + g(rng)}, {e(0) + g(rng), e(1) + g(rng)});
  o.right_line = geometry::line_through({s(2) + g(rng), s(1) + g(rng)}, {e(2) + g(rng), e(1) + g(rng)});
  return o;
}

inline optim::StereoPointObservation observe_point(const geometry::StereoCamera& cam,
                                                   const geometry::SE3& T_cw,
                                                   const Eigen::Vector3d& X, double noise_px,
                                                   std::mt19937& rng) {
  std::normal_distribution<double> g(0.0, noise_px);
  const Eigen::Vector3d p = cam.project_stereo(T_cw * X);
  optim::StereoPointObservation o;
  o.measurement = {p(0) + g(rng), p(1) + g(rng), p(2) + g(rng)};
  return o;
}

// A random 3D segment fully visible from T_cw: both endpoints inside the image, 40-300 px long.
inline std::pair<Eigen::Vector3d, Eigen::Vector3d> random_segment(const geometry::StereoCamera& cam,
                                                                  const geometry::SE3& T_cw,
                                                                  std::mt19937& rng) {
  std::uniform_real_distribution<double> ang(0.0, 2.0 * M_PI), len(40.0, 300.0), dz(-0.3, 0.3);
  for (;;) {
    const Eigen::Vector2d a = random_pixel(cam, rng, 20.0);
    const double t = ang(rng), l = len(rng);
    const Eigen::Vector2d b = a + l * Eigen::Vector2d(std::cos(t), std::sin(t));
    if (!cam.in_image(b, 20.0)) continue;
    const double za = random_depth(rng, 3.0, 25.0);
    const double zb = za * (1.0 + dz(rng));
    return {world_point_at(cam, T_cw, a, za), world_point_at(cam, T_cw, b, zb)};
  }
}

// Pose-only test frame: terms observed from T_true, `outlier_ratio` of them replaced by gross
// mismatches (observations of a random other location, 20-100 px away).
struct PoseOnlyScene {
  std::vector<optim::PosePointTerm> points;
  std::vector<optim::PoseLineTerm> lines;
  std::vector<bool> point_is_outlier, line_is_outlier;
};

inline PoseOnlyScene make_pose_only_scene(const geometry::StereoCamera& cam,
                                          const geometry::SE3& T_true, int n_points, int n_lines,
                                          double noise_px, double outlier_ratio, std::mt19937& rng) {
  PoseOnlyScene s;
  std::uniform_real_distribution<double> unit(0.0, 1.0), off(20.0, 100.0), ang(0.0, 2.0 * M_PI);
  const auto jump = [&] {
    const double a = ang(rng), r = off(rng);
    return Eigen::Vector2d(r * std::cos(a), r * std::sin(a));
  };
  for (int i = 0; i < n_points; ++i) {
    const Eigen::Vector3d X = world_point_at(cam, T_true, random_pixel(cam, rng), random_depth(rng));
    optim::PosePointTerm t{X, observe_point(cam, T_true, X, noise_px, rng)};
    const bool out = unit(rng) < outlier_ratio;
    if (out) {
      const Eigen::Vector2d j = jump();
      t.obs.measurement += Eigen::Vector3d(j.x(), j.y(), j.x());
    }
    s.points.push_back(t);
    s.point_is_outlier.push_back(out);
  }
  for (int i = 0; i < n_lines; ++i) {
    const auto [Ps, Pe] = random_segment(cam, T_true, rng);
    optim::PoseLineTerm t{Ps, Pe, observe_line(cam, T_true, Ps, Pe, noise_px, rng)};
    const bool out = unit(rng) < outlier_ratio;
    if (out) {
      // A mismatched line: a different segment's observation, shifted away.
      const auto [Qs, Qe] = random_segment(cam, T_true, rng);
      t.obs = observe_line(cam, T_true, Qs, Qe, noise_px, rng);
      const Eigen::Vector2d j = jump();
      t.obs.left_line(2) -= t.obs.left_line.head<2>().dot(j);
      t.obs.right_line(2) -= t.obs.right_line.head<2>().dot(j);
    }
    s.lines.push_back(t);
    s.line_is_outlier.push_back(out);
  }
  return s;
}

inline double rotation_error_deg(const geometry::SE3& A, const geometry::SE3& B) {
  return geometry::so3_log(A.rotation() * B.rotation().transpose()).norm() * 180.0 / M_PI;
}

// Camera-centre distance between two T_cw poses.
inline double centre_error(const geometry::SE3& A, const geometry::SE3& B) {
  return (A.inverse().translation() - B.inverse().translation()).norm();
}

}  // namespace plslam::test

#include "plslam/optim/bundle_adjustment.h"

namespace plslam::test {

// A forward-moving stereo rig (about 1 m between keyframes, gentle yaw) observing points and
// segments; every landmark is observed by every keyframe that sees it inside the image.
struct BaScene {
  std::vector<geometry::SE3> poses_true;
  std::vector<Eigen::Vector3d> points_true;
  std::vector<geometry::Segment3d> lines_true;
  optim::BaProblem problem;  // observations exact; initial state = ground truth (perturb it)
};

inline BaScene make_ba_scene(const geometry::StereoCamera& cam, int n_keyframes, int n_points,
                             int n_lines, std::mt19937& rng) {
  BaScene s;
  for (int k = 0; k < n_keyframes; ++k) {
    const double yaw = 0.03 * k;
    geometry::Vector6d xi;
    xi << 0.2 * std::sin(0.5 * k), 0.05 * k, 1.0 * k, 0.0, yaw, 0.01 * k;
    // xi parameterises T_wc; the problem wants T_cw.
    const geometry::SE3 T_wc(geometry::so3_exp(xi.tail<3>()), xi.head<3>());
    s.poses_true.push_back(T_wc.inverse());
    s.problem.keyframes.push_back({T_wc.inverse(), false});
  }
  std::uniform_int_distribution<int> pick(0, n_keyframes - 1);
  const auto visible = [&](const geometry::SE3& T, const Eigen::Vector3d& X) {
    const Eigen::Vector3d Xc = T * X;
    return Xc.z() > 0.5 && cam.in_image(cam.project(Xc), 1.0) &&
           cam.in_image({cam.project_stereo(Xc)(2), cam.project(Xc).y()}, 1.0);
  };
  while (static_cast<int>(s.points_true.size()) < n_points) {
    const int k0 = pick(rng);
    const Eigen::Vector3d X = world_point_at(cam, s.poses_true[static_cast<std::size_t>(k0)],
                                             random_pixel(cam, rng), random_depth(rng, 3.0, 40.0));
    std::vector<int> seen;
    for (int k = 0; k < n_keyframes; ++k) {
      if (visible(s.poses_true[static_cast<std::size_t>(k)], X)) seen.push_back(k);
    }
    if (seen.size() < 2) continue;
    const int id = static_cast<int>(s.points_true.size());
    s.points_true.push_back(X);
    s.problem.points.push_back({X, false});
    for (const int k : seen) {
      optim::StereoPointObservation o = observe_point(cam, s.poses_true[static_cast<std::size_t>(k)], X, 0.0, rng);
      o.keyframe = k;
      o.point = id;
      s.problem.point_observations.push_back(o);
    }
  }
  while (static_cast<int>(s.lines_true.size()) < n_lines) {
    const int k0 = pick(rng);
    const auto [A, B] = random_segment(cam, s.poses_true[static_cast<std::size_t>(k0)], rng);
    std::vector<int> seen;
    for (int k = 0; k < n_keyframes; ++k) {
      const auto& T = s.poses_true[static_cast<std::size_t>(k)];
      if (visible(T, A) && visible(T, B)) seen.push_back(k);
    }
    if (seen.size() < 2) continue;
    const int id = static_cast<int>(s.lines_true.size());
    s.lines_true.push_back({A, B});
    s.problem.lines.push_back({A, B, false});
    for (const int k : seen) {
      optim::StereoLineObservation o = observe_line(cam, s.poses_true[static_cast<std::size_t>(k)], A, B, 0.0, rng);
      o.keyframe = k;
      o.line = id;
      s.problem.line_observations.push_back(o);
    }
  }
  return s;
}

// Noisy initial state: poses off by ~trans / rot, landmarks by ~landmark_noise metres.
inline void perturb(optim::BaProblem* p, double trans, double rot, double landmark_noise,
                    std::mt19937& rng) {
  std::normal_distribution<double> g(0.0, landmark_noise);
  for (auto& kf : p->keyframes) {
    if (!kf.fixed) kf.T_cw = random_pose(rng, trans, rot) * kf.T_cw;
  }
  for (auto& pt : p->points) pt.position += Eigen::Vector3d(g(rng), g(rng), g(rng));
  for (auto& l : p->lines) {
    l.start += Eigen::Vector3d(g(rng), g(rng), g(rng));
    l.end += Eigen::Vector3d(g(rng), g(rng), g(rng));
  }
}

}  // namespace plslam::test
