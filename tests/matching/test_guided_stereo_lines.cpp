// Guided stereo lines (a search along each left line's rows, no right-image detection): endpoint
// depth against the synthetic scene's exact geometry, exact disparities on a constructed pair,
// a slanted plane's varying disparity, repeated structure refused, bad input refused, and
// counts on KITTI 06 next to the detect-and-describe matcher.
#include <chrono>
#include <cstdio>

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>

#include "features/line_synthetic_scene.h"
#include "plslam/matching/guided_stereo_lines.h"
#include "support/test_support.h"

namespace plslam::matching {
namespace {

using features::LineSegment;

TEST(GuidedStereoLines, EndpointDepthWithinTwoPercentOnSyntheticScene) {
  const auto s = test::make_line_scene(false);
  const auto fl = features::extract_lines(s.left);
  const auto matches = match_stereo_lines_guided(fl, s.left, s.right, s.calib);
  int on_gt = 0, within = 0, steep = 0, steep_within = 0;
  double worst = 0;
  for (const auto& m : matches) {
    EXPECT_EQ(m.right, -1);
    const LineSegment& l = fl.lines[static_cast<std::size_t>(m.left)];
    for (const auto& e : s.edges) {
      if (!test::on_edge(l, e)) continue;
      ++on_gt;
      const double es = std::fabs(m.P_start.z() - s.depth_at(e, l.start)) / s.depth_at(e, l.start);
      const double ee = std::fabs(m.P_end.z() - s.depth_at(e, l.end)) / s.depth_at(e, l.end);
      worst = std::max({worst, es, ee});
      within += es < 0.02 && ee < 0.02;
      // Where an edge crosses the rows at a shallow angle its column is least certain.
      if (std::fabs(l.direction().y) >= std::sin(20 * CV_PI / 180)) {
        ++steep;
        steep_within += es < 0.02 && ee < 0.02;
      }
      EXPECT_NEAR(m.P_start.x() / m.P_start.z(), (l.start.x - s.calib.cx) / s.calib.fx, 1e-9);
      EXPECT_NEAR(m.P_end.y() / m.P_end.z(), (l.end.y - s.calib.cy) / s.calib.fy, 1e-9);
      break;
    }
  }
  const auto detected = match_stereo_lines(fl, features::extract_lines(s.right), s.calib);
  std::printf("synthetic guided stereo: %zu matches (detect-and-describe: %zu), %d on GT edges, %d within 2%% depth, "
              "worst %.4f\n",
              matches.size(), detected.size(), on_gt, within, worst);
  EXPECT_GE(on_gt, 16) << matches.size() << " matches";
  EXPECT_GE(static_cast<double>(on_gt) / static_cast<double>(matches.size()), 0.95);
  EXPECT_GE(static_cast<double>(within) / on_gt, 0.9) << "worst relative depth error " << worst;
  EXPECT_GE(steep, 20);
  EXPECT_EQ(steep_within, steep) << "lines at least 20 degrees from horizontal";
}

TEST(GuidedStereoLines, ConstructedPairGivesExactDisparities) {
  const auto [a, b] = test::make_bar_pair(12);
  const StereoCalibration k{320, 240, 300, 300, 160, 120, 0.1};
  const auto fa = features::extract_lines(a);
  const auto m = match_stereo_lines_guided(fa, a, b, k);
  ASSERT_EQ(m.size(), 2u);  // the two long slanted sides
  for (const auto& x : m) {
    EXPECT_NEAR(x.disparity_start, 12, 0.15);
    EXPECT_NEAR(x.disparity_end, 12, 0.15);
    EXPECT_NEAR(x.P_start.z(), k.bf() / 12, 0.02 * k.bf() / 12);
  }
}

TEST(GuidedStereoLines, DisparityVaryingAlongTheLineIsFollowed) {
  // The right bar's bottom is 6 px further left than its top: d = 10 at row 30, 16 at row 210.
  const auto [a, b] = test::make_bar_pair(10, 6);
  const StereoCalibration k{320, 240, 300, 300, 160, 120, 0.1};
  const auto fa = features::extract_lines(a);
  const auto m = match_stereo_lines_guided(fa, a, b, k);
  ASSERT_EQ(m.size(), 2u);
  for (const auto& x : m) {
    const LineSegment& l = fa.lines[static_cast<std::size_t>(x.left)];
    EXPECT_NEAR(x.disparity_start, 10 + 6 * (l.start.y - 30) / 180, 0.25);
    EXPECT_NEAR(x.disparity_end, 10 + 6 * (l.end.y - 30) / 180, 0.25);
  }
}

TEST(GuidedStereoLines, RepeatedBarsAreRefusedNotGuessed) {
  // Identical vertical bars every 24 px, 10 px further left in the right image: along the rows,
  // disparities 10, 34, 58, ... look alike. A match must have the true one, or not be made.
  cv::Mat a(200, 400, CV_8U, cv::Scalar(40)), b(200, 400, CV_8U, cv::Scalar(40));
  for (int x = 40; x < 380; x += 24) {
    a.colRange(x, x + 10).setTo(210);
    b.colRange(x - 10, x).setTo(210);
  }
  const StereoCalibration k{400, 200, 300, 300, 200, 100, 0.1};
  const auto fa = features::extract_lines(a);
  ASSERT_GE(fa.lines.size(), 20u);
  const auto m = match_stereo_lines_guided(fa, a, b, k);
  int wrong = 0;
  for (const auto& x : m) wrong += std::fabs(x.disparity_start - 10) > 0.2 || std::fabs(x.disparity_end - 10) > 0.2;
  std::printf("repeated bars: %zu edges, %zu matches, %d at a wrong period\n", fa.lines.size(), m.size(), wrong);
  EXPECT_EQ(wrong, 0);
}

TEST(GuidedStereoLines, BadInputIsRefused) {
  const auto [a, b] = test::make_bar_pair(12);
  const auto fa = features::extract_lines(a);
  const StereoCalibration k{320, 240, 300, 300, 160, 120, 0.1};
  EXPECT_THROW(match_stereo_lines_guided(fa, a, b(cv::Rect(0, 0, 100, 100)), k), std::invalid_argument);
  EXPECT_THROW(match_stereo_lines_guided(fa, a, cv::Mat(), k), std::invalid_argument);
  StereoCalibration no_baseline = k;
  no_baseline.baseline = 0;
  EXPECT_THROW(match_stereo_lines_guided(fa, a, b, no_baseline), std::invalid_argument);
  GuidedStereoLineOptions o;
  o.min_zncc = 1.5;
  EXPECT_THROW(match_stereo_lines_guided(fa, a, b, k, {}, o), std::invalid_argument);
}

TEST(GuidedStereoLines, KittiFramesGiveLinesLikeDetectAndDescribe) {
  PLSLAM_REQUIRE_SHARED_DATA(data);
  const StereoCalibration k{1226, 370, 707.0912, 707.0912, 601.8873, 183.1104, 379.8145 / 707.0912};
  const auto root = data / "kitti/sequences/06";
  const auto o = features::LineExtractorOptions::kitti();
  std::vector<double> guided, detected, agree_share;  // agreement: a diagnostic, either may be wrong
  double ms = 0;
  for (const char* f : {"000000.png", "000025.png", "000050.png"}) {
    const cv::Mat l = cv::imread((root / "image_0" / f).string(), cv::IMREAD_GRAYSCALE);
    const cv::Mat r = cv::imread((root / "image_1" / f).string(), cv::IMREAD_GRAYSCALE);
    ASSERT_FALSE(l.empty() || r.empty()) << f;
    const auto fl = features::extract_lines(l, o);
    const auto t0 = std::chrono::steady_clock::now();
    const auto g = match_stereo_lines_guided(fl, l, r, k);
    ms += std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    const auto d = match_stereo_lines(fl, features::extract_lines(r, o), k);
    guided.push_back(static_cast<double>(g.size()));
    detected.push_back(static_cast<double>(d.size()));
    // Where both matchers pair a left line, their endpoint disparities agree.
    int both = 0, agree = 0;
    for (const auto& x : g) {
      EXPECT_GT(x.P_start.z(), 0.5);
      EXPECT_GT(x.P_end.z(), 0.5);
      for (const auto& y : d) {
        if (y.left != x.left) continue;
        ++both;
        agree += std::fabs(x.disparity_start - y.disparity_start) < 1.0 && std::fabs(x.disparity_end - y.disparity_end) < 1.0;
      }
    }
    ASSERT_GT(both, 0) << f;
    agree_share.push_back(static_cast<double>(agree) / both);
  }
  std::printf("KITTI 06 stereo lines, guided: %.0f %.0f %.0f, detect-and-describe: %.0f %.0f %.0f; agreeing where both "
              "match: %.2f %.2f %.2f; guided search %.2f ms per frame (not a timing test)\n",
              guided[0], guided[1], guided[2], detected[0], detected[1], detected[2], agree_share[0], agree_share[1],
              agree_share[2], ms / 3);
  for (std::size_t i = 0; i < guided.size(); ++i) {
    EXPECT_GE(guided[i], 0.6 * detected[i]) << "frame " << i;
    EXPECT_GE(agree_share[i], 0.6) << "frame " << i;
  }
}

}  // namespace
}  // namespace plslam::matching
