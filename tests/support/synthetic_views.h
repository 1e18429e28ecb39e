#pragma once
// Frames and keyframes with exact ground truth, for the tests of local mapping and tracking: world
// points and segments with fixed random descriptors, seen by cameras at chosen poses. Keypoints sit
// at the exact projections (as floats), with the exact stereo depth; nothing is rendered or
// extracted, so every number the code under test sees is known.
#include <array>
#include <cstdint>
#include <cstring>
#include <map>
#include <memory>
#include <optional>
#include <random>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "plslam/geometry/se3.h"
#include "plslam/geometry/stereo_camera.h"
#include "plslam/map/map.h"

namespace plslam::test {

// 640x480, fx = fy = 400, baseline 0.1 m: 40 baselines (the "close" depth) are 4 m.
inline StereoCalibration small_calibration() {
  StereoCalibration c;
  c.width = 640;
  c.height = 480;
  c.fx = c.fy = 400;
  c.cx = 320;
  c.cy = 240;
  c.baseline = 0.1;
  return c;
}

// T_cw of a camera at `centre` looking along +z of the world (no rotation).
inline geometry::SE3 camera_at(const Eigen::Vector3d& centre) {
  return geometry::SE3(Eigen::Matrix3d::Identity(), -centre);
}

using Descriptor = std::array<std::uint8_t, 32>;

struct SyntheticWorld {
  StereoCalibration calib = small_calibration();
  std::vector<Eigen::Vector3d> points;
  std::vector<Descriptor> point_descriptors;
  std::vector<std::pair<Eigen::Vector3d, Eigen::Vector3d>> segments;
  std::vector<Descriptor> segment_descriptors;
  std::mt19937_64 rng{7};

  Descriptor random_descriptor() {
    Descriptor d;
    for (auto& b : d) b = static_cast<std::uint8_t>(rng() & 0xff);
    return d;
  }
  int add_point(const Eigen::Vector3d& X) {
    points.push_back(X);
    point_descriptors.push_back(random_descriptor());
    return static_cast<int>(points.size()) - 1;
  }
  // The point seen by camera T_cw at pixel uv and depth z.
  int add_point_seen_at(const geometry::SE3& T_cw, const Eigen::Vector2d& uv, double z) {
    return add_point(T_cw.inverse() * camera().unproject(uv, z));
  }
  int add_segment(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
    segments.emplace_back(a, b);
    segment_descriptors.push_back(random_descriptor());
    return static_cast<int>(segments.size()) - 1;
  }
  geometry::StereoCamera camera() const { return geometry::StereoCamera(calib); }

  struct View {
    std::shared_ptr<map::FrameData> data;
    std::vector<int> point_of;    // keypoint -> world point
    std::vector<int> segment_of;  // line -> world segment
  };

  // What camera T_cw sees: every world point in front of it and inside the image (or only those
  // listed in `only`), at its exact projection, with a stereo depth when `stereo`; and every
  // segment whose endpoints are both in view, as a stereo line when `stereo`. `octave` is the
  // pyramid level of every keypoint.
  View observe(const geometry::SE3& T_cw, long frame_id, bool stereo = true,
               const std::optional<std::vector<int>>& only = std::nullopt, int octave = 0) const {
    const auto cam = camera();
    View v;
    v.data = std::make_shared<map::FrameData>();
    auto& d = *v.data;
    d.frame_id = frame_id;
    d.timestamp = 0.05 * static_cast<double>(frame_id);
    d.calib = calib;
    std::vector<int> candidates;
    if (only) {
      candidates = *only;
    } else {
      for (std::size_t i = 0; i < points.size(); ++i) candidates.push_back(static_cast<int>(i));
    }
    std::vector<const Descriptor*> rows;
    for (int w : candidates) {
      const Eigen::Vector3d Xc = T_cw * points[static_cast<std::size_t>(w)];
      if (Xc.z() <= 0.1) continue;
      const Eigen::Vector3d s = cam.project_stereo(Xc);
      if (!cam.in_image(s.head<2>(), 1)) continue;
      d.keypoints.emplace_back(cv::Point2f(static_cast<float>(s.x()), static_cast<float>(s.y())), 31.f, 0.f, 1.f,
                               octave);
      d.u_right.push_back(stereo && s.z() >= 0 ? static_cast<float>(s.z()) : -1.f);
      d.depth.push_back(stereo && s.z() >= 0 ? static_cast<float>(Xc.z()) : -1.f);
      rows.push_back(&point_descriptors[static_cast<std::size_t>(w)]);
      v.point_of.push_back(w);
    }
    d.descriptors = to_mat(rows);
    std::vector<const Descriptor*> line_rows;
    for (std::size_t k = 0; k < segments.size(); ++k) {
      const Eigen::Vector3d a = T_cw * segments[k].first, b = T_cw * segments[k].second;
      if (a.z() <= 0.1 || b.z() <= 0.1) continue;
      const Eigen::Vector3d sa = cam.project_stereo(a), sb = cam.project_stereo(b);
      if (!cam.in_image(sa.head<2>(), 1) || !cam.in_image(sb.head<2>(), 1)) continue;
      map::LineObservation l;
      l.segment.start = cv::Point2f(static_cast<float>(sa.x()), static_cast<float>(sa.y()));
      l.segment.end = cv::Point2f(static_cast<float>(sb.x()), static_cast<float>(sb.y()));
      l.left_line = geometry::line_through(sa.head<2>(), sb.head<2>());
      l.right_line = geometry::line_through({sa.z(), sa.y()}, {sb.z(), sb.y()});
      l.stereo = stereo;
      if (stereo) {
        l.start_cam = a;
        l.end_cam = b;
      }
      d.lines.push_back(l);
      line_rows.push_back(&segment_descriptors[k]);
      v.segment_of.push_back(static_cast<int>(k));
    }
    d.line_descriptors = to_mat(line_rows);
    d.build_grid();
    return v;
  }

  static cv::Mat to_mat(const std::vector<const Descriptor*>& rows) {
    cv::Mat m(static_cast<int>(rows.size()), 32, CV_8U);
    for (std::size_t i = 0; i < rows.size(); ++i) std::memcpy(m.ptr(static_cast<int>(i)), rows[i]->data(), 32);
    return m;
  }
};

// A map over a SyntheticWorld: keyframes made from views, and one map point (line) per world
// point (segment), at its true position, made by the first keyframe that observes it.
struct SyntheticMap {
  SyntheticWorld world;
  map::Map map;
  std::map<map::KeyFrame*, SyntheticWorld::View> views;
  std::map<int, map::MapPoint*> point;  // world point -> its map point
  std::map<int, map::MapLine*> line;    // world segment -> its map line

  map::KeyFrame* add_keyframe(const geometry::SE3& T_cw, bool stereo = true,
                              const std::optional<std::vector<int>>& only = std::nullopt, int octave = 0) {
    auto view = world.observe(T_cw, static_cast<long>(views.size()), stereo, only, octave);
    map::KeyFrame* kf = map.create_keyframe(view.data, T_cw);
    views.emplace(kf, std::move(view));
    return kf;
  }

  // The keypoint of `kf` that shows world point w, or -1.
  int keypoint_of(map::KeyFrame* kf, int w) const {
    const auto& of = views.at(kf).point_of;
    for (std::size_t i = 0; i < of.size(); ++i) {
      if (of[i] == w) return static_cast<int>(i);
    }
    return -1;
  }
  int line_of(map::KeyFrame* kf, int s) const {
    const auto& of = views.at(kf).segment_of;
    for (std::size_t i = 0; i < of.size(); ++i) {
      if (of[i] == s) return static_cast<int>(i);
    }
    return -1;
  }

  // `kf` observes world point w (which it must see): its map point, made here if it has none yet.
  map::MapPoint* observe_point(map::KeyFrame* kf, int w) {
    const int i = keypoint_of(kf, w);
    if (i < 0) return nullptr;
    map::MapPoint*& mp = point[w];
    if (!mp) mp = map.create_point(world.points[static_cast<std::size_t>(w)], kf, kf->frame_id());
    mp->add_observation(kf, i);
    kf->add_map_point(mp, i);
    mp->update_descriptor();
    mp->update_normal_and_depth();
    return mp;
  }
  map::MapLine* observe_line(map::KeyFrame* kf, int s) {
    const int j = line_of(kf, s);
    if (j < 0) return nullptr;
    map::MapLine*& ml = line[s];
    const auto& seg = world.segments[static_cast<std::size_t>(s)];
    if (!ml) ml = map.create_line(seg.first, seg.second, kf, kf->frame_id());
    ml->add_observation(kf, j);
    kf->add_map_line(ml, j);
    ml->update_descriptor();
    ml->update_normal_and_depth();
    return ml;
  }
  // Observes each of `ws` and updates the covisibility graph.
  void observe_points(map::KeyFrame* kf, const std::vector<int>& ws) {
    for (int w : ws) observe_point(kf, w);
    kf->update_connections();
  }
};

// 0, 1, ..., n - 1 shifted by `first`.
inline std::vector<int> range(int first, int n) {
  std::vector<int> v;
  for (int i = 0; i < n; ++i) v.push_back(first + i);
  return v;
}

}  // namespace plslam::test
