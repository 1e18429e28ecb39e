// Stereo point matching: exact depths on synthetic fronto-parallel planes, and the share of left
// keypoints that get a depth on real KITTI 06 and EuRoC frames.
#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <random>
#include <vector>

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

// The SAD curve from its definition, written out here: the sum over the window of |l - r - o|,
// with o the rounded difference of the window means.
std::vector<int> sad_by_definition(const cv::Mat& l, int xl, int y, const cv::Mat& r, int xr0, int hw, int search) {
  const int n = (2 * hw + 1) * (2 * hw + 1);
  std::vector<int> out;
  for (int s = -search; s <= search; ++s) {
    long sum_l = 0, sum_r = 0;
    for (int dy = -hw; dy <= hw; ++dy)
      for (int dx = -hw; dx <= hw; ++dx) {
        sum_l += l.at<uchar>(y + dy, xl + dx);
        sum_r += r.at<uchar>(y + dy, xr0 + s + dx);
      }
    const long diff = sum_l - sum_r;
    const long o = (diff + (diff >= 0 ? n / 2 : -n / 2)) / n;
    int total = 0;
    for (int dy = -hw; dy <= hw; ++dy)
      for (int dx = -hw; dx <= hw; ++dx)
        total += static_cast<int>(std::labs(l.at<uchar>(y + dy, xl + dx) - r.at<uchar>(y + dy, xr0 + s + dx) - o));
    out.push_back(total);
  }
  return out;
}

TEST(StereoPoints, SadCurveLanesEqualTheDefinition) {
  std::mt19937 rng(7);
  cv::Mat left(64, 96, CV_8U), right(64, 96, CV_8U);
  // Random texture, and in the top-left corner a black and white checkerboard against its
  // inverse: there the sums reach their bound (255 per pixel), which the 16-bit lanes must hold.
  cv::randu(left, 0, 256);
  cv::randu(right, 0, 256);
  for (int y = 0; y < 24; ++y)
    for (int x = 0; x < 40; ++x) {
      const bool white = (x + y) % 2 == 0;
      if (x < 24) left.at<uchar>(y, x) = white ? 255 : 0;
      right.at<uchar>(y, x) = white ? 0 : 255;
    }
  int checked = 0;
  for (const auto& [hw, search] : {std::pair{5, 5}, std::pair{3, 2}, std::pair{5, 9}, std::pair{7, 5}, std::pair{1, 1}}) {
    std::uniform_int_distribution<int> x(hw + search + 2, 96 - hw - search - 3), yy(hw, 63 - hw);
    std::vector<std::pair<int, int>> places = {{10, 10}, {hw + 1, hw}};  // the white/black corner
    for (int i = 0; i < 40; ++i) places.emplace_back(x(rng), yy(rng));
    for (const auto& [xl, y] : places) {
      const int xr0 = std::clamp(xl + static_cast<int>(rng() % 7) - 3, hw + search, 95 - hw - search);
      const auto expected = sad_by_definition(left, xl, y, right, xr0, hw, search);
      for (const auto code : {detail::SadCode::kAuto, detail::SadCode::kSse2, detail::SadCode::kPlain}) {
        std::vector<int> sad(expected.size());
        detail::zero_mean_sad_curve(left, xl, y, right, xr0, hw, search, code, sad.data());
        ASSERT_EQ(sad, expected) << "code " << static_cast<int>(code) << " hw " << hw << " search " << search
                                 << " at " << xl << "," << y;
      }
      ++checked;
    }
  }
  EXPECT_EQ(checked, 5 * 42);
  // The corner: at shift 0 every pixel differs by 255 and the means by about 2, so the sum is
  // close to 121 * 255; one pixel either way the patterns agree and the sum is 0.
  std::vector<int> corner(11);
  detail::zero_mean_sad_curve(left, 10, 10, right, 10, 5, 5, detail::SadCode::kAuto, corner.data());
  EXPECT_GE(corner[5], 120 * 255);
  EXPECT_EQ(corner[4], 0);
  EXPECT_EQ(corner[6], 0);
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
