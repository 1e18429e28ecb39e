// Detection and merging against the exact ground truth of a synthetic scene, plus bounds on
// real frames.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "features/line_synthetic_scene.h"
#include "plslam/core/error.h"
#include "plslam/features/line_extractor.h"
#include "support/test_support.h"

namespace plslam::features {
namespace {

double recall_long_edges(const test::SyntheticLineScene& s, const std::vector<LineSegment>& segs, double min_len,
                         bool quads_only) {
  int total = 0, found = 0;
  for (const auto& e : s.edges) {
    if ((quads_only && e.pole) || cv::norm(e.b - e.a) <= min_len) continue;
    ++total;
    if (test::coverage(e, segs) >= 0.7) ++found;
  }
  return total ? static_cast<double>(found) / total : 0;
}

void save_overlay(const cv::Mat& grey, const std::vector<LineSegment>& segs, const std::string& name) {
  cv::Mat vis;
  cv::cvtColor(grey, vis, cv::COLOR_GRAY2BGR);
  for (const auto& l : segs)
    cv::line(vis, l.start, l.end, l.fragments > 1 ? cv::Scalar(0, 0, 255) : cv::Scalar(0, 255, 0), 1, cv::LINE_AA);
  cv::imwrite((test::artifacts_dir() / name).string(), vis);
}

TEST(LineDetector, RecallOnSyntheticSceneBothDetectors) {
  const auto s = test::make_line_scene(false);
  for (const auto kind : {LineDetectorKind::kGrow, LineDetectorKind::kLsd}) {
    LineExtractorOptions o;
    o.detector.kind = kind;
    o.detector.scale = kind == LineDetectorKind::kLsd ? 1.0 : 0.5;
    const LineFeatures f = extract_lines(s.left, o);
    const double r = recall_long_edges(s, f.lines, 40, true);
    std::printf("%s: recall %.3f of quad edges > 40 px\n", to_string(kind), r);
    EXPECT_GE(r, 0.8) << to_string(kind);
    save_overlay(s.left, f.lines, std::string("lines_synthetic_") + to_string(kind) + ".png");
    // Accuracy: segments on a GT edge sit within 1 px of it on average.
    double sum = 0;
    int n = 0;
    for (const auto& l : f.lines)
      for (const auto& e : s.edges)
        if (test::on_edge(l, e)) {
          const LineSegment g{e.a, e.b};
          sum += 0.5 * (distance_to_line(g, l.start) + distance_to_line(g, l.end));
          ++n;
        }
    ASSERT_GT(n, 20);
    std::printf("%s: mean endpoint distance to GT line %.3f px over %d segments\n", to_string(kind), sum / n, n);
    EXPECT_LT(sum / n, 1.0) << to_string(kind);
  }
}

TEST(LineDetector, MergingReducesFragmentsWithoutFusingDistinctEdges) {
  const auto s = test::make_line_scene(true);
  LineDetectorOptions d;
  const DetectedLines det = detect_lines(s.left, d);
  const auto merged = merge_segments(det.segments, s.left.size(), LineMergeOptions{});
  save_overlay(s.left, merged, "lines_synthetic_merged.png");

  auto pieces_on_quads = [&](const std::vector<LineSegment>& segs) {
    int n = 0;
    for (const auto& l : segs)
      for (const auto& e : s.edges)
        if (!e.pole && test::on_edge(l, e)) {
          ++n;
          break;
        }
    return n;
  };
  const int before = pieces_on_quads(det.segments), after = pieces_on_quads(merged);
  std::printf("fragments on quad edges: %d before merging, %d after\n", before, after);
  ASSERT_GT(before, 30);
  EXPECT_LE(after, 0.7 * before) << "before " << before << " after " << after;

  // Precision: every merged segment lies on one ground-truth edge, within its extent.
  int fused = 0, correct = 0;
  for (const auto& l : merged) {
    if (l.fragments < 2) continue;
    ++fused;
    for (const auto& e : s.edges)
      if (test::on_edge(l, e)) {
        ++correct;
        break;
      }
  }
  std::printf("merged segments on one GT edge: %d of %d\n", correct, fused);
  ASSERT_GT(fused, 10);
  EXPECT_GE(static_cast<double>(correct) / fused, 0.95) << correct << " of " << fused;
}

TEST(LineDetector, KeepsBestNAndRejectsBadInput) {
  const auto s = test::make_line_scene(true);
  LineExtractorOptions o;
  o.max_lines = 10;
  LineTimings t;
  const LineFeatures f = extract_lines(s.left, o, &t);
  EXPECT_EQ(f.lines.size(), 10u);
  EXPECT_EQ(f.descriptors.rows, 10);
  EXPECT_EQ(f.descriptors.cols, kLbdBytes);
  for (std::size_t i = 1; i < f.lines.size(); ++i) EXPECT_GE(f.lines[i - 1].length(), f.lines[i].length());
  EXPECT_GE(t.detected, t.merged);
  EXPECT_THROW(extract_lines(cv::Mat(), o), std::invalid_argument);
  EXPECT_THROW(extract_lines(cv::Mat(10, 10, CV_32F), o), std::invalid_argument);
  EXPECT_THROW(parse_line_detector("hough"), InputError);
  EXPECT_EQ(parse_line_detector("lsd"), LineDetectorKind::kLsd);
}

TEST(LineDetector, BrighterSideIsOnTheRight) {
  cv::Mat img(200, 200, CV_8U, cv::Scalar(50));
  img(cv::Rect(100, 0, 100, 200)).setTo(200);  // bright right half: a vertical edge at x = 99.5
  for (const auto kind : {LineDetectorKind::kGrow, LineDetectorKind::kLsd}) {
    LineDetectorOptions o;
    o.kind = kind;
    const auto d = detect_lines(img, o);
    ASSERT_GE(d.segments.size(), 1u) << to_string(kind);
    const auto& l = d.segments.front();
    EXPECT_NEAR(0.5 * (l.start.x + l.end.x), 99.5, 0.6) << to_string(kind);
    EXPECT_LT(l.end.y, l.start.y) << to_string(kind);  // goes up, so the bright side is right
  }
}

TEST(LineDetector, RealFramesGiveEnoughLines) {
  PLSLAM_REQUIRE_SHARED_DATA(data);
  const auto img = cv::imread((data / "kitti/sequences/06/image_0/000000.png").string(), cv::IMREAD_GRAYSCALE);
  ASSERT_FALSE(img.empty());
  LineTimings t;
  const auto f = extract_lines(img, LineExtractorOptions::kitti(), &t);
  EXPECT_GE(f.lines.size(), 150u);
  save_overlay(img, f.lines, "lines_kitti06_000000.png");
}

// extract_lines with a flatness limit drops flat pieces before merging (to save the merge their
// cost). The lines it keeps must be those of merging everything and dropping the flat lines after.
void expect_same_lines_as_filtering_after_merging(const cv::Mat& img, LineExtractorOptions o, double min_share) {
  o.min_angle_from_horizontal_deg = 10;
  const LineFeatures f = extract_lines(img, o);
  LineExtractorOptions all = o;
  all.min_angle_from_horizontal_deg = 0;
  all.max_lines = 100000;
  std::vector<LineSegment> ref = extract_lines(img, all).lines;
  const double s_min = std::sin(10 * CV_PI / 180);
  std::erase_if(ref, [&](const LineSegment& l) { return std::abs(l.end.y - l.start.y) < s_min * l.length(); });
  keep_best(ref, o.max_lines);
  ASSERT_GT(ref.size(), 20u);
  for (const auto& l : f.lines) EXPECT_GE(std::abs(l.end.y - l.start.y), s_min * l.length());
  std::size_t found = 0;
  for (const auto& r : ref) {
    found += std::any_of(f.lines.begin(), f.lines.end(), [&](const LineSegment& l) {
      return cv::norm(l.start - r.start) < 0.5 && cv::norm(l.end - r.end) < 0.5;
    });
  }
  std::printf("lines kept with the flat pieces dropped before merging: %zu, after merging: %zu, in both: %zu\n",
              f.lines.size(), ref.size(), found);
  EXPECT_GE(static_cast<double>(found), min_share * static_cast<double>(ref.size()));
  EXPECT_LE(f.lines.size(), ref.size() + (ref.size() - found));
}

TEST(LineDetector, FlatPiecesDroppedBeforeMergingLeaveTheKeptLinesAsTheyWere) {
  // Quads turned in plane, broken by poles: edges at every angle, many in pieces.
  expect_same_lines_as_filtering_after_merging(test::make_line_scene(true).left, LineExtractorOptions::euroc(), 1.0);
  PLSLAM_REQUIRE_SHARED_DATA(data);
  const auto img = cv::imread((data / "kitti/sequences/06/image_0/000000.png").string(), cv::IMREAD_GRAYSCALE);
  ASSERT_FALSE(img.empty());
  // A real street: a chain of merges may turn a flat piece into a kept line, rarely.
  expect_same_lines_as_filtering_after_merging(img, LineExtractorOptions::kitti(), 0.97);
}

}  // namespace
}  // namespace plslam::features
