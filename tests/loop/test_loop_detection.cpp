// Loop detection and verification on a map with exact ground truth: a camera circles inside a
// cylinder of textured points, looking outward, one and a half times. The second lap's keyframes
// and points carry a drift (3 degrees of yaw and 36 cm) and are new map points, as if tracking had
// not recognised the place: exactly what loop closing must find and measure.
#include <cmath>
#include <map>
#include <numbers>
#include <random>

#include <gtest/gtest.h>

#include "place/synthetic_descriptors.h"
#include "plslam/geometry/stereo_camera.h"
#include "plslam/loop/loop_detector.h"
#include "plslam/loop/loop_verifier.h"
#include "plslam/map/map.h"
#include "plslam/place/vocabulary_training.h"

namespace plslam::loop {
namespace {

using place::Descriptor256;

constexpr int kPerLap = 45;  // a keyframe every 8 degrees
constexpr int kKeyframes = kPerLap + kPerLap / 2;

StereoCalibration calibration() {
  StereoCalibration c;
  c.width = 640;
  c.height = 480;
  c.fx = c.fy = 400;
  c.cx = 320;
  c.cy = 240;
  c.baseline = 0.12;
  return c;
}

// The true T_cw of keyframe k: on a 6 m circle at angle 8k degrees, looking outward.
geometry::SE3 true_pose(int k) {
  const double a = k * 2 * std::numbers::pi / kPerLap;
  const Eigen::Vector3d z(std::cos(a), std::sin(a), 0), y(0, 0, -1), c = 6 * z;
  Eigen::Matrix3d R_wc;
  R_wc.col(0) = y.cross(z);
  R_wc.col(1) = y;
  R_wc.col(2) = z;
  return geometry::SE3(R_wc, c).inverse();
}

// What the second lap's map believes: the world moved by 3 degrees of yaw and (0.3, 0.2, 0) m.
geometry::SE3 drift() {
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
  map::KeyFrame* add_keyframe(int k) {
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
    std::normal_distribution<double> pixel_noise(0, 0.5);
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
    const geometry::SE3 estimate = lap == 0 ? T : T * drift().inverse();
    map::KeyFrame* kf = map.create_keyframe(d, estimate);
    for (std::size_t j = 0; j < ids.size(); ++j) {
      auto& mp = instance[{lap, ids[j]}];
      if (!mp) {
        const Eigen::Vector3d world = lap == 0 ? points[static_cast<std::size_t>(ids[j])] : drift() * points[static_cast<std::size_t>(ids[j])];
        mp = map.create_point(world, kf, k);
      }
      mp->add_observation(kf, static_cast<int>(j));
      kf->add_map_point(mp, static_cast<int>(j));
    }
    kf->update_connections();
    db->add(kf);
    keyframes.push_back(kf);
    return kf;
  }
};

TEST(LoopDetection, TheSecondLapFindsTheFirstAfterThreeConsistentKeyframesAndNeverBefore) {
  Scene s;
  LoopDetector detector(*s.db);
  int first_detection = -1;
  for (int k = 0; k < kKeyframes; ++k) {
    map::KeyFrame* kf = s.add_keyframe(k);
    const auto found = detector.detect(kf);
    if (k < kPerLap) {
      // The first lap's look-alikes are all covisible: no loop.
      EXPECT_TRUE(found.empty()) << "keyframe " << k << " found " << (found.empty() ? -1 : found[0].keyframe->frame_id()) << " score " << (found.empty() ? 0 : found[0].score) << " covisibles " << kf->covisibles().size();
      continue;
    }
    for (const auto& f : found) {
      // The same place: the first lap's keyframe within two keyframes (16 degrees) of this one.
      EXPECT_LE(std::abs(f.keyframe->frame_id() - (k - kPerLap)), 2) << "keyframe " << k;
      EXPECT_GE(f.consistency, 3);
    }
    if (!found.empty() && first_detection < 0) first_detection = k;
  }
  // Keyframe 45 has no covisible neighbour yet; 46, 47 and 48 find the place in a row.
  EXPECT_GE(first_detection, kPerLap + 2);
  EXPECT_LE(first_detection, kPerLap + 4);
}

TEST(LoopVerification, RecoversTheRelativePoseOfATrueLoop) {
  Scene s;
  for (int k = 0; k < kKeyframes; ++k) s.add_keyframe(k);
  map::KeyFrame* query = s.keyframes[kPerLap + 5];
  map::KeyFrame* candidate = s.keyframes[5];
  const auto c = verify_loop(query, candidate, *s.db);
  ASSERT_TRUE(c);
  EXPECT_GE(c->matches.size(), 100u);
  // The truth: both keyframes see the same place from the same true pose.
  const geometry::SE3 truth = true_pose(kPerLap + 5) * true_pose(5).inverse();
  const geometry::SE3 err = truth.inverse() * c->T_query_candidate;
  EXPECT_LT(err.translation().norm(), 0.02);
  EXPECT_LT(Eigen::AngleAxisd(err.rotation()).angle(), 0.5 * std::numbers::pi / 180);
  // And the drift follows from it: T_qw(corrected) = T_qc * T_cw; the query's estimate is off by it.
  const geometry::SE3 corrected = c->T_query_candidate * candidate->pose();
  EXPECT_LT((corrected.inverse().translation() - true_pose(kPerLap + 5).inverse().translation()).norm(), 0.05);
  for (const auto& [a, b] : c->matches) {
    EXPECT_LT((drift().inverse() * a->position() - b->position()).norm(), 1e-9);
  }
}

TEST(LoopVerification, RejectsDistantPlacesAndAliasedGeometry) {
  Scene s;
  for (int k = 0; k < kKeyframes; ++k) s.add_keyframe(k);
  // Half a lap apart: nothing in common.
  EXPECT_FALSE(verify_loop(s.keyframes[kPerLap + 5], s.keyframes[5 + kPerLap / 2], *s.db));
  // Perceptual aliasing: a keyframe that looks exactly like keyframe 5 (same features) but whose
  // map points lie at random places. The matches agree on no single transform.
  map::KeyFrame* original = s.keyframes[5];
  auto copy = std::make_shared<map::FrameData>(original->data());
  copy->frame_id = 1000;
  map::KeyFrame* alias = s.map.create_keyframe(copy, original->pose());
  std::uniform_real_distribution<double> u(-12, 12);
  for (std::size_t j = 0; j < copy->keypoints.size(); ++j) {
    map::MapPoint* mp = s.map.create_point(Eigen::Vector3d(u(s.rng), u(s.rng), u(s.rng)), alias, 1000);
    mp->add_observation(alias, static_cast<int>(j));
    alias->add_map_point(mp, static_cast<int>(j));
  }
  s.db->add(alias);
  EXPECT_TRUE(verify_loop(s.keyframes[kPerLap + 5], original, *s.db));
  EXPECT_FALSE(verify_loop(s.keyframes[kPerLap + 5], alias, *s.db));
  LoopVerifierOptions bad;
  bad.min_inliers = 2;
  EXPECT_THROW(verify_loop(s.keyframes[kPerLap + 5], original, *s.db, bad), std::invalid_argument);
}

}  // namespace
}  // namespace plslam::loop
