#include "plslam/tracking/projection_search.h"

#include <array>
#include <cmath>
#include <limits>
#include <optional>

#include <opencv2/features2d.hpp>

#include "plslam/core/pointer_set.h"
#include "plslam/features/orb_descriptor.h"
#include "plslam/geometry/stereo_camera.h"
#include "plslam/map/keyframe.h"
#include "plslam/map/line_projection.h"
#include "plslam/map/map_line.h"
#include "plslam/map/map_point.h"

namespace plslam::tracking {
namespace {

bool slot_taken(const Frame& f, int j) {
  const auto* p = f.points[static_cast<std::size_t>(j)];
  return p && p->num_observations() > 0;
}

// Stereo consistency: a keypoint with a right match must also agree in u_r.
bool stereo_consistent(const map::FrameData& d, int j, double u_right, double radius) {
  const float ur = d.u_right[static_cast<std::size_t>(j)];
  return ur < 0 || std::abs(u_right - ur) <= radius;
}

// Where a map point shows in a frame, if the frame can see it (ORB-SLAM2's isInFrustum): in front,
// inside the image, within the point's scale range, and seen less than 60 degrees off its mean
// viewing direction.
struct Visibility {
  Eigen::Vector3d Xc;
  Eigen::Vector2d uv;
  double distance = 0;
  double view_cos = 0;
};

std::optional<Visibility> visibility(const map::MapPoint& mp, const geometry::SE3& T_cw, const Eigen::Vector3d& Ow,
                                     const geometry::StereoCamera& cam) {
  Visibility v;
  const Eigen::Vector3d P = mp.position();
  v.Xc = T_cw * P;
  if (v.Xc.z() <= 0) return std::nullopt;
  v.uv = cam.project(v.Xc);
  if (!cam.in_image(v.uv)) return std::nullopt;
  const Eigen::Vector3d ray = P - Ow;
  v.distance = ray.norm();
  if (v.distance < mp.min_distance() || v.distance > mp.max_distance()) return std::nullopt;
  v.view_cos = ray.dot(mp.normal()) / v.distance;
  if (v.view_cos < 0.5) return std::nullopt;
  return v;
}

}  // namespace

int count_visible_points(const Frame& f, const std::vector<map::MapPoint*>& points) {
  const geometry::StereoCamera cam(f.data->calib);
  const Eigen::Vector3d Ow = f.T_cw.inverse().translation();
  int n = 0;
  for (const map::MapPoint* mp : points) n += mp && !mp->is_bad() && visibility(*mp, f.T_cw, Ow, cam).has_value();
  return n;
}

CellCoverage cell_coverage(const Frame& f, const std::vector<map::MapPoint*>& points, int cols, int rows,
                           int min_points) {
  const auto& d = *f.data;
  const geometry::StereoCamera cam(d.calib);
  const Eigen::Vector3d Ow = f.T_cw.inverse().translation();
  core::PointerSet inliers;
  inliers.clear(f.points.size());
  for (std::size_t i = 0; i < f.points.size(); ++i) {
    if (f.points[i] && !f.point_outlier[i]) inliers.insert(f.points[i]);
  }
  const auto cells = static_cast<std::size_t>(cols * rows);
  std::vector<int> visible(cells, 0), matched(cells, 0);
  for (const map::MapPoint* mp : points) {
    if (!mp || mp->is_bad()) continue;
    const auto v = visibility(*mp, f.T_cw, Ow, cam);
    if (!v) continue;
    const int c = std::clamp(static_cast<int>(v->uv.x() * cols / d.calib.width), 0, cols - 1);
    const int r = std::clamp(static_cast<int>(v->uv.y() * rows / d.calib.height), 0, rows - 1);
    const auto k = static_cast<std::size_t>(r * cols + c);
    ++visible[k];
    if (inliers.contains(mp)) ++matched[k];
  }
  CellCoverage out;
  for (std::size_t k = 0; k < cells; ++k) {
    if (visible[k] < min_points) continue;
    ++out.predicted;
    out.covered += matched[k] > 0;
  }
  return out;
}

int search_points_from_frame(Frame& cur, const Frame& last, double radius, const SearchOptions& o) {
  const auto& d = *cur.data;
  const geometry::StereoCamera cam(d.calib);
  int matches = 0;
  for (std::size_t i = 0; i < last.points.size(); ++i) {
    map::MapPoint* mp = last.points[i];
    if (!mp || last.point_outlier[i] || mp->is_bad()) continue;
    const Eigen::Vector3d Xc = cur.T_cw * mp->position();
    if (Xc.z() <= 0) continue;
    const Eigen::Vector2d uv = cam.project(Xc);
    if (!cam.in_image(uv)) continue;
    const int level = last.data->keypoints[i].octave;
    const double r = radius * d.level_scale(level);
    const auto candidates = d.points_in_area(uv.x(), uv.y(), r, std::max(0, level - 1), level + 1);
    if (candidates.empty()) continue;
    std::array<uint8_t, 32> desc;
    if (!mp->copy_descriptor(desc)) continue;
    const double u_right = uv.x() - cam.bf() / Xc.z();
    int best = std::numeric_limits<int>::max(), second = best, best_j = -1;
    for (int j : candidates) {
      if (slot_taken(cur, j) || !stereo_consistent(d, j, u_right, r)) continue;
      const int dist = features::hamming_distance(desc.data(), d.descriptors.ptr<uint8_t>(j));
      if (dist < best) {
        second = best;
        best = dist;
        best_j = j;
      } else if (dist < second) {
        second = dist;
      }
    }
    // Low-threshold FAST packs many similar corners into a window: without the ratio test the
    // nearest look-alike of the predicted position wins, which drags the pose towards the motion
    // model's prediction and makes the velocity run away.
    if (best_j >= 0 && best <= o.point_max_hamming && best < o.point_ratio * second) {
      cur.points[static_cast<std::size_t>(best_j)] = mp;
      cur.point_outlier[static_cast<std::size_t>(best_j)] = false;
      ++matches;
    }
  }
  return matches;
}

int search_points_in_local_map(Frame& cur, const std::vector<map::MapPoint*>& candidates_in, double radius,
                               const SearchOptions& o) {
  const auto& d = *cur.data;
  const geometry::StereoCamera cam(d.calib);
  core::PointerSet already;
  already.assign(cur.points);
  const geometry::SE3 T_wc = cur.T_cw.inverse();
  const Eigen::Vector3d Ow = T_wc.translation();
  int matches = 0;
  for (map::MapPoint* mp : candidates_in) {
    if (!mp || mp->is_bad() || already.contains(mp)) continue;
    const auto v = visibility(*mp, cur.T_cw, Ow, cam);
    if (!v) continue;
    const Eigen::Vector3d& Xc = v->Xc;
    const Eigen::Vector2d& uv = v->uv;
    const double dist = v->distance, view_cos = v->view_cos;
    mp->increase_visible();
    const int level = mp->predict_level(dist, d.levels, d.scale_factor);
    const double r = radius * (view_cos > 0.998 ? 2.5 : 4.0) * d.level_scale(level);
    const auto candidates = d.points_in_area(uv.x(), uv.y(), r, std::max(0, level - 1), level);
    if (candidates.empty()) continue;
    std::array<uint8_t, 32> desc;
    if (!mp->copy_descriptor(desc)) continue;
    const double u_right = uv.x() - cam.bf() / Xc.z();
    int best = std::numeric_limits<int>::max(), second = best, best_j = -1, best_level = -1, second_level = -1;
    for (int j : candidates) {
      if (slot_taken(cur, j) || !stereo_consistent(d, j, u_right, r)) continue;
      const int dist_h = features::hamming_distance(desc.data(), d.descriptors.ptr<uint8_t>(j));
      const int lvl = d.keypoints[static_cast<std::size_t>(j)].octave;
      if (dist_h < best) {
        second = best;
        second_level = best_level;
        best = dist_h;
        best_level = lvl;
        best_j = j;
      } else if (dist_h < second) {
        second = dist_h;
        second_level = lvl;
      }
    }
    if (best_j < 0 || best > o.point_max_hamming) continue;
    if (best_level == second_level && best > o.point_ratio * second) continue;
    cur.points[static_cast<std::size_t>(best_j)] = mp;
    cur.point_outlier[static_cast<std::size_t>(best_j)] = false;
    already.insert(mp);
    ++matches;
  }
  return matches;
}

int search_lines(Frame& cur, const std::vector<map::MapLine*>& candidates, double radius, const SearchOptions& o) {
  const auto& d = *cur.data;
  if (d.lines.empty()) return 0;
  const geometry::StereoCamera cam(d.calib);
  core::PointerSet already;
  already.assign(cur.lines);
  const map::LineMatchGate gate{radius, o.line_max_angle_deg, o.line_min_overlap};
  // Frame lines already matched to a map line with observations are taken.
  const auto taken = [&cur](std::size_t j) { return cur.lines[j] && cur.lines[j]->num_observations() > 0; };
  int matches = 0;
  for (map::MapLine* ml : candidates) {
    if (!ml || ml->is_bad() || already.contains(ml)) continue;
    const auto projected = map::project_line(cam, cur.T_cw, *ml);
    if (!projected) continue;
    const cv::Mat desc = ml->descriptor();
    if (desc.empty()) continue;
    ml->increase_visible();
    int best = 0;
    const int best_j = map::best_line_match(d, *projected, desc, gate, taken, &best);
    if (best_j >= 0 && best <= o.line_max_hamming) {
      cur.lines[static_cast<std::size_t>(best_j)] = ml;
      cur.line_outlier[static_cast<std::size_t>(best_j)] = false;
      already.insert(ml);
      ++matches;
    }
  }
  return matches;
}

int match_to_keyframe(Frame& cur, const map::KeyFrame& kf, double ratio, const SearchOptions& o) {
  int matches = 0;
  const auto& d = *cur.data;
  cv::BFMatcher matcher(cv::NORM_HAMMING);
  // Points.
  {
    std::vector<map::MapPoint*> pts;
    cv::Mat descs;
    for (auto* p : kf.map_points()) {
      if (!p || p->is_bad()) continue;
      const cv::Mat dsc = p->descriptor();
      if (dsc.empty()) continue;
      pts.push_back(p);
      descs.push_back(dsc);
    }
    if (!pts.empty() && !d.descriptors.empty()) {
      std::vector<std::vector<cv::DMatch>> knn;
      matcher.knnMatch(descs, d.descriptors, knn, 2);
      for (const auto& m : knn) {
        if (m.empty() || m[0].distance > 50) continue;  // ORB-SLAM2's TH_LOW
        if (m.size() > 1 && m[0].distance > ratio * m[1].distance) continue;
        auto& slot = cur.points[static_cast<std::size_t>(m[0].trainIdx)];
        if (slot) continue;
        slot = pts[static_cast<std::size_t>(m[0].queryIdx)];
        ++matches;
      }
    }
  }
  // Lines.
  {
    std::vector<map::MapLine*> ls;
    cv::Mat descs;
    for (auto* l : kf.map_lines()) {
      if (!l || l->is_bad()) continue;
      const cv::Mat dsc = l->descriptor();
      if (dsc.empty()) continue;
      ls.push_back(l);
      descs.push_back(dsc);
    }
    if (!ls.empty() && !d.line_descriptors.empty()) {
      std::vector<std::vector<cv::DMatch>> knn;
      matcher.knnMatch(descs, d.line_descriptors, knn, 2);
      for (const auto& m : knn) {
        if (m.empty() || m[0].distance > o.line_max_hamming) continue;
        if (m.size() > 1 && m[0].distance > ratio * m[1].distance) continue;
        auto& slot = cur.lines[static_cast<std::size_t>(m[0].trainIdx)];
        if (slot) continue;
        slot = ls[static_cast<std::size_t>(m[0].queryIdx)];
        ++matches;
      }
    }
  }
  return matches;
}

}  // namespace plslam::tracking
