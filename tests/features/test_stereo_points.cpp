// Stereo point matching: exact depths on synthetic fronto-parallel planes, and the share of left
// keypoints that get a depth on real KITTI 06 and EuRoC frames.
#include <algorithm>
#include <cmath>

#include <gtest/gtest.h>

#include "features/points_synthetic.h"
#include "plslam/core/error.h"
#include "plslam/io/dataset.h"
#include "plslam/matching/stereo_point_frame.h"
#include "support/test_support.h"

namespace plslam::matching {
namespace {

TEST(StereoPoints, OptionsValidation) {
  StereoPointOptions o;
  EXPECT_THROW(o.validate(), InputError);  // bf unset
  o.bf = 400;
  EXPECT_THROW(o.validate(), InputError);  // min_depth 0 needs the baseline
  o.baseline = 0.5;
  EXPECT_NO_THROW(o.validate());
  o.max_hamming = 300;
  EXPECT_THROW(o.validate(), InputError);
}

struct DepthCheck {
  int matched = 0, within = 0, total = 0;
};

DepthCheck check_depths(const StereoPointFrame& f, const std::vector<double>& row_depth, double rel_tol) {
  DepthCheck c;
  c.total = static_cast<int>(f.left.keypoints.size());
  for (std::size_t i = 0; i < f.left.keypoints.size(); ++i) {
    if (!(f.stereo.depth[i] > 0)) continue;
    ++c.matched;
    const int y = static_cast<int>(std::lround(f.left.keypoints[i].pt.y));
    const double truth = row_depth[static_cast<std::size_t>(y)];
    if (std::abs(f.stereo.depth[i] - truth) <= rel_tol * truth) ++c.within;
    EXPECT_NEAR(f.stereo.u_right[i], f.left.keypoints[i].pt.x - 400.0 / f.stereo.depth[i], 1e-2);
  }
  return c;
}

TEST(StereoPoints, SyntheticPlanesGiveDepthsWithinOnePercent) {
  const double bf = 400.0, baseline = 0.5;
  // Fractional disparities 62.3, 41.7 and 27.9 px.
  const std::vector<double> depths = {bf / 62.3, bf / 41.7, bf / 27.9};
  const auto scene = test::synthetic_plane_stereo(cv::Size(752, 480), bf, depths);
  const features::OrbOptions oo;
  const features::OrbExtractor ex(oo), ex_right(right_image_options(oo));
  StereoPointOptions so;
  so.bf = bf;
  so.baseline = baseline;
  const StereoPointFrame f = extract_stereo_points(ex, ex_right, scene.left, scene.right, so);
  const DepthCheck c = check_depths(f, scene.row_depth, 0.01);
  const auto& r = f.stereo.rejected;
  std::cout << "rejections: none " << r.no_candidate << " hamming " << r.hamming << " window " << r.window
            << " sad_edge " << r.sad_edge << " disparity " << r.disparity << " outlier " << r.sad_outlier << "\n";
  EXPECT_EQ(c.matched, f.stereo.matched);
  EXPECT_GT(c.matched, 0.55 * c.total) << c.matched << " of " << c.total;
  EXPECT_GE(c.within, 0.95 * c.matched) << c.within << " of " << c.matched;
}

TEST(StereoPoints, SubPixelDisparityErrorIsSmallAtLevelZero) {
  // One plane, disparity 33.37 px: level-0 points must be within 0.2 px of the truth.
  const double bf = 400.0, d = 33.37;
  const auto scene = test::synthetic_plane_stereo(cv::Size(640, 480), bf, {bf / d}, 5);
  const features::OrbExtractor ex;
  StereoPointOptions so;
  so.bf = bf;
  so.baseline = 0.5;
  const StereoPointFrame f = extract_stereo_points(ex, ex, scene.left, scene.right, so);
  std::vector<double> err;
  for (std::size_t i = 0; i < f.left.keypoints.size(); ++i)
    if (f.stereo.depth[i] > 0 && f.left.keypoints[i].octave == 0)
      err.push_back(std::abs(f.left.keypoints[i].pt.x - f.stereo.u_right[i] - d));
  ASSERT_GT(err.size(), 100u);
  std::sort(err.begin(), err.end());
  EXPECT_LT(err[err.size() / 2], 0.1);
  EXPECT_LT(err[err.size() * 95 / 100], 0.2);
}

// Other SAD windows and search ranges than the default (9x9 over 19 shifts, 5x5 over 3, 15x15
// over 9) keep the sub-pixel accuracy of the default.
TEST(StereoPoints, OtherSadWindowsAndSearchRangesStayAccurate) {
  const double bf = 400.0, d = 33.37;
  const auto scene = test::synthetic_plane_stereo(cv::Size(640, 480), bf, {bf / d}, 5);
  const features::OrbExtractor ex;
  for (const auto& [hw, search] : {std::pair{4, 9}, std::pair{2, 1}, std::pair{7, 4}, std::pair{5, 5}}) {
    StereoPointOptions so;
    so.bf = bf;
    so.baseline = 0.5;
    so.sad_half_window = hw;
    so.sad_search = search;
    const StereoPointFrame f = extract_stereo_points(ex, ex, scene.left, scene.right, so);
    std::vector<double> err;
    for (std::size_t i = 0; i < f.left.keypoints.size(); ++i)
      if (f.stereo.depth[i] > 0 && f.left.keypoints[i].octave == 0)
        err.push_back(std::abs(f.left.keypoints[i].pt.x - f.stereo.u_right[i] - d));
    ASSERT_GT(err.size(), 100u) << "window " << hw << " search " << search;
    std::sort(err.begin(), err.end());
    EXPECT_LT(err[err.size() / 2], 0.1) << "window " << hw << " search " << search;
    EXPECT_LT(err[err.size() * 95 / 100], 0.25) << "window " << hw << " search " << search;
  }
}

// Pixel locking: a sub-pixel fit that does not match the SAD curve's shape pulls disparities to
// whole pixels, most at fractions 0.2 and 0.8 (the parabola: -0.10 and +0.10 px mean error at
// level 0 on these planes, 0.10 px mean absolute error; the equiangular fit: -0.03, +0.03, 0.03).
TEST(StereoPoints, SubPixelDisparitiesAreNotPulledToWholePixels) {
  const double bf = 400.0;
  for (const double d : {20.2, 20.5, 20.8, 40.2, 40.8}) {
    const auto scene = test::synthetic_plane_stereo(cv::Size(640, 480), bf, {bf / d}, 5);
    const features::OrbOptions oo;
    const features::OrbExtractor ex(oo), ex_right(right_image_options(oo));
    StereoPointOptions so;
    so.bf = bf;
    so.baseline = 0.5;
    const StereoPointFrame f = extract_stereo_points(ex, ex_right, scene.left, scene.right, so);
    double signed_sum = 0, abs_sum = 0;
    int n = 0;
    for (std::size_t i = 0; i < f.left.keypoints.size(); ++i) {
      if (!(f.stereo.depth[i] > 0) || f.left.keypoints[i].octave != 0) continue;
      const double e = f.left.keypoints[i].pt.x - f.stereo.u_right[i] - d;
      if (std::abs(e) > 1) continue;  // a wrong match, not a sub-pixel error
      signed_sum += e;
      abs_sum += std::abs(e);
      ++n;
    }
    ASSERT_GT(n, 150) << "disparity " << d;
    EXPECT_LT(std::abs(signed_sum / n), 0.05) << "disparity " << d;
    EXPECT_LT(abs_sum / n, 0.05) << "disparity " << d;
  }
}

TEST(StereoPoints, DisparityRangeExcludesTooNearPoints) {
  // Everything at disparity 62 px, but z_min set so that d_max = bf / z_min = 40 px.
  const double bf = 400.0;
  const auto scene = test::synthetic_plane_stereo(cv::Size(640, 480), bf, {bf / 62.0}, 6);
  const features::OrbExtractor ex;
  StereoPointOptions so;
  so.bf = bf;
  so.min_depth = bf / 40.0;
  const StereoPointFrame f = extract_stereo_points(ex, ex, scene.left, scene.right, so);
  // Only wrong matches can survive, and none of them at the true (too near) depth.
  int at_truth = 0;
  for (std::size_t i = 0; i < f.left.keypoints.size(); ++i)
    if (f.stereo.depth[i] > 0) {
      EXPECT_GE(f.stereo.depth[i], so.min_depth * 0.999);
      if (std::abs(f.stereo.depth[i] - bf / 62.0) < 0.05 * bf / 62.0) ++at_truth;
    }
  EXPECT_EQ(at_truth, 0);
  EXPECT_LT(f.stereo.matched, 0.15 * static_cast<double>(f.left.keypoints.size()));
}

double depth_share_on_first_frame(const std::filesystem::path& seq, int n_features, double* median_depth) {
  const auto ds = io::open_dataset(seq);
  const io::StereoFrame frame = ds->load(0);
  features::OrbOptions oo;
  oo.n_features = n_features;
  const features::OrbExtractor ex(oo), ex_right(right_image_options(oo));
  StereoPointOptions so;
  so.bf = ds->calibration().bf();
  so.baseline = ds->calibration().baseline;
  const StereoPointFrame f = extract_stereo_points(ex, ex_right, frame.left, frame.right, so);
  const auto& r = f.stereo.rejected;
  std::cout << "rejections: none " << r.no_candidate << " hamming " << r.hamming << " window " << r.window
            << " sad_edge " << r.sad_edge << " disparity " << r.disparity << " outlier " << r.sad_outlier << "\n";
  std::vector<float> depths;
  for (float z : f.stereo.depth)
    if (z > 0) depths.push_back(z);
  std::nth_element(depths.begin(), depths.begin() + static_cast<std::ptrdiff_t>(depths.size() / 2), depths.end());
  *median_depth = depths.empty() ? 0.0 : depths[depths.size() / 2];
  return static_cast<double>(f.stereo.matched) / static_cast<double>(f.left.keypoints.size());
}

TEST(StereoPoints, Kitti06MostLeftKeypointsGetDepth) {
  PLSLAM_REQUIRE_SHARED_DATA(data);
  double median_depth = 0;
  const double share = depth_share_on_first_frame(data / "kitti/sequences/06", 2000, &median_depth);
  std::cout << "KITTI 06 frame 0: " << 100 * share << " % of left keypoints with depth, median depth "
            << median_depth << " m\n";
  EXPECT_GE(share, 0.60);
  EXPECT_GT(median_depth, 3.0);   // a street scene: metres to tens of metres
  EXPECT_LT(median_depth, 60.0);
}

TEST(StereoPoints, EurocMicroManyLeftKeypointsGetDepth) {
  PLSLAM_REQUIRE_SHARED_DATA(data);
  double median_depth = 0;
  const double share = depth_share_on_first_frame(data / "euroc/V1_01_easy_micro", 1200, &median_depth);
  std::cout << "EuRoC V1_01 micro frame 0: " << 100 * share << " % of left keypoints with depth, median depth "
            << median_depth << " m\n";
  EXPECT_GE(share, 0.40);
  EXPECT_GT(median_depth, 1.0);  // a room a few metres across
  EXPECT_LT(median_depth, 15.0);
}

}  // namespace
}  // namespace plslam::matching
