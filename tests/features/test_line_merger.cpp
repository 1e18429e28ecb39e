// Hough mapping and merge rules on constructed segments.
#include <gtest/gtest.h>

#include "plslam/features/line_merger.h"

namespace plslam::features {
namespace {

LineSegment seg(float x0, float y0, float x1, float y1) { return {{x0, y0}, {x1, y1}}; }

const cv::Size kImage(752, 480);
const MergeFrame kFrame = MergeFrame::of(kImage);  // centre (375.5, 239.5)

TEST(LineHough, HorizontalVerticalAndWrap) {
  // Horizontal line 10 px below the centre: normal points down (theta = pi/2), rho = 10.
  const HoughLine h = to_hough(seg(100, 249.5f, 300, 249.5f), kFrame.centre);
  EXPECT_NEAR(h.theta, CV_PI / 2, 1e-6);
  EXPECT_NEAR(h.rho, 10.0, 1e-4);
  // The same line reversed has the same theta and rho (theta is taken modulo pi).
  const HoughLine hr = to_hough(seg(300, 249.5f, 100, 249.5f), kFrame.centre);
  EXPECT_NEAR(hr.theta, h.theta, 1e-6);
  EXPECT_NEAR(hr.rho, h.rho, 1e-4);
  // Vertical line 20 px left of the centre.
  const HoughLine v = to_hough(seg(355.5f, 10, 355.5f, 400), kFrame.centre);
  EXPECT_NEAR(hough_angle_difference(v.theta, 0.0), 0.0, 1e-6);
  EXPECT_NEAR(std::fabs(v.rho), 20.0, 1e-4);
  // Slightly tilted either way about vertical: angles near 0 and near pi are 1 degree apart.
  const double a = to_hough(seg(355.5f, 100, 357.f, 100 + 1.5f / std::tan(0.5 * CV_PI / 180)), kFrame.centre).theta;
  const double b = to_hough(seg(355.5f, 100, 354.f, 100 + 1.5f / std::tan(0.5 * CV_PI / 180)), kFrame.centre).theta;
  EXPECT_NEAR(hough_angle_difference(a, b), CV_PI / 180, 1e-4);
  EXPECT_GT(std::fabs(a - b), CV_PI / 2);  // they sit on opposite sides of the wrap
}

TEST(LineMerge, CollinearWithSmallGapMerges) {
  const LineMergeOptions o;
  const LineSegment a = seg(100, 200, 200, 230), b = seg(210, 233, 300, 260);  // same line y = 0.3x + 170
  EXPECT_TRUE(can_merge(a, b, kFrame, o));
  const auto m = merge_segments({a, b}, kImage, o);
  ASSERT_EQ(m.size(), 1u);
  EXPECT_EQ(m[0].fragments, 2);
  // Extended to the extreme projections, orientation kept.
  EXPECT_NEAR(m[0].start.x, 100, 0.05);
  EXPECT_NEAR(m[0].start.y, 200, 0.05);
  EXPECT_NEAR(m[0].end.x, 300, 0.05);
  EXPECT_NEAR(m[0].end.y, 260, 0.05);
}

TEST(LineMerge, CollinearAcrossThetaWrapMerges) {
  // Nearly vertical pieces on opposite sides of theta = 0 / pi, 0.4 degrees apart.
  const LineSegment a = seg(400, 100, 400.5f, 200), b = seg(400.6f, 210, 400.5f, 290);
  EXPECT_TRUE(can_merge(a, b, kFrame, {}));
}

TEST(LineMerge, GapBeyondThresholdDoesNotMerge) {
  const LineMergeOptions o;  // max gap 20 px
  EXPECT_FALSE(can_merge(seg(100, 100, 200, 100), seg(225, 100, 300, 100), kFrame, o));
  EXPECT_TRUE(can_merge(seg(100, 100, 200, 100), seg(215, 100, 300, 100), kFrame, o));
  // Distant collinear edges (two windows in a row) never fuse.
  EXPECT_EQ(merge_segments({seg(50, 100, 150, 100), seg(300, 100, 400, 100)}, kImage, o).size(), 2u);
}

TEST(LineMerge, ParallelOffsetDoesNotMerge) {
  // 3 px apart: two sides of a thin bar with the same polarity, must stay separate.
  EXPECT_FALSE(can_merge(seg(100, 100, 200, 100), seg(205, 103, 300, 103), kFrame, {}));
  // 1 px apart is within the endpoint tolerance of one noisy edge.
  EXPECT_TRUE(can_merge(seg(100, 100, 200, 100), seg(205, 101, 300, 101), kFrame, {}));
}

TEST(LineMerge, CrossingAndAngledDoNotMerge) {
  EXPECT_FALSE(can_merge(seg(100, 100, 300, 300), seg(100, 300, 300, 100), kFrame, {}));
  // 2 degrees apart sharing an endpoint region.
  const float dy = 100 * std::tan(2 * CV_PI / 180);
  EXPECT_FALSE(can_merge(seg(100, 100, 200, 100), seg(200, 100, 300, 100 + dy), kFrame, {}));
}

TEST(LineMerge, OppositePolarityAndLargeOverlapDoNotMerge) {
  EXPECT_FALSE(can_merge(seg(100, 100, 200, 100), seg(300, 100, 205, 100), kFrame, {}));
  LineMergeOptions o;
  o.same_polarity = false;
  EXPECT_TRUE(can_merge(seg(100, 100, 200, 100), seg(300, 100, 205, 100), kFrame, o));
  // Overlapping by 50 px along the line exceeds the overlap tolerance (10 px).
  EXPECT_FALSE(can_merge(seg(100, 100, 200, 100), seg(150, 100, 300, 100), kFrame, {}));
  EXPECT_TRUE(can_merge(seg(100, 100, 200, 100), seg(195, 100, 300, 100), kFrame, {}));
}

TEST(LineMerge, RefitIsLeastSquaresThroughEndpoints) {
  // Two pieces 1 px apart in y, equal length: the fused line runs midway, spanning both.
  const LineSegment f = fuse_segments(seg(0, 0, 100, 0), seg(110, 1, 210, 1));
  EXPECT_NEAR(f.start.x, 0, 0.6);
  EXPECT_NEAR(f.end.x, 210, 0.6);
  EXPECT_NEAR(0.5 * (f.start.y + f.end.y), 0.5, 0.05);
  EXPECT_EQ(f.fragments, 2);
  // A longer piece weighs more: the line leans towards it.
  const LineSegment g = fuse_segments(seg(0, 0, 300, 0), seg(310, 1, 330, 1));
  EXPECT_LT(0.5 * (g.start.y + g.end.y), 0.3);
}

TEST(LineMerge, ChainOfPiecesMergesToOneAndKeepBestSorts) {
  std::vector<LineSegment> v;
  for (int i = 0; i < 5; ++i) v.push_back(seg(50.f + 60 * i, 300, 100.f + 60 * i, 300));  // gaps of 10 px
  v.push_back(seg(100, 50, 100, 90));  // an unrelated short vertical one
  auto m = merge_segments(v, kImage, {});
  ASSERT_EQ(m.size(), 2u);
  keep_best(m, 1);
  ASSERT_EQ(m.size(), 1u);
  EXPECT_EQ(m[0].fragments, 5);
  EXPECT_NEAR(m[0].length(), 290, 0.1);
}

}  // namespace
}  // namespace plslam::features
