#include "plslam/features/line_extractor.h"

#include "plslam/core/stopwatch.h"

#include <chrono>

namespace plslam::features {

namespace {
}  // namespace

LineFeatures extract_lines(const cv::Mat& grey, const LineExtractorOptions& o, LineTimings* timings) {
  LineTimings t;
  auto t0 = std::chrono::steady_clock::now();
  DetectedLines det = detect_lines(grey, o.detector);
  t.detect_ms = ms_since(t0);
  t.detected = det.segments.size();

  t0 = std::chrono::steady_clock::now();
  LineFeatures f;
  f.image_size = grey.size();
  // For stereo use: a line within min_angle_from_horizontal_deg of the rows has an ill-conditioned
  // disparity, so it would only take one of the N places from a line that can be matched.
  const auto drop_flatter_than = [](std::vector<LineSegment>& lines, double deg) {
    const double s_min = std::sin(deg * M_PI / 180.0);
    std::erase_if(lines, [&](const LineSegment& l) {
      const double len = l.length();
      return len <= 0 || std::abs(l.end.y - l.start.y) < s_min * len;
    });
  };
  if (o.merge_enabled && o.min_angle_from_horizontal_deg > 0) {
    // Most segments of a street are flat (about 350 of 620 per image on the rendered street
    // loop), and merging them took 1.2-1.5 ms of the 5.2 per image (0.36 ms without them). Pieces
    // merge only within max_theta_deg of each other, so a piece flatter than the limit by twice
    // that could reach a kept line only through a chain of merges that each turn it further.
    drop_flatter_than(det.segments, o.min_angle_from_horizontal_deg - 2 * o.merge.max_theta_deg);
  }
  f.lines = o.merge_enabled ? merge_segments(std::move(det.segments), grey.size(), o.merge) : std::move(det.segments);
  t.merged = f.lines.size();
  if (o.min_angle_from_horizontal_deg > 0) drop_flatter_than(f.lines, o.min_angle_from_horizontal_deg);
  keep_best(f.lines, o.max_lines);
  t.kept = f.lines.size();
  t.merge_ms = ms_since(t0);

  t0 = std::chrono::steady_clock::now();
  f.descriptors = describe_lines(det.gradient, f.lines, o.lbd);
  t.describe_ms = ms_since(t0);
  if (timings) *timings = t;
  return f;
}

}  // namespace plslam::features
