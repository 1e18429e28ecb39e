// Own FAST-9 detector: the segment test and score by their definition (brute force), and
// identical output to cv::FAST on synthetic and real images for every implementation.
#include <algorithm>
#include <array>
#include <vector>

#include <gtest/gtest.h>
#include <opencv2/features2d.hpp>

#include "features/points_synthetic.h"
#include "plslam/core/error.h"
#include "plslam/features/fast_detector.h"
#include "plslam/features/image_pyramid.h"
#include "plslam/io/dataset.h"
#include "support/test_support.h"

namespace plslam::features {
namespace {

constexpr std::array<std::array<int, 2>, 16> kCircle = {{{0, 3}, {1, 3}, {2, 2}, {3, 1}, {3, 0}, {3, -1}, {2, -2}, {1, -3},
                                                        {0, -3}, {-1, -3}, {-2, -2}, {-3, -1}, {-3, 0}, {-3, 1}, {-2, 2}, {-1, 3}}};

// The segment test as written in the FAST paper: 9 contiguous circle pixels all brighter than
// centre + t or all darker than centre - t.
bool segment_test(const cv::Mat& img, int x, int y, int t) {
  const int c = img.at<uchar>(y, x);
  for (int start = 0; start < 16; ++start) {
    bool bright = true, dark = true;
    for (int j = 0; j < 9; ++j) {
      const auto& o = kCircle[static_cast<std::size_t>((start + j) % 16)];
      const int p = img.at<uchar>(y + o[1], x + o[0]);
      bright = bright && p > c + t;
      dark = dark && p < c - t;
    }
    if (bright || dark) return true;
  }
  return false;
}

// Score by definition: the largest threshold at which the pixel is still a corner (0 if none).
int brute_score(const cv::Mat& img, int x, int y, int t) {
  if (!segment_test(img, x, y, t)) return 0;
  int s = t;
  while (s < 255 && segment_test(img, x, y, s + 1)) ++s;
  return s;
}

std::vector<cv::KeyPoint> brute_fast(const cv::Mat& img, int t) {
  cv::Mat score = cv::Mat::zeros(img.size(), CV_32S);
  for (int y = 3; y < img.rows - 3; ++y)
    for (int x = 3; x < img.cols - 3; ++x) score.at<int>(y, x) = brute_score(img, x, y, t);
  std::vector<cv::KeyPoint> out;
  for (int y = 3; y < img.rows - 3; ++y)
    for (int x = 3; x < img.cols - 3; ++x) {
      const int s = score.at<int>(y, x);
      bool max = s > 0;
      for (int dy = -1; dy <= 1 && max; ++dy)
        for (int dx = -1; dx <= 1 && max; ++dx)
          if ((dx || dy) && score.at<int>(y + dy, x + dx) >= s) max = false;
      if (max) out.emplace_back(cv::Point2f(static_cast<float>(x), static_cast<float>(y)), 7.f, -1.f, static_cast<float>(s));
    }
  return out;
}

std::vector<FastImpl> own_impls() {
  std::vector<FastImpl> v;
  for (FastImpl i : {FastImpl::kAvx2, FastImpl::kSse2, FastImpl::kScalar})
    if (fast_impl_available(i)) v.push_back(i);
  return v;
}

// Same positions, scores, sizes, angles and order.
void expect_same(const std::vector<cv::KeyPoint>& a, const std::vector<cv::KeyPoint>& b, const std::string& what) {
  ASSERT_EQ(a.size(), b.size()) << what;
  for (std::size_t i = 0; i < a.size(); ++i) {
    ASSERT_EQ(a[i].pt, b[i].pt) << what << " #" << i;
    ASSERT_EQ(a[i].response, b[i].response) << what << " #" << i << " at " << a[i].pt;
    ASSERT_EQ(a[i].size, b[i].size);
    ASSERT_EQ(a[i].angle, b[i].angle);
    ASSERT_EQ(a[i].octave, b[i].octave);
  }
}

TEST(Fast, ScoreOfAHandMadeCornerIsItsWeakestArcDifference) {
  cv::Mat img(9, 9, CV_8U, cv::Scalar(100));
  // Arc of 9 brighter pixels: +40 except one at +25 -> score 24 (corner for t < 25).
  for (int j = 0; j < 9; ++j) {
    const auto& o = kCircle[static_cast<std::size_t>(j + 3)];
    img.at<uchar>(4 + o[1], 4 + o[0]) = static_cast<uchar>(j == 4 ? 125 : 140);
  }
  EXPECT_EQ(fast_corner_score(img, 4, 4, 7), 24);
  EXPECT_EQ(fast_corner_score(img, 4, 4, 24), 24);
  EXPECT_EQ(fast_corner_score(img, 4, 4, 25), -1);
  // Eight pixels are not enough.
  img.at<uchar>(4 + kCircle[3][1], 4 + kCircle[3][0]) = 100;
  EXPECT_EQ(fast_corner_score(img, 4, 4, 7), -1);
  EXPECT_THROW(fast_corner_score(img, 2, 4, 7), std::invalid_argument);
}

TEST(Fast, EveryImplementationMatchesTheDefinitionByBruteForce) {
  // Sizes around the SIMD widths exercise the overlapping last block and the scalar fallback.
  for (const cv::Size size : {cv::Size(90, 40), cv::Size(38, 20), cv::Size(37, 12), cv::Size(21, 9), cv::Size(7, 7)}) {
    const cv::Mat img = test::points_texture(size, 11);
    for (int t : {1, 7, 20}) {
      const auto ref = brute_fast(img, t);
      if (size.width == 90) {
        EXPECT_GT(ref.size(), 20u) << "texture too flat for the test";
      }
      for (FastImpl impl : own_impls()) {
        std::vector<cv::KeyPoint> kps;
        detect_fast(img, t, kps, impl);
        expect_same(kps, ref, std::string(to_string(impl)) + " t=" + std::to_string(t));
      }
    }
  }
}

TEST(Fast, PlateausAndSaturatedContrastAgreeWithOpenCv) {
  // Equal neighbouring scores (no strict maximum) and differences up to 255.
  cv::Mat img(64, 96, CV_8U, cv::Scalar(0));
  cv::rectangle(img, cv::Rect(20, 20, 30, 20), cv::Scalar(255), cv::FILLED);
  cv::rectangle(img, cv::Rect(60, 10, 3, 3), cv::Scalar(255), cv::FILLED);
  cv::circle(img, cv::Point(70, 45), 6, cv::Scalar(128), cv::FILLED);
  for (int t : {1, 7, 100, 254}) {
    std::vector<cv::KeyPoint> ref;
    cv::FAST(img, ref, t, true);
    for (FastImpl impl : own_impls()) {
      std::vector<cv::KeyPoint> kps;
      detect_fast(img, t, kps, impl);
      expect_same(kps, ref, std::string(to_string(impl)) + " t=" + std::to_string(t));
    }
  }
}

TEST(Fast, IdenticalToOpenCvOnRealPyramidLevelsAndViews) {
  PLSLAM_REQUIRE_SHARED_DATA(data);
  for (const char* seq : {"kitti/sequences/06", "euroc/V1_01_easy_micro"}) {
    const auto ds = io::open_dataset(data / seq);
    for (std::size_t frame : {std::size_t{0}, ds->size() / 2}) {
      ImagePyramid p;
      p.build(ds->load(frame).left, 8, 1.2, 19);
      std::size_t total = 0;
      for (int l = 0; l < p.levels(); ++l) {
        // The level, and a view into it with an odd offset as the extractor uses.
        const cv::Mat& level = p.level(l);
        for (const cv::Mat& img : {level, level(cv::Rect(13, 13, level.cols - 26, level.rows - 26))}) {
          for (int t : {7, 20}) {
            std::vector<cv::KeyPoint> ref;
            cv::FAST(img, ref, t, true);
            total += ref.size();
            for (FastImpl impl : own_impls()) {
              std::vector<cv::KeyPoint> kps;
              detect_fast(img, t, kps, impl);
              expect_same(kps, ref, std::string(seq) + " level " + std::to_string(l) + " " + to_string(impl));
            }
          }
        }
      }
      EXPECT_GT(total, 10000u) << seq;
    }
  }
}

TEST(Fast, CornersHoldTheKeypoints) {
  const cv::Mat img = test::points_texture(cv::Size(200, 120), 5);
  for (FastImpl impl : {FastImpl::kAuto, FastImpl::kScalar, FastImpl::kOpenCv}) {
    std::vector<cv::KeyPoint> ref;
    cv::FAST(img, ref, 7, true);
    FastCorners corners;
    detect_fast(img, 7, corners, impl);
    ASSERT_GT(corners.size(), 50u);
    ASSERT_EQ(corners.score.size(), corners.size());
    expect_same(corners.keypoints(), ref, to_string(impl));
    for (std::size_t i = 0; i < corners.size(); ++i) {
      EXPECT_EQ(corners.x(i), static_cast<int>(ref[i].pt.x));
      EXPECT_EQ(corners.y(i), static_cast<int>(ref[i].pt.y));
      EXPECT_EQ(FastCorners::pack(corners.x(i), corners.y(i)), corners.position[i]);
    }
  }
  // Round trip, and keypoints the compact layout cannot hold.
  std::vector<cv::KeyPoint> kps{cv::KeyPoint(cv::Point2f(3.f, 65535.f), 7.f, -1.f, 255.f),
                                cv::KeyPoint(cv::Point2f(0.f, 0.f), 7.f, -1.f, 0.f)};
  const FastCorners c = FastCorners::from_keypoints(kps);
  EXPECT_EQ(c.keypoint(0).pt, kps[0].pt);
  EXPECT_EQ(c.keypoint(0).response, 255.f);
  EXPECT_EQ(c.keypoint(1).response, 0.f);
  for (const cv::KeyPoint& bad : {cv::KeyPoint(cv::Point2f(1.5f, 2.f), 7.f, -1.f, 9.f), cv::KeyPoint(cv::Point2f(1.f, 2.f), 7.f, -1.f, 9.5f),
                                  cv::KeyPoint(cv::Point2f(-1.f, 2.f), 7.f, -1.f, 9.f), cv::KeyPoint(cv::Point2f(1.f, 2.f), 7.f, -1.f, 256.f)})
    EXPECT_THROW(FastCorners::from_keypoints({bad}), std::invalid_argument);
}

TEST(Fast, ImplementationNamesAndAvailability) {
  for (FastImpl i : {FastImpl::kAuto, FastImpl::kAvx2, FastImpl::kSse2, FastImpl::kScalar, FastImpl::kOpenCv})
    EXPECT_EQ(parse_fast_impl(to_string(i)), i);
  EXPECT_THROW(parse_fast_impl("neon"), InputError);
  EXPECT_TRUE(fast_impl_available(FastImpl::kScalar));
  EXPECT_TRUE(fast_impl_available(resolve_fast_impl(FastImpl::kAuto)));
  EXPECT_NE(resolve_fast_impl(FastImpl::kAuto), FastImpl::kAuto);
  std::vector<cv::KeyPoint> kps;
  EXPECT_THROW(detect_fast(cv::Mat(20, 20, CV_32F, cv::Scalar(0)), 7, kps), std::invalid_argument);
  detect_fast(cv::Mat(), 7, kps);
  EXPECT_TRUE(kps.empty());
}

}  // namespace
}  // namespace plslam::features
