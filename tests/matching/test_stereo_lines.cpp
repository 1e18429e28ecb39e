// Stereo line matching: endpoint depth against the synthetic scene's exact geometry, the
// rejection of near-horizontal lines, line coefficients, and counts on KITTI 06.
#include <cstdio>

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>

#include "features/line_synthetic_scene.h"
#include "plslam/matching/stereo_line_matcher.h"
#include "support/test_support.h"

namespace plslam::matching {
namespace {

using features::LineSegment;

TEST(StereoLines, EndpointDepthWithinTwoPercentOnSyntheticScene) {
  const auto s = test::make_line_scene(false);
  const auto fl = features::extract_lines(s.left), fr = features::extract_lines(s.right);
  const auto matches = match_stereo_lines(fl, fr, s.calib);
  int on_gt = 0, within = 0;
  double worst = 0;
  for (const auto& m : matches) {
    const LineSegment& l = fl.lines[m.left];
    for (const auto& e : s.edges) {
      if (!test::on_edge(l, e)) continue;
      ++on_gt;
      const double es = std::fabs(m.P_start.z() - s.depth_at(e, l.start)) / s.depth_at(e, l.start);
      const double ee = std::fabs(m.P_end.z() - s.depth_at(e, l.end)) / s.depth_at(e, l.end);
      worst = std::max({worst, es, ee});
      within += es < 0.02 && ee < 0.02;
      // X and Y follow from the same depth through the pixel.
      EXPECT_NEAR(m.P_start.x() / m.P_start.z(), (l.start.x - s.calib.cx) / s.calib.fx, 1e-9);
      EXPECT_NEAR(m.P_end.y() / m.P_end.z(), (l.end.y - s.calib.cy) / s.calib.fy, 1e-9);
      break;
    }
  }
  std::printf("synthetic stereo: %zu matches, %d on GT edges, %d within 2%% depth, worst %.4f\n", matches.size(),
              on_gt, within, worst);
  // Every quad edge that is not near-horizontal (about 20 of them) should be matched.
  EXPECT_GE(on_gt, 16) << matches.size() << " matches";
  EXPECT_GE(static_cast<double>(on_gt) / matches.size(), 0.95);
  EXPECT_GE(static_cast<double>(within) / on_gt, 0.95) << "worst relative depth error " << worst;
}

TEST(StereoLines, NearHorizontalLinesAreRejected) {
  const auto s = test::make_line_scene(false);
  const auto fl = features::extract_lines(s.left), fr = features::extract_lines(s.right);
  const auto matches = match_stereo_lines(fl, fr, s.calib);
  ASSERT_FALSE(matches.empty());
  for (const auto& m : matches) {
    const cv::Point2f d = fl.lines[m.left].direction();
    EXPECT_GE(std::fabs(d.y), std::sin(10 * CV_PI / 180));
  }
  // The aligned quads' horizontal edges exist in both images but never match.
  int horizontal_detected = 0;
  for (const auto& l : fl.lines) horizontal_detected += std::fabs(l.direction().y) < 0.01 && l.length() > 80;
  EXPECT_GE(horizontal_detected, 3);
  // A pure horizontal-edge pair gives no match at all.
  cv::Mat a(200, 300, CV_8U, cv::Scalar(60)), b;
  a.rowRange(100, 200).setTo(200);
  b = a.clone();
  const StereoCalibration k{300, 200, 300, 300, 150, 100, 0.1};
  const auto ha = features::extract_lines(a), hb = features::extract_lines(b);
  ASSERT_FALSE(ha.lines.empty());
  EXPECT_TRUE(match_stereo_lines(ha, hb, k).empty());
}

TEST(StereoLines, LineCoefficientsAndRowIntersection) {
  const cv::Point2f ps(100, 50), pe(300, 250);
  const Eigen::Vector3d l = line_coefficients(ps, pe);
  const Eigen::Vector3d hs(100, 50, 1), he(300, 250, 1);
  EXPECT_NEAR(l.dot(hs), 0, 1e-12);
  EXPECT_NEAR(l.dot(he), 0, 1e-12);
  EXPECT_NEAR(l.norm(), hs.cross(he).norm() / (hs.norm() * he.norm()), 1e-12);
  EXPECT_NEAR(column_at_row(LineSegment{ps, pe}, 150), 200, 1e-4);
}

TEST(StereoLines, ConstructedPairGivesExactDisparities) {
  // A tilted bright bar; the right image holds it 12 px to the left.
  const auto [a, b] = test::make_bar_pair(12);
  const StereoCalibration k{320, 240, 300, 300, 160, 120, 0.1};
  const auto fa = features::extract_lines(a), fb = features::extract_lines(b);
  const auto m = match_stereo_lines(fa, fb, k);
  ASSERT_EQ(m.size(), 2u);  // the two long slanted sides
  for (const auto& x : m) {
    EXPECT_NEAR(x.disparity_start, 12, 0.25);
    EXPECT_NEAR(x.disparity_end, 12, 0.25);
    EXPECT_NEAR(x.P_start.z(), k.bf() / 12, 0.02 * k.bf() / 12);
  }
}

TEST(StereoLines, KittiFramesGiveManyMatches) {
  PLSLAM_REQUIRE_SHARED_DATA(data);
  const StereoCalibration k{1226, 370, 707.0912, 707.0912, 601.8873, 183.1104, 379.8145 / 707.0912};
  const auto root = data / "kitti/sequences/06";
  std::vector<double> counts;
  for (const char* f : {"000000.png", "000025.png", "000050.png"}) {
    const cv::Mat l = cv::imread((root / "image_0" / f).string(), cv::IMREAD_GRAYSCALE);
    const cv::Mat r = cv::imread((root / "image_1" / f).string(), cv::IMREAD_GRAYSCALE);
    ASSERT_FALSE(l.empty() || r.empty()) << f;
    const auto o = features::LineExtractorOptions::kitti();
    const auto m = match_stereo_lines(features::extract_lines(l, o), features::extract_lines(r, o), k);
    counts.push_back(static_cast<double>(m.size()));
    // Depths are physical: in front, and not absurdly far for a street.
    for (const auto& x : m) {
      EXPECT_GT(x.P_start.z(), 0.5);
      EXPECT_GT(x.P_end.z(), 0.5);
    }
  }
  std::sort(counts.begin(), counts.end());
  std::printf("KITTI 06 stereo line matches: %.0f %.0f %.0f\n", counts[0], counts[1], counts[2]);
  EXPECT_GE(counts[1], 100) << "median stereo line matches";
}

}  // namespace
}  // namespace plslam::matching
