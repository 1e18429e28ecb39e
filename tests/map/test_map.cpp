#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cstring>
#include <set>
#include <stdexcept>

#include "plslam/map/descriptor_utils.h"
#include "plslam/geometry/stereo_camera.h"
#include "plslam/map/map.h"

namespace plslam::map {
namespace {

std::shared_ptr<FrameData> make_data(long id, int n_points, int n_lines = 0) {
  auto d = std::make_shared<FrameData>();
  d->frame_id = id;
  d->calib.width = 640;
  d->calib.height = 480;
  d->calib.fx = d->calib.fy = 500;
  d->calib.cx = 320;
  d->calib.cy = 240;
  d->calib.baseline = 0.1;
  cv::RNG rng(static_cast<std::uint64_t>(id) + 1);
  for (int i = 0; i < n_points; ++i) {
    d->keypoints.emplace_back(cv::Point2f(rng.uniform(0.f, 640.f), rng.uniform(0.f, 480.f)), 31.f, 0.f, 0.f, 0);
    d->u_right.push_back(-1);
    d->depth.push_back(-1);
  }
  d->descriptors = cv::Mat(n_points, 32, CV_8U);
  rng.fill(d->descriptors, cv::RNG::UNIFORM, 0, 256);
  d->lines.resize(static_cast<std::size_t>(n_lines));
  d->line_descriptors = cv::Mat(n_lines, 32, CV_8U);
  if (n_lines > 0) rng.fill(d->line_descriptors, cv::RNG::UNIFORM, 0, 256);
  d->build_grid();
  return d;
}

// Three keyframes: 0 and 1 share 30 points, 1 and 2 share 20, 0 and 2 share 5.
struct Fixture {
  Map map;
  KeyFrame* k[3];
  Fixture() {
    for (int i = 0; i < 3; ++i) k[i] = map.create_keyframe(make_data(i, 100), geometry::SE3());
    int next[3] = {0, 0, 0};
    auto share = [&](int a, int b, int n) {
      for (int s = 0; s < n; ++s) {
        MapPoint* p = map.create_point(Eigen::Vector3d(s, a, b), k[a], 0);
        for (int kf : {a, b}) {
          p->add_observation(k[kf], next[kf]);
          k[kf]->add_map_point(p, next[kf]++);
        }
      }
    };
    share(0, 1, 30);
    share(1, 2, 20);
    share(0, 2, 5);
    for (auto* kf : k) kf->update_connections();
  }
};

TEST(Map, CovisibilityWeightsCountSharedPoints) {
  Fixture f;
  EXPECT_EQ(f.k[0]->weight(f.k[1]), 30);
  EXPECT_EQ(f.k[1]->weight(f.k[2]), 20);
  // Below 15 shared points there is no edge, except to a keyframe's strongest neighbour.
  EXPECT_EQ(f.k[0]->weight(f.k[2]), 0);
  EXPECT_EQ(f.k[1]->covisibles(), (std::vector<KeyFrame*>{f.k[0], f.k[2]}));
  EXPECT_EQ(f.k[1]->best_covisibles(1), (std::vector<KeyFrame*>{f.k[0]}));
}

TEST(Map, SpanningTreeAttachesToStrongestNeighbour) {
  Fixture f;
  EXPECT_EQ(f.k[0]->parent(), nullptr);
  EXPECT_EQ(f.k[1]->parent(), f.k[0]);
  EXPECT_EQ(f.k[2]->parent(), f.k[1]);
  EXPECT_TRUE(f.k[0]->children().count(f.k[1]));
}

TEST(Map, CullingAKeyframeReparentsChildrenAndKeepsRelativePose) {
  Fixture f;
  f.k[1]->set_pose(geometry::SE3(Eigen::Matrix3d::Identity(), Eigen::Vector3d(1, 0, 0)));
  f.k[1]->set_bad();
  f.map.erase_keyframe(f.k[1]);
  EXPECT_TRUE(f.k[1]->is_bad());
  EXPECT_EQ(f.k[2]->parent(), f.k[0]);
  EXPECT_EQ(f.map.num_keyframes(), 2u);
  EXPECT_NEAR((f.k[1]->pose_relative_to_parent().translation() - Eigen::Vector3d(1, 0, 0)).norm(), 0, 1e-12);
  // Points seen only by k0 and k1 lost their second observation and are gone.
  EXPECT_EQ(f.map.num_points(), 5u);
  EXPECT_EQ(f.k[0]->tracked_map_points(1), 5);
}

TEST(Map, TransformWorldKeepsEveryObjectWhereTheCamerasSeeIt) {
  Fixture f;
  for (int i = 0; i < 3; ++i) {
    f.k[i]->set_pose(geometry::SE3::exp((geometry::Vector6d() << 0.3 * i, -0.2, 0.1 * i, 0.05, -0.1 * i, 0.2).finished()));
  }
  MapLine* line = f.map.create_line(Eigen::Vector3d(1, 2, 3), Eigen::Vector3d(2, 2, 4), f.k[0], 0);
  for (MapPoint* p : f.map.points()) p->update_normal_and_depth();
  f.k[1]->set_bad();  // a culled keyframe still anchors frames: it turns too
  f.map.erase_keyframe(f.k[1]);
  const auto points = f.map.points();
  ASSERT_FALSE(points.empty());
  std::vector<Eigen::Vector3d> in_camera, normals;
  for (MapPoint* p : points) {
    in_camera.push_back(f.k[2]->pose() * p->position());
    normals.push_back(p->normal());
  }
  ASSERT_GT(normals.front().norm(), 0.5);
  const Eigen::Vector3d s0 = f.k[1]->pose() * line->start(), e0 = f.k[0]->pose() * line->end();
  const Eigen::Vector3d c1 = f.k[1]->camera_center();
  const long changes = f.map.changes();

  const geometry::SE3 T(Eigen::AngleAxisd(0.4, Eigen::Vector3d(1, -2, 0.5).normalized()).toRotationMatrix(),
                        Eigen::Vector3d(0.5, -1, 2));
  f.map.transform_world(T);
  for (std::size_t i = 0; i < points.size(); ++i) {
    EXPECT_LT((f.k[2]->pose() * points[i]->position() - in_camera[i]).norm(), 1e-12);
    EXPECT_LT((points[i]->normal() - T.rotation() * normals[i]).norm(), 1e-12);
  }
  EXPECT_LT((f.k[1]->pose() * line->start() - s0).norm(), 1e-12);
  EXPECT_LT((f.k[0]->pose() * line->end() - e0).norm(), 1e-12);
  EXPECT_LT((f.k[1]->camera_center() - T * c1).norm(), 1e-12);
  EXPECT_GT(f.map.changes(), changes);  // a viewer redraws
}

TEST(Map, FirstKeyframeIsNeverCulled) {
  Fixture f;
  f.k[0]->set_bad();
  EXPECT_FALSE(f.k[0]->is_bad());
}

TEST(Map, ASegmentIsAnchoredOnceALoopTiesItToTheFirst) {
  Map m;
  KeyFrame* k0 = m.create_keyframe(make_data(0, 10), geometry::SE3());
  EXPECT_EQ(k0->segment(), 0);
  EXPECT_TRUE(m.anchored(0));
  const int s1 = m.start_segment(), s2 = m.start_segment(), s3 = m.start_segment();
  EXPECT_EQ(m.num_segments(), 4);
  KeyFrame* k1 = m.create_keyframe(make_data(1, 10), geometry::SE3(), s1);
  EXPECT_EQ(k1->segment(), s1);
  EXPECT_THROW(m.create_keyframe(make_data(2, 10), geometry::SE3(), 7), std::invalid_argument);
  EXPECT_FALSE(m.anchored(s1));
  // Two new segments tied to each other are still both guesses.
  m.tie_segments(s3, s2);
  EXPECT_FALSE(m.anchored(s2));
  EXPECT_FALSE(m.anchored(s3));
  // Tied to one of them, then that set to the first: all anchored, whichever order.
  m.tie_segments(s1, s3);
  m.tie_segments(s2, 0);
  for (int s : {0, s1, s2, s3}) EXPECT_TRUE(m.anchored(s)) << s;
}

TEST(Map, TheOriginIsTheFirstKeyframeWhateverItsId) {
  Fixture f;
  EXPECT_TRUE(f.k[0]->is_origin());
  EXPECT_FALSE(f.k[1]->is_origin());
  // A loaded map whose lowest id is not 0 (its keyframe 0 was culled before it was saved): the
  // first restored keyframe holds the gauge and is never culled; keyframes made later do not.
  Map loaded;
  KeyFrame* a = loaded.restore_keyframe(4, make_data(4, 10), geometry::SE3());
  KeyFrame* b = loaded.restore_keyframe(9, make_data(9, 10), geometry::SE3());
  EXPECT_EQ(loaded.first_keyframe(), a);
  EXPECT_TRUE(a->is_origin());
  EXPECT_FALSE(b->is_origin());
  a->set_bad();
  EXPECT_FALSE(a->is_bad());
  KeyFrame* c = loaded.create_keyframe(make_data(10, 10), geometry::SE3());
  EXPECT_EQ(c->id(), 10);
  EXPECT_FALSE(c->is_origin());
}

TEST(Map, ReplacingAPointMovesItsObservations) {
  Map map;
  KeyFrame* a = map.create_keyframe(make_data(0, 10), geometry::SE3());
  KeyFrame* b = map.create_keyframe(make_data(1, 10), geometry::SE3());
  KeyFrame* c = map.create_keyframe(make_data(2, 10), geometry::SE3());
  MapPoint* p = map.create_point({0, 0, 1}, a, 0);
  MapPoint* q = map.create_point({0, 0, 1.01}, b, 1);
  p->add_observation(a, 3);
  a->add_map_point(p, 3);
  p->add_observation(c, 4);
  c->add_map_point(p, 4);
  q->add_observation(b, 5);
  b->add_map_point(q, 5);
  q->add_observation(c, 4);
  c->add_map_point(q, 4);
  // The list holds what the map holds, in keyframe-id order.
  const std::vector<std::pair<KeyFrame*, int>> before{{b, 5}, {c, 4}};
  EXPECT_EQ(q->observation_list(), before);
  p->replace_with(q);
  EXPECT_TRUE(p->is_bad());
  EXPECT_EQ(p->replaced_by(), q);
  EXPECT_EQ(q->num_observations(), 3);
  EXPECT_EQ(a->map_point(3), q);
  EXPECT_EQ(c->map_point(4), q);
  EXPECT_EQ(map.num_points(), 1u);
  const std::vector<std::pair<KeyFrame*, int>> after{{a, 3}, {b, 5}, {c, 4}};
  EXPECT_EQ(q->observation_list(), after);
  EXPECT_TRUE(p->observation_list().empty());
}

TEST(Map, PointWithOneObservationLeftBecomesBad) {
  Map map;
  KeyFrame* a = map.create_keyframe(make_data(0, 10), geometry::SE3());
  KeyFrame* b = map.create_keyframe(make_data(1, 10), geometry::SE3());
  MapPoint* p = map.create_point({0, 0, 1}, a, 0);
  p->add_observation(a, 0);
  a->add_map_point(p, 0);
  p->add_observation(b, 0);
  b->add_map_point(p, 0);
  p->erase_observation(b);
  EXPECT_TRUE(p->is_bad());
  EXPECT_EQ(a->map_point(0), nullptr);
}

TEST(Map, ABadLandmarkTakesNoObservation) {
  Map map;
  KeyFrame* a = map.create_keyframe(make_data(0, 10, 2), geometry::SE3());
  MapPoint* p = map.create_point({0, 0, 1}, a, 0);
  p->set_bad();
  EXPECT_FALSE(p->add_observation(a, 0));
  EXPECT_EQ(p->num_observations(), 0);
  MapLine* l = map.create_line({0, 0, 1}, {1, 0, 1}, a, 0);
  EXPECT_TRUE(l->add_observation(a, 0));
}

// Reclamation frees exactly the bad points and lines (ASan in CI checks the freeing), keeps the
// good ones and every keyframe, calls the threads' clean-up first, and counts what it freed.
TEST(Map, ReclaimFreesTheBadPointsAndLinesOnly) {
  Fixture f;  // 55 good points
  Map& map = f.map;
  MapPoint* culled = map.points().front();
  culled->set_bad();  // clears its keyframes' slots
  MapPoint* replaced = map.points().front();
  MapPoint* survivor = map.points().back();
  replaced->replace_with(survivor);
  MapLine* line = map.create_line({0, 0, 1}, {1, 0, 1}, f.k[0], 0);
  MapLine* bad_line = map.create_line({0, 1, 1}, {1, 1, 1}, f.k[0], 0);
  map.erase_line(bad_line);
  const long survivor_id = survivor->id();
  int calls = 0;
  const auto freed = map.reclaim([&] {
    ++calls;
    EXPECT_TRUE(culled->is_bad());  // still alive while the threads drop their pointers
  });
  EXPECT_EQ(calls, 1);
  EXPECT_EQ(freed.points, 2);
  EXPECT_EQ(freed.lines, 1);
  EXPECT_EQ(map.num_points(), 53u);
  EXPECT_EQ(map.num_lines(), 1u);
  EXPECT_EQ(map.lines().front(), line);
  EXPECT_EQ(map.num_keyframes(), 3u);
  EXPECT_EQ(survivor->id(), survivor_id);
  // No keyframe slot points at a freed object: every non-null slot is an active point.
  const auto active = map.points();
  const std::set<MapPoint*> alive(active.begin(), active.end());
  for (auto* kf : f.k) {
    for (auto* p : kf->map_points()) {
      if (p) {
        EXPECT_TRUE(alive.count(p));
      }
    }
  }
  const auto again = map.reclaim();
  EXPECT_EQ(again.points, 0);
  EXPECT_EQ(map.reclaimed().points, 2);
  EXPECT_EQ(map.reclaimed().lines, 1);
}

// ORB-SLAM's observation count: stereo observations weigh 2, left-only ones 1, and the weight
// follows additions, re-indexing, removals and replacement.
TEST(Map, ObservationWeightCountsStereoTwice) {
  Map map;
  auto stereo_data = [](long id) {
    auto d = make_data(id, 10, 2);
    for (int i = 0; i < 5; ++i) {  // points 0-4 and line 0 are stereo
      d->u_right[static_cast<std::size_t>(i)] = 100.f;
      d->depth[static_cast<std::size_t>(i)] = 2.f;
    }
    d->lines[0].stereo = true;
    return d;
  };
  KeyFrame* a = map.create_keyframe(stereo_data(0), geometry::SE3());
  KeyFrame* b = map.create_keyframe(stereo_data(1), geometry::SE3());
  KeyFrame* c = map.create_keyframe(stereo_data(2), geometry::SE3());
  MapPoint* p = map.create_point({0, 0, 2}, a, 0);
  p->add_observation(a, 1);  // stereo
  EXPECT_EQ(p->observation_weight(), 2);
  p->add_observation(b, 7);  // left only
  EXPECT_EQ(p->observation_weight(), 3);
  p->add_observation(b, 2);  // the same keyframe, now a stereo feature
  EXPECT_EQ(p->observation_weight(), 4);
  EXPECT_EQ(p->num_observations(), 2);
  p->add_observation(c, 8);
  EXPECT_EQ(p->observation_weight(), 5);
  p->erase_observation(a);
  EXPECT_EQ(p->observation_weight(), 3);
  a->add_map_point(p, 1);
  b->add_map_point(p, 2);
  c->add_map_point(p, 8);
  EXPECT_EQ(b->tracked_map_points(3), 1);
  EXPECT_EQ(b->tracked_map_points(4), 0);

  MapLine* l = map.create_line({0, 0, 2}, {1, 0, 2}, a, 0);
  l->add_observation(a, 0);
  l->add_observation(b, 1);
  EXPECT_EQ(l->observation_weight(), 3);
  MapPoint* q = map.create_point({0, 0, 2.1}, c, 2);
  q->add_observation(c, 3);
  q->add_observation(a, 4);
  p->replace_with(q);  // b's stereo observation moves over; c already sees q
  EXPECT_EQ(p->observation_weight(), 0);
  EXPECT_EQ(q->observation_weight(), 6);
}

TEST(Map, MostDistinctiveDescriptorHasSmallestMedianDistance) {
  // A central descriptor, three that each differ from it in 4 other bits, and a far one.
  auto with_bits = [](int from, int to) {
    cv::Mat m(1, 32, CV_8U, cv::Scalar(0));
    for (int b = from; b < to; ++b) m.at<uchar>(0, b / 8) |= static_cast<uchar>(1 << (b % 8));
    return m;
  };
  const std::vector<cv::Mat> d{with_bits(0, 4), with_bits(0, 0), with_bits(4, 8), with_bits(8, 12),
                               with_bits(100, 160)};
  // Median distances (self included, as ORB-SLAM2): central 4, the others 8, the far one 60+.
  std::vector<const uint8_t*> rows;
  for (const auto& m : d) rows.push_back(m.ptr<uint8_t>(0));
  EXPECT_EQ(descriptor_distance(d[most_distinctive_index(rows)], d[1]), 0);
  EXPECT_EQ(most_distinctive_index({}), 0u);
}

TEST(Map, MostDistinctiveIndexIsTheFirstRowWithTheSmallestMedian) {
  // Against the definition, on random rows and on rows with ties (few distinct values).
  cv::RNG rng(7);
  for (int trial = 0; trial < 200; ++trial) {
    const int n = 1 + trial % 23;
    cv::Mat rows(n, 32, CV_8U);
    rng.fill(rows, cv::RNG::UNIFORM, 0, trial % 2 ? 256 : 2);
    std::vector<const uint8_t*> ptrs;
    for (int i = 0; i < n; ++i) ptrs.push_back(rows.ptr<uint8_t>(i));
    std::size_t expected = 0;
    int best = 1 << 30;
    for (int i = 0; i < n; ++i) {
      std::vector<int> dist;
      for (int j = 0; j < n; ++j) dist.push_back(descriptor_distance(rows.row(i), rows.row(j)));
      std::sort(dist.begin(), dist.end());
      if (dist[static_cast<std::size_t>((n - 1) / 2)] < best) {
        best = dist[static_cast<std::size_t>((n - 1) / 2)];
        expected = static_cast<std::size_t>(i);
      }
    }
    ASSERT_EQ(most_distinctive_index(ptrs), expected) << "trial " << trial;
  }
}

TEST(Map, CopiedDescriptorIsTheLandmarksDescriptor) {
  Fixture f;
  MapPoint* p = f.k[0]->map_point(0);
  ASSERT_NE(p, nullptr);
  std::array<uint8_t, 32> bytes{};
  bytes.fill(7);
  MapPoint* fresh = f.map.create_point({0, 0, 1}, f.k[0], 0);
  EXPECT_FALSE(fresh->copy_descriptor(bytes));  // no observation, no descriptor: untouched
  EXPECT_EQ(bytes[0], 7);
  p->update_descriptor();
  ASSERT_TRUE(p->copy_descriptor(bytes));
  const cv::Mat d = p->descriptor();
  ASSERT_EQ(d.total(), 32u);
  EXPECT_EQ(0, std::memcmp(bytes.data(), d.ptr<uint8_t>(0), 32));
}

TEST(FrameData, GridSearchFindsExactlyThePointsInTheRadius) {
  auto d = make_data(0, 500);
  const double u = 300, v = 200, r = 40;
  auto found = d->points_in_area(u, v, r);
  std::sort(found.begin(), found.end());
  std::vector<int> brute;
  for (std::size_t i = 0; i < d->keypoints.size(); ++i) {
    if (std::hypot(d->keypoints[i].pt.x - u, d->keypoints[i].pt.y - v) <= r) brute.push_back(static_cast<int>(i));
  }
  EXPECT_EQ(found, brute);
  EXPECT_FALSE(brute.empty());
}

TEST(FrameData, StereoConstraintStopsAtTheFarDepth) {
  FrameData d;
  d.calib.baseline = 0.5;
  d.u_right = {100.f, -1.f, 50.f, 80.f};
  d.depth = {5.f, -1.f, 10.f, 10.5f};  // 10, -, 20 and 21 baselines
  EXPECT_TRUE(d.stereo_constraint(0, 20));
  EXPECT_FALSE(d.stereo_constraint(1, 20));  // no right match
  EXPECT_TRUE(d.stereo_constraint(2, 20));   // at the limit
  EXPECT_FALSE(d.stereo_constraint(3, 20));
  EXPECT_TRUE(d.stereo_constraint(3, 0));    // 0: no limit
  EXPECT_FALSE(d.stereo_constraint(1, 0));
}

TEST(FrameData, LevelScalesArePowersOfTheScaleFactor) {
  FrameData d;
  d.scale_factor = 1.2;
  for (int l = 0; l < 8; ++l) {
    EXPECT_NEAR(d.level_scale(l), std::pow(1.2, l), 1e-12);
    EXPECT_NEAR(d.level_sigma2(l), std::pow(1.2, 2 * l), 1e-12);
  }
}

}  // namespace
}  // namespace plslam::map

namespace plslam::map {
namespace {

// Three keyframes see a 2 m 3D segment from different places, each a different part of it.
// Collapsed onto a point of the line (what BA used to leave), the line gets its direction back
// from the observed planes and its extent from the observed segments.
TEST(MapLine, RefitRecoversDirectionAndExtentFromTheObservations) {
  const Eigen::Vector3d A(-1.0, 0.3, 6.0), B(1.0, -0.2, 7.0);  // the true segment, world frame
  Map map;
  std::vector<KeyFrame*> kfs;
  const std::vector<Eigen::Vector3d> centres = {{0, 0, 0}, {0.8, 0.1, 0.5}, {-0.6, -0.4, 0.2}};
  const std::vector<std::pair<double, double>> parts = {{0.0, 0.7}, {0.2, 1.0}, {0.1, 0.9}};
  for (std::size_t k = 0; k < centres.size(); ++k) {
    auto d = make_data(static_cast<long>(k), 1, 1);
    const geometry::SE3 T_cw(Eigen::AngleAxisd(0.05 * static_cast<double>(k), Eigen::Vector3d::UnitY()).toRotationMatrix(),
                             Eigen::Vector3d::Zero());
    const geometry::SE3 T(T_cw.rotation(), -(T_cw.rotation() * centres[k]));
    const geometry::StereoCamera cam(d->calib);
    const Eigen::Vector2d s = cam.project(T * (A + parts[k].first * (B - A)));
    const Eigen::Vector2d e = cam.project(T * (A + parts[k].second * (B - A)));
    auto& o = d->lines[0];
    o.segment.start = cv::Point2f(static_cast<float>(s.x()), static_cast<float>(s.y()));
    o.segment.end = cv::Point2f(static_cast<float>(e.x()), static_cast<float>(e.y()));
    o.left_line = geometry::line_through(s, e);
    const Eigen::Vector3d sr = cam.project_stereo(T * (A + parts[k].first * (B - A)));
    const Eigen::Vector3d er = cam.project_stereo(T * (A + parts[k].second * (B - A)));
    o.right_line = geometry::line_through({sr.z(), sr.y()}, {er.z(), er.y()});
    o.stereo = true;
    kfs.push_back(map.create_keyframe(d, T));
  }
  const Eigen::Vector3d on_line = A + 0.4 * (B - A);
  MapLine* ml = map.create_line(on_line, on_line, kfs[0], 0);
  for (std::size_t k = 0; k < kfs.size(); ++k) {
    ml->add_observation(kfs[k], 0);
    kfs[k]->add_map_line(ml, 0);
  }
  ASSERT_TRUE(ml->refit_to_observations());
  // The union of the observed parts: the whole segment, up to float pixel rounding.
  const bool forward = (ml->end() - ml->start()).dot(B - A) > 0;
  EXPECT_LT(((forward ? ml->start() : ml->end()) - A).norm(), 1e-3);
  EXPECT_LT(((forward ? ml->end() : ml->start()) - B).norm(), 1e-3);
  // A line that keeps its direction is only re-clipped: a too short one grows to the extent seen.
  ml->set_endpoints(A + 0.45 * (B - A), A + 0.55 * (B - A));
  ASSERT_TRUE(ml->refit_to_observations());
  EXPECT_LT((ml->start() - A).norm(), 1e-3);
  EXPECT_LT((ml->end() - B).norm(), 1e-3);
  // A collapsed line without observations has nothing to be refitted from.
  MapLine* lone = map.create_line(on_line, on_line, kfs[0], 0);
  EXPECT_FALSE(lone->refit_to_observations());
}

}  // namespace
}  // namespace plslam::map

namespace plslam::map {
namespace {

// IMU samples of a body turning at a steady rate and accelerating, 200 Hz over [0, 1] s.
std::vector<ImuSample> turning_samples() {
  std::vector<ImuSample> s;
  for (int k = 0; k <= 200; ++k) {
    const double t = 0.005 * k;
    s.push_back({t, Eigen::Vector3d(0.3, -0.2 + t, 0.5), Eigen::Vector3d(1.0 + t, 0.2, 9.81 - 0.5 * t)});
  }
  return s;
}

std::shared_ptr<FrameData> data_at(long id, double t) {
  auto d = std::make_shared<FrameData>();
  d->frame_id = id;
  d->timestamp = t;
  return d;
}

// A culled keyframe of the IMU chain hands its interval to its successor: the successor's
// preintegration then runs from the culled one's predecessor, as if integrated over the whole
// interval at once; a culled first keyframe of the chain leaves its successor at the chain's start.
TEST(KeyFrameImu, CullingJoinsTheNeighboursIntervals) {
  Map map;
  map.create_keyframe(data_at(0, 0.0), geometry::SE3());  // the origin, never culled
  KeyFrame* k[4];
  const double t[4] = {0.1, 0.3, 0.45, 0.6};
  for (int i = 0; i < 4; ++i) k[i] = map.create_keyframe(data_at(i + 1, t[i]), geometry::SE3());
  const auto samples = turning_samples();
  const inertial::ImuBias b0{Eigen::Vector3d(0.01, 0, -0.02), Eigen::Vector3d(0.1, -0.05, 0)};
  const inertial::ImuBias b1{Eigen::Vector3d(0.02, 0.01, 0), Eigen::Vector3d(0, 0.05, 0.1)};
  auto between = [&](int i, int j, const inertial::ImuBias& b) {
    return std::make_shared<const inertial::Preintegration>(samples, t[i], t[j], b, kEurocAdis16448Noise);
  };
  k[0]->set_imu({Eigen::Vector3d(1, 0, 0), b0, nullptr, nullptr});
  k[1]->set_imu({Eigen::Vector3d(1, 0.1, 0), b1, k[0], between(0, 1, b0)});
  k[2]->set_imu({Eigen::Vector3d(1, 0.2, 0), b1, k[1], between(1, 2, b1)});
  k[3]->set_imu({Eigen::Vector3d(1, 0.3, 0), b1, k[2], between(2, 3, b1)});
  EXPECT_EQ(k[0]->imu_next(), k[1]);
  EXPECT_EQ(k[2]->imu_next(), k[3]);
  EXPECT_EQ(k[3]->imu_next(), nullptr);

  k[1]->set_bad();
  EXPECT_EQ(k[0]->imu_next(), k[2]);
  const auto s2 = k[2]->imu();
  ASSERT_TRUE(s2);
  EXPECT_EQ(s2->previous, k[0]);
  ASSERT_TRUE(s2->from_previous);
  // Integrated again at the predecessor's bias, over both intervals.
  const inertial::Preintegration direct(samples, t[0], t[2], b0, kEurocAdis16448Noise);
  EXPECT_DOUBLE_EQ(s2->from_previous->t_i(), t[0]);
  EXPECT_DOUBLE_EQ(s2->from_previous->t_j(), t[2]);
  EXPECT_LT((s2->from_previous->delta_R() - direct.delta_R()).norm(), 1e-12);
  EXPECT_LT((s2->from_previous->delta_v() - direct.delta_v()).norm(), 1e-12);
  EXPECT_LT((s2->from_previous->delta_p() - direct.delta_p()).norm(), 1e-12);
  EXPECT_LT((s2->from_previous->covariance() - direct.covariance()).norm(), 1e-12 * direct.covariance().norm());
  EXPECT_EQ(s2->v, Eigen::Vector3d(1, 0.2, 0));  // its own state stays

  k[0]->set_bad();  // the chain's first keyframe: its successor starts the chain
  const auto s2b = k[2]->imu();
  EXPECT_EQ(s2b->previous, nullptr);
  EXPECT_EQ(s2b->from_previous, nullptr);
  EXPECT_EQ(k[2]->imu_next(), k[3]);
  k[3]->set_bad();  // the last: its predecessor ends the chain
  EXPECT_EQ(k[2]->imu_next(), nullptr);
}

TEST(KeyFrameImu, BaEstimatesAndTheWorldsTurn) {
  Map map;
  KeyFrame* kf = map.create_keyframe(data_at(0, 0.0), geometry::SE3());
  EXPECT_FALSE(kf->has_imu());
  EXPECT_THROW(kf->set_imu_velocity_and_bias(Eigen::Vector3d::Zero(), {}), std::logic_error);
  kf->set_imu({Eigen::Vector3d(1, 2, 3), {}, nullptr, nullptr});
  EXPECT_FALSE(kf->imu()->estimated);  // a seed
  kf->set_imu_velocity_and_bias(Eigen::Vector3d(0, 1, 0), {Eigen::Vector3d(0.1, 0, 0), Eigen::Vector3d(0, 0, 0.2)});
  EXPECT_TRUE(kf->imu()->estimated);
  const geometry::SE3 T(Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitZ()).toRotationMatrix(), Eigen::Vector3d(5, 0, 0));
  map.transform_world(T);
  EXPECT_LT((kf->imu()->v - Eigen::Vector3d(-1, 0, 0)).norm(), 1e-12);  // turns, does not move
  EXPECT_EQ(kf->imu()->bias.acc, Eigen::Vector3d(0, 0, 0.2));          // the body's: unchanged
  // A loop correction that turns the keyframe's camera by 90 deg about z turns its velocity too;
  // BA's set_pose does not (it estimates the velocity itself).
  const geometry::SE3 turned =
      kf->pose() * geometry::SE3(Eigen::AngleAxisd(-M_PI / 2, Eigen::Vector3d::UnitZ()).toRotationMatrix(), Eigen::Vector3d(1, 2, 3));
  kf->move_to(turned);
  EXPECT_LT((kf->imu()->v - Eigen::Vector3d(0, -1, 0)).norm(), 1e-12);
  kf->set_pose(geometry::SE3());
  EXPECT_LT((kf->imu()->v - Eigen::Vector3d(0, -1, 0)).norm(), 1e-12);
}

}  // namespace
}  // namespace plslam::map
