// Pyramid, orientation, BRIEF pattern, the ORB extractor end to end, and descriptor invariance
// to rotation and scale.
#include <algorithm>
#include <bit>
#include <cmath>
#include <cstring>
#include <functional>
#include <random>

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "features/points_synthetic.h"
#include "plslam/core/error.h"
#include "plslam/features/fast_gaussian.h"
#include "plslam/features/orb_descriptor.h"
#include "plslam/features/orb_extractor.h"
#include "support/test_support.h"

namespace plslam::features {
namespace {

TEST(ImagePyramid, LevelSizesCoordinateMapsAndBorder) {
  const cv::Mat img = test::points_texture(cv::Size(752, 480));
  ImagePyramid p;
  p.build(img, 8, 1.2, 19);
  ASSERT_EQ(p.levels(), 8);
  for (int l = 0; l < 8; ++l) {
    EXPECT_EQ(p.level(l).cols, static_cast<int>(std::lround(752 / std::pow(1.2, l))));
    EXPECT_EQ(p.level(l).rows, static_cast<int>(std::lround(480 / std::pow(1.2, l))));
    EXPECT_NEAR(p.scale(l), std::pow(1.2, l), 1e-12);
    EXPECT_NEAR(p.to_level_x(p.from_level_x(17.f, l), l), 17.f, 1e-4);
    EXPECT_NEAR(p.to_level_y(p.from_level_y(9.f, l), l), 9.f, 1e-4);
  }
  EXPECT_EQ(cv::norm(p.level(0), img, cv::NORM_INF), 0.0);
  // Reflect-101 border: the pixel 3 left of column 0 equals column 3.
  const cv::Mat& pad = p.padded(2);
  for (int y = 19; y < pad.rows - 19; y += 37) {
    EXPECT_EQ(pad.at<uchar>(y, 19 - 3), pad.at<uchar>(y, 19 + 3));
    EXPECT_EQ(pad.at<uchar>(y, pad.cols - 19 + 2), pad.at<uchar>(y, pad.cols - 19 - 4));
  }
  // Level 1 is a bilinear shrink of level 0: a smooth region's mean is preserved.
  EXPECT_NEAR(cv::mean(p.level(1))[0], cv::mean(img)[0], 1.0);
}

TEST(FastGaussian, MatchesOpenCvGaussianBlurWithinTwoGreyLevels) {
  const cv::Mat img = test::points_texture(cv::Size(300, 200), 3);
  const cv::Rect rect(3, 3, 294, 194);
  cv::Mat ours, ref;
  gaussian_blur_7x7(img, rect, ours);
  cv::GaussianBlur(img, ref, cv::Size(7, 7), 2.0, 2.0, cv::BORDER_REFLECT_101);
  ASSERT_EQ(ours.size(), rect.size());
  EXPECT_LE(cv::norm(ours, ref(rect), cv::NORM_INF), 2.0);
  // A constant image stays constant (the fixed-point kernel sums to exactly 1).
  const cv::Mat flat(50, 50, CV_8U, cv::Scalar(173));
  gaussian_blur_7x7(flat, cv::Rect(3, 3, 44, 44), ours);
  EXPECT_EQ(cv::norm(ours, cv::Mat(44, 44, CV_8U, cv::Scalar(173)), cv::NORM_INF), 0.0);
  EXPECT_THROW(gaussian_blur_7x7(flat, cv::Rect(2, 3, 44, 44), ours), std::invalid_argument);
}

TEST(FastGaussian, BaselineAndDispatchedCodeGiveTheSameBytes) {
  // Random noise reaches every sum the 16-bit lanes hold; odd widths leave vector remainders.
  cv::Mat img(123, 301, CV_8U);
  cv::randu(img, 0, 256);
  img(cv::Rect(0, 0, 40, 40)).setTo(255);
  for (const cv::Rect rect : {cv::Rect(3, 3, 295, 117), cv::Rect(5, 4, 17, 9), cv::Rect(3, 3, 1, 1)}) {
    cv::Mat dispatched, baseline;
    gaussian_blur_7x7(img, rect, dispatched);
    detail::gaussian_blur_7x7_baseline(img, rect, baseline);
    ASSERT_EQ(dispatched.size(), rect.size());
    EXPECT_EQ(cv::norm(dispatched, baseline, cv::NORM_INF), 0.0) << rect;
  }
  // Saturated input stays saturated: the largest sums do not wrap.
  cv::Mat white;
  gaussian_blur_7x7(img, cv::Rect(3, 3, 30, 30), white);
  EXPECT_EQ(cv::countNonZero(white != 255), 0);
}

TEST(OrbDescriptor, PatternIsDeterministicBoundedAndNonDegenerate) {
  const auto& p = brief_pattern();
  int left_of_centre = 0;
  for (const auto& t : p) {
    for (int c : t) EXPECT_LE(std::abs(c), kBriefPatternHalfExtent);
    EXPECT_FALSE(t[0] == t[2] && t[1] == t[3]);
    if (t[0] < 0) ++left_of_centre;
  }
  EXPECT_GT(left_of_centre, 80);  // a Gaussian spread, not a degenerate line
  EXPECT_LT(left_of_centre, 150);
  // Fixed seed: the first pair never changes between builds or platforms.
  const auto first = p[0];
  EXPECT_EQ(first, brief_pattern()[0]);
}

TEST(OrbDescriptor, IntensityCentroidPointsToTheBrightSide) {
  cv::Mat img(64, 64, CV_8U, cv::Scalar(20));
  img(cv::Rect(32, 0, 32, 64)).setTo(200);  // bright right half -> 0 degrees
  EXPECT_NEAR(intensity_centroid_angle(img, 32, 32), 0.0, 3.0);
  img.setTo(20);
  img(cv::Rect(0, 33, 64, 31)).setTo(200);  // bright below (y down) -> 90 degrees
  EXPECT_NEAR(intensity_centroid_angle(img, 32, 32), 90.0, 3.0);
  img.setTo(20);
  img(cv::Rect(0, 0, 31, 64)).setTo(200);  // bright left -> 180 degrees
  EXPECT_NEAR(intensity_centroid_angle(img, 32, 32), 180.0, 3.0);
}

TEST(OrbDescriptor, BaselineAndDispatchedCodeGiveTheSameResults) {
  cv::Mat img(120, 160, CV_8U);
  cv::randu(img, 0, 256);
  cv::Mat blurred;
  gaussian_blur_7x7(img, cv::Rect(3, 3, 154, 114), blurred);
  std::mt19937 rng(3);
  std::uniform_int_distribution<int> coord(20, 90);
  int bits_set = 0;
  for (int i = 0; i < 200; ++i) {
    const int x = coord(rng) + 20, y = coord(rng);
    const float angle = intensity_centroid_angle(img, x, y);
    ASSERT_EQ(angle, detail::intensity_centroid_angle_baseline(img, x, y)) << x << "," << y;
    // Any angle, not only the centroid's: each rotation rounds the pattern differently.
    for (const float a : {angle, 0.f, 37.5f, 359.9f}) {
      uint8_t dispatched[32], baseline[32];
      brief_descriptor(blurred, x, y, a, dispatched);
      detail::brief_descriptor_baseline(blurred, x, y, a, baseline);
      ASSERT_EQ(std::memcmp(dispatched, baseline, 32), 0) << x << "," << y << " angle " << a;
      for (const uint8_t b : dispatched) bits_set += std::popcount(b);
    }
  }
  // Random texture: about half the tests come out set.
  EXPECT_NEAR(bits_set / (200.0 * 4 * 256), 0.5, 0.05);
}

TEST(OrbDescriptor, HammingDistance) {
  uint8_t a[32] = {}, b[32] = {};
  EXPECT_EQ(hamming_distance(a, b), 0);
  b[0] = 0xFF;
  b[31] = 0x01;
  EXPECT_EQ(hamming_distance(a, b), 9);
}

TEST(OrbExtractor, OptionsValidation) {
  OrbOptions o;
  EXPECT_NO_THROW(o.validate());
  EXPECT_EQ(OrbOptions::kitti().n_features, 2000);
  o.n_features = 0;
  EXPECT_THROW(o.validate(), InputError);
  o = {};
  o.scale_factor = 1.0;
  EXPECT_THROW(OrbExtractor{o}, InputError);
  o = {};
  o.fast_min_threshold = 30;
  EXPECT_THROW(o.validate(), InputError);
  EXPECT_EQ(parse_distribution("quadtree"), Distribution::kQuadtree);
  EXPECT_THROW(parse_distribution("grid"), InputError);
  EXPECT_EQ(parse_fast_mode("ini_min"), FastMode::kIniMin);
  EXPECT_THROW(OrbExtractor().extract(cv::Mat()), InputError);
}

TEST(OrbExtractor, ExtractsTheRequestedCountInsideTheImageDeterministically) {
  const cv::Mat img = test::points_texture(cv::Size(752, 480));
  for (const auto method : {Distribution::kSsc, Distribution::kQuadtree}) {
    OrbOptions o;
    o.distribution = method;
    const OrbExtractor ex(o);
    ExtractionTimings t;
    const PointFeatures f = ex.extract(img, &t);
    EXPECT_EQ(static_cast<int>(f.keypoints.size()), 1200) << to_string(method);
    EXPECT_EQ(f.descriptors.rows, 1200);
    EXPECT_EQ(f.descriptors.cols, 32);
    EXPECT_EQ(f.descriptors.type(), CV_8U);
    EXPECT_GT(t.fast_candidates, 1200);
    EXPECT_GT(t.total_ms(), 0.0);
    std::vector<int> per_level(8, 0);
    for (const auto& k : f.keypoints) {
      ASSERT_GE(k.octave, 0);
      ASSERT_LT(k.octave, 8);
      ++per_level[static_cast<std::size_t>(k.octave)];
      const float margin = 15.f * static_cast<float>(std::pow(1.2, k.octave));
      EXPECT_GE(k.pt.x, margin);
      EXPECT_LT(k.pt.x, 752.f - margin);
      EXPECT_GE(k.pt.y, margin);
      EXPECT_LT(k.pt.y, 480.f - margin);
      EXPECT_NEAR(k.size, 31.0 * std::pow(1.2, k.octave), 1e-3);
      EXPECT_GE(k.angle, 0.f);
      EXPECT_LT(k.angle, 360.f);
    }
    // Shares follow the level areas: level 0 holds the most, each next level fewer.
    for (int l = 1; l < 8; ++l) EXPECT_LT(per_level[static_cast<std::size_t>(l)], per_level[static_cast<std::size_t>(l - 1)]);
    const PointFeatures g = ex.extract(img);
    ASSERT_EQ(g.keypoints.size(), f.keypoints.size());
    EXPECT_EQ(cv::norm(f.descriptors, g.descriptors, cv::NORM_HAMMING), 0.0);
  }
}

TEST(OrbExtractor, IniMinModeAndShortLevelsStillFillTheBudget) {
  const cv::Mat img = test::points_texture(cv::Size(640, 480));
  OrbOptions o;
  o.fast_mode = FastMode::kIniMin;
  o.n_features = 1000;
  EXPECT_EQ(OrbExtractor(o).extract(img).keypoints.size(), 1000u);
  // Strong corners are all kept; weak ones only where a cell has no strong one, so far fewer.
  {
    OrbOptions single = o;
    single.fast_mode = FastMode::kSingle;
    single.fast_threshold = o.fast_min_threshold;
    ImagePyramid pyr;
    OrbExtractor(single).build_pyramid(img, pyr);
    const auto all = OrbExtractor(single).detect(pyr)[0].corners;
    const auto mixed = OrbExtractor(o).detect(pyr)[0].corners;
    std::size_t strong = 0;
    for (const uint8_t s : all.score) strong += s >= o.fast_ini_threshold;
    std::size_t mixed_strong = 0;
    for (const uint8_t s : mixed.score) mixed_strong += s >= o.fast_ini_threshold;
    EXPECT_EQ(mixed_strong, strong);
    EXPECT_LT(mixed.size(), all.size());
    EXPECT_GE(mixed.size(), strong);
  }
  // A budget no level can meet alone: deficits move to other levels, and when every candidate is
  // used the extractor returns all of them.
  const OrbExtractor ex(o);
  ImagePyramid p;
  ex.build_pyramid(img, p);
  PyramidCandidates c = ex.detect(p);
  c[7].corners.resize(3);
  const auto targets = ex.level_targets(c);
  EXPECT_EQ(targets[7], 3);
  int sum = 0;
  for (int t : targets) sum += t;
  EXPECT_EQ(sum, 1000);
}

struct Correspondence {
  int hamming;
  bool nearest_is_true;
  float angle_change;
};

// Pairs each keypoint of `a` with the keypoint of `b` found where `map` sends it (same level
// shifted by `level_shift`), and reports their Hamming distance and whether b's descriptor
// nearest to a's is that one.
std::vector<Correspondence> correspondences(const PointFeatures& a, const PointFeatures& b, int level_shift,
                                            const std::function<cv::Point2f(cv::Point2f)>& map) {
  std::vector<Correspondence> out;
  for (int i = 0; i < static_cast<int>(a.keypoints.size()); ++i) {
    const auto& ka = a.keypoints[static_cast<std::size_t>(i)];
    const cv::Point2f q = map(ka.pt);
    const float tol = 1.5f * static_cast<float>(std::pow(1.2, ka.octave));
    int match = -1;
    for (int j = 0; j < static_cast<int>(b.keypoints.size()); ++j) {
      const auto& kb = b.keypoints[static_cast<std::size_t>(j)];
      if (kb.octave != ka.octave + level_shift) continue;
      if (cv::norm(kb.pt - q) < tol) match = j;
    }
    if (match < 0) continue;
    int best = -1, best_d = 1000;
    for (int j = 0; j < b.descriptors.rows; ++j) {
      const int d = hamming_distance(a.descriptors.ptr<uint8_t>(i), b.descriptors.ptr<uint8_t>(j));
      if (d < best_d) {
        best_d = d;
        best = j;
      }
    }
    float dang = b.keypoints[static_cast<std::size_t>(match)].angle - ka.angle;
    dang = std::fmod(dang + 540.f, 360.f) - 180.f;
    out.push_back({hamming_distance(a.descriptors.ptr<uint8_t>(i), b.descriptors.ptr<uint8_t>(match)), best == match, dang});
  }
  return out;
}

double median_of(std::vector<double> v) {
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2), v.end());
  return v[v.size() / 2];
}

void expect_invariant(const std::vector<Correspondence>& c, double expected_angle_change) {
  ASSERT_GE(c.size(), 100u);
  std::vector<double> ham, dang;
  int nearest = 0, under_threshold = 0;
  for (const auto& x : c) {
    ham.push_back(x.hamming);
    dang.push_back(std::abs(std::fmod(x.angle_change - expected_angle_change + 540.0, 360.0) - 180.0));
    nearest += x.nearest_is_true;
    under_threshold += x.hamming <= 50;
  }
  EXPECT_LT(median_of(ham), 35.0);
  EXPECT_GT(under_threshold, static_cast<int>(0.75 * static_cast<double>(c.size())));
  EXPECT_GT(nearest, static_cast<int>(0.8 * static_cast<double>(c.size())));
  EXPECT_LT(median_of(dang), 4.0);
}

TEST(OrbExtractor, DescriptorsSurviveImageRotation) {
  const cv::Mat img = test::points_texture(cv::Size(640, 480));
  OrbOptions o;
  o.n_features = 1500;
  const OrbExtractor ex(o);
  const PointFeatures a = ex.extract(img);
  for (const double deg : {30.0, 90.0, 135.0}) {
    const cv::Point2f c(319.5f, 239.5f);
    const cv::Mat M = cv::getRotationMatrix2D(c, deg, 1.0);
    cv::Mat rotated;
    cv::warpAffine(img, rotated, M, img.size(), cv::INTER_LINEAR, cv::BORDER_REFLECT_101);
    const PointFeatures b = ex.extract(rotated);
    auto map = [&](cv::Point2f p) {
      return cv::Point2f(static_cast<float>(M.at<double>(0, 0) * p.x + M.at<double>(0, 1) * p.y + M.at<double>(0, 2)),
                         static_cast<float>(M.at<double>(1, 0) * p.x + M.at<double>(1, 1) * p.y + M.at<double>(1, 2)));
    };
    // Only points whose neighbourhood stays inside both images.
    PointFeatures central;
    std::vector<int> rows;
    for (int i = 0; i < static_cast<int>(a.keypoints.size()); ++i)
      if (cv::norm(a.keypoints[static_cast<std::size_t>(i)].pt - c) < 170.f) {
        central.keypoints.push_back(a.keypoints[static_cast<std::size_t>(i)]);
        central.descriptors.push_back(a.descriptors.row(i));
      }
    SCOPED_TRACE(deg);
    // getRotationMatrix2D turns the picture counter-clockwise on screen; with y pointing down
    // the keypoint angles decrease by the same amount.
    expect_invariant(correspondences(central, b, 0, map), -deg);
  }
}

TEST(OrbExtractor, DescriptorsSurviveOneOctaveOfScale) {
  const cv::Mat img = test::points_texture(cv::Size(900, 600));
  const OrbExtractor ex;
  const PointFeatures a = ex.extract(img);
  cv::Mat small;
  cv::resize(img, small, cv::Size(750, 500), 0, 0, cv::INTER_LINEAR);  // exactly 1/1.2
  const PointFeatures b = ex.extract(small);
  PointFeatures upper;  // points of level >= 1 reappear one level lower in the shrunk image
  for (int i = 0; i < static_cast<int>(a.keypoints.size()); ++i)
    if (a.keypoints[static_cast<std::size_t>(i)].octave >= 1) {
      upper.keypoints.push_back(a.keypoints[static_cast<std::size_t>(i)]);
      upper.descriptors.push_back(a.descriptors.row(i));
    }
  auto map = [](cv::Point2f p) { return cv::Point2f((p.x + 0.5f) / 1.2f - 0.5f, (p.y + 0.5f) / 1.2f - 0.5f); };
  expect_invariant(correspondences(upper, b, -1, map), 0.0);
}

TEST(OrbExtractor, RandomPairsDoNotMatch) {
  const OrbExtractor ex;
  const PointFeatures a = ex.extract(test::points_texture(cv::Size(640, 480), 1));
  const PointFeatures b = ex.extract(test::points_texture(cv::Size(640, 480), 2));
  std::vector<double> d;
  for (int i = 0; i < 500; ++i) d.push_back(hamming_distance(a.descriptors.ptr<uint8_t>(i), b.descriptors.ptr<uint8_t>(i)));
  EXPECT_GT(median_of(d), 90.0);
}

}  // namespace
}  // namespace plslam::features
