// LBD: matching under a small viewpoint change (homography warp of real and synthetic images).
#include <cstdio>
#include <random>

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "features/line_synthetic_scene.h"
#include "plslam/features/orb_descriptor.h"
#include "plslam/features/line_descriptor.h"
#include "plslam/features/line_extractor.h"
#include "support/test_support.h"

namespace plslam::features {
namespace {

cv::Point2f apply(const cv::Matx33d& H, const cv::Point2f& p) {
  const cv::Vec3d q = H * cv::Vec3d(p.x, p.y, 1.0);
  return {static_cast<float>(q[0] / q[2]), static_cast<float>(q[1] / q[2])};
}

struct WarpResult {
  int correspondences = 0;  // lines of image 1 with a geometric counterpart in image 2
  int matched = 0, correct = 0;  // among lines with a counterpart
};

// Extracts lines in img and its warp by H; matches by nearest Hamming with a ratio test and
// checks each match against the warped geometry.
WarpResult match_under_warp(const cv::Mat& img, const cv::Matx33d& H) {
  cv::Mat warped;
  cv::warpPerspective(img, warped, cv::Mat(H), img.size(), cv::INTER_LINEAR, cv::BORDER_REPLICATE);
  const LineExtractorOptions o;
  const LineFeatures a = extract_lines(img, o), b = extract_lines(warped, o);
  auto same_line = [&](int i, int j) {
    LineSegment t{apply(H, a.lines[i].start), apply(H, a.lines[i].end)};
    const LineSegment& u = b.lines[j];
    if (t.direction().dot(u.direction()) < std::cos(3 * CV_PI / 180)) return false;
    if (distance_to_line(t, u.start) > 3 || distance_to_line(t, u.end) > 3) return false;
    const cv::Point2f d = t.direction();
    const double t1 = d.dot(u.start - t.start), t2 = d.dot(u.end - t.start);
    return std::max(t1, t2) > 0 && std::min(t1, t2) < t.length();  // overlapping along the line
  };
  WarpResult r;
  for (int i = 0; i < a.descriptors.rows; ++i) {
    int best = 1 << 30, second = 1 << 30, bj = -1;
    bool has = false;
    for (int j = 0; j < b.descriptors.rows; ++j) {
      has = has || same_line(i, j);
      const int d = hamming_distance(a.descriptors.ptr<uint8_t>(i), b.descriptors.ptr<uint8_t>(j));
      if (d < best) {
        second = best;
        best = d;
        bj = j;
      } else if (d < second) {
        second = d;
      }
    }
    // Precision is judged on lines that have a counterpart; the others cannot match correctly.
    r.correspondences += has;
    if (!has || bj < 0 || best > 70 || best >= 0.8 * second) continue;
    ++r.matched;
    r.correct += same_line(i, bj);
  }
  return r;
}

cv::Matx33d small_viewpoint_change(const cv::Size& s) {
  // 3 degree rotation about the centre, 4 % zoom, a slight perspective tilt.
  const double a = 3 * CV_PI / 180, k = 1.04;
  const cv::Matx33d T(1, 0, s.width / 2.0, 0, 1, s.height / 2.0, 0, 0, 1);
  const cv::Matx33d R(k * std::cos(a), -k * std::sin(a), 0, k * std::sin(a), k * std::cos(a), 0, 2e-5, 1e-5, 1);
  return T * R * T.inv();
}

TEST(LineDescriptor, MatchesUnderSmallViewpointChangeSynthetic) {
  const auto s = test::make_line_scene(false);
  const WarpResult r = match_under_warp(s.left, small_viewpoint_change(s.left.size()));
  std::printf("synthetic: %d correct of %d matched, %d lines with a counterpart\n", r.correct, r.matched,
              r.correspondences);
  EXPECT_GE(r.matched, 15);
  // Uniform quads repeat (two are identical), so a few edges look alike to LBD.
  EXPECT_GE(static_cast<double>(r.correct) / r.matched, 0.75) << r.correct << " / " << r.matched;
}

TEST(LineDescriptor, MatchesUnderSmallViewpointChangeReal) {
  PLSLAM_REQUIRE_SHARED_DATA(data);
  for (const char* f : {"kitti/sequences/06/image_0/000000.png",
                        "euroc/V1_01_easy_micro/mav0/cam0/data/1403715273262142976.png"}) {
    const cv::Mat img = cv::imread((data / f).string(), cv::IMREAD_GRAYSCALE);
    ASSERT_FALSE(img.empty()) << f;
    const WarpResult r = match_under_warp(img, small_viewpoint_change(img.size()));
    std::printf("%s: %d correct of %d matched, %d lines with a counterpart\n", f, r.correct, r.matched,
                r.correspondences);
    EXPECT_GE(r.matched, 0.3 * r.correspondences) << f << ": " << r.matched << " of " << r.correspondences;
    EXPECT_GE(static_cast<double>(r.correct) / r.matched, 0.85) << f << ": " << r.correct << " / " << r.matched;
  }
}

TEST(LineDescriptor, HammingAndShape) {
  uint8_t a[kLbdBytes] = {}, b[kLbdBytes] = {};
  EXPECT_EQ(hamming_distance(a, b), 0);
  b[0] = 0xFF;
  b[31] = 0x01;
  EXPECT_EQ(hamming_distance(a, b), 9);
  const auto s = test::make_line_scene(false);
  const DetectedLines d = detect_lines(s.left);
  const cv::Mat f = describe_lines_float(d.gradient, d.segments);
  ASSERT_EQ(f.rows, static_cast<int>(d.segments.size()));
  ASSERT_EQ(f.cols, 72);
  // Mean and std halves are unit vectors after clamping and renormalising.
  for (int i = 0; i < f.rows; ++i) {
    double m = 0, sd = 0;
    for (int j = 0; j < 9; ++j)
      for (int c = 0; c < 4; ++c) {
        m += std::pow(f.at<float>(i, j * 8 + c), 2);
        sd += std::pow(f.at<float>(i, j * 8 + 4 + c), 2);
      }
    EXPECT_NEAR(m, 1.0, 1e-4);
    EXPECT_NEAR(sd, 1.0, 1e-4);
  }
}

// The band sums: the SSE2 code and the portable one give the same floats (so runs are identical
// on any machine), and both are the sums of the positive and negative parts, to float rounding.
TEST(LineDescriptor, PositiveNegativeSumsAreExactAndPortable) {
  std::mt19937 rng(7);
  std::uniform_int_distribution<int> grad(-1020, 1020);
  std::uniform_real_distribution<float> angle(0.f, 6.2831853f);
  for (int trial = 0; trial < 200; ++trial) {
    const int count = 4 * (1 + trial % 6);
    std::vector<float> gx(static_cast<std::size_t>(count)), gy(gx.size());
    for (std::size_t k = 0; k < gx.size(); ++k) {
      gx[k] = static_cast<float>(grad(rng));
      gy[k] = static_cast<float>(grad(rng));
    }
    if (trial % 5 == 0) gx[0] = gy[0] = 0.f;  // padding samples: zero gradient
    const float t = angle(rng);
    const cv::Point2f d(std::cos(t), std::sin(t)), n(-d.y, d.x);
    float fast[4], portable[4];
    detail::positive_negative_sums(gx.data(), gy.data(), count, n, d, fast);
    detail::positive_negative_sums_portable(gx.data(), gy.data(), count, n, d, portable);
    double expect[4] = {0, 0, 0, 0};
    for (std::size_t k = 0; k < gx.size(); ++k) {
      const double dp = double(gx[k]) * n.x + double(gy[k]) * n.y, dl = double(gx[k]) * d.x + double(gy[k]) * d.y;
      expect[0] += std::max(dp, 0.0);
      expect[1] += std::max(-dp, 0.0);
      expect[2] += std::max(dl, 0.0);
      expect[3] += std::max(-dl, 0.0);
    }
    for (int c = 0; c < 4; ++c) {
      EXPECT_EQ(fast[c], portable[c]) << "trial " << trial << " sum " << c;
      EXPECT_NEAR(fast[c], expect[c], 1e-5 * (1.0 + expect[c])) << "trial " << trial << " sum " << c;
      EXPECT_GE(fast[c], 0.f);
    }
  }
}

}  // namespace
}  // namespace plslam::features
