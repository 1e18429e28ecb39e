#include "plslam/mapping/landmark_triangulation.h"

#include <algorithm>
#include <cmath>

#include "plslam/features/orb_descriptor.h"
#include "plslam/geometry/stereo_camera.h"
#include "plslam/geometry/triangulation.h"
#include "plslam/mapping/epipolar_index.h"

namespace plslam::mapping {
namespace {

constexpr double kChi2Mono = 5.991;     // 2 DoF, 95 %: reprojection error of a keypoint
constexpr double kChi2Epipolar = 3.84;  // 1 DoF, 95 %: distance of a keypoint to its epipolar line

// Points: each free keypoint of kf1 (free in `points1`, kf1's associations before any pair, and
// still free now) with its nearest free keypoint of kf2 near its epipolar line.
void triangulate_points(map::Map& map, map::KeyFrame& kf1, map::KeyFrame& kf2,
                        const std::vector<map::MapPoint*>& points1, const TriangulationOptions& o,
                        std::vector<map::MapPoint*>& created) {
  const auto& d1 = kf1.data();
  const auto& d2 = kf2.data();
  const geometry::StereoCamera cam(d1.calib);
  const geometry::SE3 T1 = kf1.pose();
  const geometry::SE3 T2 = kf2.pose();
  const Eigen::Vector3d O1 = kf1.camera_center();
  const Eigen::Vector3d O2 = kf2.camera_center();
  const auto points2 = kf2.map_points();
  // Fundamental matrix F12 (x1^T F12 x2 = 0) from the relative pose, for the epipolar check.
  const geometry::SE3 T12 = T1 * T2.inverse();
  const Eigen::Matrix3d R12 = T12.rotation();
  const Eigen::Vector3d t12 = T12.translation();
  Eigen::Matrix3d K;
  K << d1.calib.fx, 0, d1.calib.cx, 0, d1.calib.fy, d1.calib.cy, 0, 0, 1;
  const Eigen::Matrix3d Kinv = K.inverse();
  const Eigen::Matrix3d F12 = Kinv.transpose() * geometry::hat(t12) * R12 * Kinv;
  const geometry::SE3 T21 = T12.inverse();
  const Eigen::Vector3d epipole = K * T21.translation();
  const Eigen::Matrix3d H21 = K * T21.rotation() * Kinv;  // x1 -> image-2 direction of its ray
  // Free keypoints of kf2, indexed around the epipole (camera 1's centre seen from camera 2). One
  // index for all levels, read with the widest level's band; the exact test below applies each
  // candidate's own band. One index per level read 8 times as many angular windows per keypoint,
  // and those reads were most of the triangulation's time.
  std::vector<int> free2;
  std::vector<Eigen::Vector2d> free2_position;
  int top_level = 0;
  for (std::size_t j = 0; j < points2.size(); ++j) {
    if (points2[j]) continue;
    free2.push_back(static_cast<int>(j));
    free2_position.emplace_back(d2.keypoints[j].pt.x, d2.keypoints[j].pt.y);
    top_level = std::max(top_level, std::clamp(d2.keypoints[j].octave, 0, d2.levels - 1));
  }
  // The epipolar test's gate below at the widest level, plus rounding.
  const EpipolarIndex index(free2_position, epipole, std::sqrt(kChi2Epipolar * d2.level_sigma2(top_level)) + 1e-6);
  std::vector<int> candidates;
  std::vector<bool> used2(points2.size(), false);
  for (std::size_t i = 0; i < points1.size(); ++i) {
    if (points1[i] || kf1.map_point(static_cast<int>(i))) continue;
    const auto& kp1 = d1.keypoints[i];
    const Eigen::Vector3d x1(kp1.pt.x, kp1.pt.y, 1.0);
    const Eigen::Vector3d epiline = F12.transpose() * x1;  // line in image 2
    const double norm = std::hypot(epiline.x(), epiline.y());
    int best = o.point_max_hamming, best_j = -1;
    EpipolarIndex::Ray ray;
    const bool has_ray = index.ray(H21 * x1, &ray);
    if (has_ray) {
      index.query(ray, &candidates);
    } else {
      index.query_all(&candidates);
    }
    for (int c : candidates) {
      const int j = free2[static_cast<std::size_t>(c)];
      if (used2[static_cast<std::size_t>(j)]) continue;
      const auto& kp2 = d2.keypoints[static_cast<std::size_t>(j)];
      const double dist_epi = std::abs(epiline.x() * kp2.pt.x + epiline.y() * kp2.pt.y + epiline.z()) / norm;
      const double gate2 = kChi2Epipolar * d2.level_sigma2(kp2.octave);
      if (dist_epi * dist_epi > gate2) continue;
      // Only where a depth in front of both cameras projects: the infinite epipolar line also
      // passes behind the epipole and beyond the vanishing point.
      if (has_ray && !index.along_segment(ray, free2_position[static_cast<std::size_t>(c)], std::sqrt(gate2))) continue;
      const int h = features::hamming_distance(d1.descriptors.ptr<uint8_t>(static_cast<int>(i)),
                                               d2.descriptors.ptr<uint8_t>(j));
      if (h < best || (h == best && j < best_j)) {  // ties: the lowest index, whatever the query order
        best = h;
        best_j = j;
      }
    }
    if (best_j < 0) continue;
    const auto& kp2 = d2.keypoints[static_cast<std::size_t>(best_j)];
    // Enough parallax, otherwise stereo depth already did better.
    const Eigen::Vector3d r1 = T1.rotation().transpose() * (Kinv * x1);
    const Eigen::Vector3d r2 = T2.rotation().transpose() * (Kinv * Eigen::Vector3d(kp2.pt.x, kp2.pt.y, 1.0));
    if (r1.normalized().dot(r2.normalized()) > o.max_parallax_cos) continue;
    const auto X = geometry::triangulate_point(cam, T1, T2, {kp1.pt.x, kp1.pt.y}, {kp2.pt.x, kp2.pt.y});
    if (!X) continue;
    const Eigen::Vector3d Xc1 = T1 * *X, Xc2 = T2 * *X;
    if (Xc1.z() <= 0 || Xc2.z() <= 0) continue;
    if ((cam.project(Xc1) - Eigen::Vector2d(kp1.pt.x, kp1.pt.y)).squaredNorm() > kChi2Mono * d1.level_sigma2(kp1.octave)) continue;
    if ((cam.project(Xc2) - Eigen::Vector2d(kp2.pt.x, kp2.pt.y)).squaredNorm() > kChi2Mono * d2.level_sigma2(kp2.octave)) continue;
    // Scale consistency: the distance ratio must agree with the octave ratio.
    const double ratio_dist = (*X - O2).norm() / std::max((*X - O1).norm(), 1e-9);
    const double ratio_octave = d1.level_scale(kp1.octave) / d2.level_scale(kp2.octave);
    if (ratio_dist * o.scale_tolerance * d1.scale_factor < ratio_octave ||
        ratio_dist > ratio_octave * o.scale_tolerance * d1.scale_factor) {
      continue;
    }
    map::MapPoint* mp = map.create_point(*X, &kf1, d1.frame_id);
    mp->add_observation(&kf1, static_cast<int>(i));
    mp->add_observation(&kf2, best_j);
    kf1.add_map_point(mp, static_cast<int>(i));
    kf2.add_map_point(mp, best_j);
    mp->update_descriptor();
    mp->update_normal_and_depth();
    used2[static_cast<std::size_t>(best_j)] = true;
    created.push_back(mp);
  }
}

// Lines not yet in the map (too far for stereo creation): plane intersection with kf2.
void triangulate_lines(map::Map& map, map::KeyFrame& kf1, map::KeyFrame& kf2, const TriangulationOptions& o,
                       std::vector<map::MapLine*>& created) {
  const auto& d1 = kf1.data();
  const auto& d2 = kf2.data();
  const geometry::StereoCamera cam(d1.calib);
  const geometry::SE3 T1 = kf1.pose();
  const geometry::SE3 T2 = kf2.pose();
  const auto lines1 = kf1.map_lines();
  const auto lines2 = kf2.map_lines();
  for (std::size_t a = 0; a < lines1.size(); ++a) {
    if (lines1[a] || kf1.map_line(static_cast<int>(a))) continue;
    int best = o.line_max_hamming, best_b = -1;
    for (std::size_t b = 0; b < lines2.size(); ++b) {
      if (lines2[b]) continue;
      const int h = features::hamming_distance(d1.line_descriptors.ptr<uint8_t>(static_cast<int>(a)),
                                               d2.line_descriptors.ptr<uint8_t>(static_cast<int>(b)));
      if (h < best) {
        best = h;
        best_b = static_cast<int>(b);
      }
    }
    if (best_b < 0) continue;
    const auto& s1 = d1.lines[a].segment;
    const auto& s2 = d2.lines[static_cast<std::size_t>(best_b)].segment;
    const auto seg = geometry::triangulate_line(cam, T1, T2, {{s1.start.x, s1.start.y}, {s1.end.x, s1.end.y}},
                                                {{s2.start.x, s2.start.y}, {s2.end.x, s2.end.y}},
                                                o.line_min_ray_plane_sine);
    if (!seg) continue;
    // The two-view segment must agree with the stereo endpoints of view 1.
    const Eigen::Vector3d s_c = T1 * seg->start, e_c = T1 * seg->end;
    const auto& obs = d1.lines[a];
    if (std::abs(s_c.z() - obs.start_cam.z()) > o.line_depth_tolerance * obs.start_cam.z() ||
        std::abs(e_c.z() - obs.end_cam.z()) > o.line_depth_tolerance * obs.end_cam.z()) {
      continue;
    }
    map::MapLine* ml = map.create_line(seg->start, seg->end, &kf1, d1.frame_id);
    ml->add_observation(&kf1, static_cast<int>(a));
    ml->add_observation(&kf2, best_b);
    kf1.add_map_line(ml, static_cast<int>(a));
    kf2.add_map_line(ml, best_b);
    ml->update_descriptor();
    ml->update_normal_and_depth();
    created.push_back(ml);
  }
}

}  // namespace

NewLandmarks triangulate_new_landmarks(map::Map& map, map::KeyFrame& kf, const TriangulationOptions& o) {
  NewLandmarks out;
  const Eigen::Vector3d O1 = kf.camera_center();
  const double min_distance = o.min_baselines * kf.data().calib.baseline;
  const auto points1 = kf.map_points();
  for (map::KeyFrame* kf2 : kf.best_covisibles(static_cast<std::size_t>(o.neighbors))) {
    // Below the stereo baseline, two-view triangulation adds nothing to the stereo depth.
    if ((kf2->camera_center() - O1).norm() < min_distance) continue;
    triangulate_points(map, kf, *kf2, points1, o, out.points);
    if (o.lines) triangulate_lines(map, kf, *kf2, o, out.lines);
  }
  return out;
}

}  // namespace plslam::mapping
