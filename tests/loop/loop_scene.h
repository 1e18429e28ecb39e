#pragma once
// A map with exact ground truth for the loop tests: a camera circles inside a cylinder of textured
// points, looking outward, one and a half times. The second lap's keyframes and points carry a
// drift (3 degrees of yaw and 36 cm) and are new map points, as if tracking had not recognised
// the place: exactly what loop closing must find, measure and remove.
#include <cmath>
#include <map>
#include <memory>
#include <mutex>
#include <numbers>
#include <random>

#include "place/synthetic_descriptors.h"
#include "plslam/geometry/stereo_camera.h"
#include "plslam/map/map.h"
#include "plslam/place/keyframe_database.h"
#include "plslam/place/vocabulary_training.h"

namespace plslam::loop::test {

using place::Descriptor256;

constexpr int kPerLap = 45;  // a keyframe every 8 degrees
constexpr int kKeyframes = kPerLap + kPerLap / 2;

inline StereoCalibration calibration() {
  StereoCalibration c;
  c.width = 640;
  c.height = 480;
  c.fx = c.fy = 400;
  c.cx = 320;
  c.cy = 240;
  c.baseline = 0.5;  // 17 px of disparity at 12 m: depth well constrained for BA
  return c;
}

// The true T_cw of keyframe k: on a 6 m circle at angle 8k degrees, looking outward.
inline geometry::SE3 true_pose(int k) {
  const double a = k * 2 * std::numbers::pi / kPerLap;
  const Eigen::Vector3d z(std::cos(a), std::sin(a), 0), y(0, 0, -1), c = 6 * z;
  Eigen::Matrix3d R_wc;
  R_wc.col(0) = y.cross(z);
  R_wc.col(1) = y;
  R_wc.col(2) = z;
  return geometry::SE3(R_wc, c).inverse();
}

// What the second lap's map believes: the world moved by 3 degrees of yaw and (0.3, 0.2, 0) m.
inline geometry::SE3 drift() {
  return geometry::SE3(Eigen::AngleAxisd(3 * std::numbers::pi / 180, Eigen::Vector3d::UnitZ()).toRotationMatrix(),
                       Eigen::Vector3d(0.3, 0.2, 0));
}

struct Scene {
  std::vector<Eigen::Vector3d> points;
  std::vector<Descriptor256> descriptors;
  std::shared_ptr<const place::Vocabulary> vocabulary;
  map::Map map;
  std::unique_ptr<place::KeyframeDatabase> db;
  std::vector<map::KeyFrame*> keyframes;
  std::map<std::pair<int, int>, map::MapPoint*> instance;  // (lap, point) -> its map point
  std::mt19937_64 rng{5};

  Scene() {
    std::uniform_real_distribution<double> angle(0, 2 * std::numbers::pi), height(-2.5, 2.5), radius(11, 13);
    for (int i = 0; i < 1500; ++i) {
      const double a = angle(rng), r = radius(rng);
      points.emplace_back(r * std::cos(a), r * std::sin(a), height(rng));
      descriptors.push_back(place::random_descriptor(rng));
    }
    std::vector<std::vector<Descriptor256>> images(20);
    for (std::size_t i = 0; i < descriptors.size(); ++i) images[i % 20].push_back(descriptors[i]);
    // About one word per point: unrelated keyframes share only chance words, as real places do.
    place::VocabularyTrainingOptions o;
    o.k = 16;
    o.levels = 3;
    vocabulary = std::make_shared<const place::Vocabulary>(place::train_vocabulary(images, o));
    db = std::make_unique<place::KeyframeDatabase>(vocabulary, 1);
  }

  // Keyframe k observes every point in view; the second lap's keyframes get their own map points.
  // Unmapped: as tracking leaves a keyframe in local mapping's queue, its new points observed by it
  // and the points it tracked only listed, with no connections and not in the database.
  map::KeyFrame* add_keyframe(int k, bool mapped = true) {
    const int lap = k / kPerLap;
    const geometry::SE3 T = true_pose(k);
    const geometry::StereoCamera cam(calibration());
    auto d = std::make_shared<map::FrameData>();
    d->frame_id = k;
    d->timestamp = k;
    d->calib = calibration();
    d->levels = 1;
    std::vector<Descriptor256> desc;
    std::vector<int> ids;
    std::normal_distribution<double> pixel_noise(0, 0.2);
    for (std::size_t i = 0; i < points.size(); ++i) {
      const Eigen::Vector3d Xc = T * points[i];
      if (Xc.z() < 1) continue;
      const Eigen::Vector2d uv = cam.project(Xc) + Eigen::Vector2d(pixel_noise(rng), pixel_noise(rng));
      if (!cam.in_image(uv, 5)) continue;
      d->keypoints.emplace_back(cv::Point2f(static_cast<float>(uv.x()), static_cast<float>(uv.y())), 7.f, 0.f, 0.f, 0);
      d->u_right.push_back(static_cast<float>(uv.x() - cam.bf() / Xc.z()));
      d->depth.push_back(static_cast<float>(Xc.z()));
      desc.push_back(place::flip_bits(descriptors[i], 4, rng));
      ids.push_back(static_cast<int>(i));
    }
    d->descriptors = place::to_mat(desc);
    d->build_grid();
    // As tracking does: atomic with respect to loop correction and global BA, and after a
    // correction the drift is gone (tracking goes on from the corrected pose).
    std::lock_guard map_lock(map.update_mutex());
    const bool drifted = lap > 0 && map.big_changes() == 0;
    const geometry::SE3 estimate = drifted ? T * drift().inverse() : T;
    map::KeyFrame* kf = map.create_keyframe(d, estimate);
    for (std::size_t j = 0; j < ids.size(); ++j) {
      // As tracking would: the points this lap already has (moved or fused by a correction), and
      // after a correction the first lap's points for what this lap has not seen yet.
      auto resolve = [&](int l) {
        map::MapPoint*& p = instance[{l, ids[j]}];
        while (p && p->is_bad() && p->replaced_by()) p = p->replaced_by();  // fused by loop closing
        return p && !p->is_bad() ? p : nullptr;
      };
      map::MapPoint* mp = resolve(lap);
      if (!mp && !drifted) mp = resolve(0);
      const bool created = !mp;
      if (created) {
        const Eigen::Vector3d& P = points[static_cast<std::size_t>(ids[j])];
        mp = map.create_point(drifted ? drift() * P : P, kf, k);
        instance[{lap, ids[j]}] = mp;
      }
      // Tracking observes the points it creates; local mapping adds the tracked ones.
      if (mapped || created) mp->add_observation(kf, static_cast<int>(j));
      kf->add_map_point(mp, static_cast<int>(j));
      // Descriptor and distance range, for the projection searches of loop closing.
      if (mp->num_observations() <= 2) {
        mp->update_descriptor();
        mp->update_normal_and_depth();
      }
    }
    if (mapped) {
      kf->update_connections();
      db->add(kf);
    }
    keyframes.push_back(kf);
    return kf;
  }
};

}  // namespace plslam::loop::test
