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
  f.lines = o.merge_enabled ? merge_segments(std::move(det.segments), grey.size(), o.merge) : std::move(det.segments);
  t.merged = f.lines.size();
  if (o.min_angle_from_horizontal_deg > 0) {
    // For stereo use: a line within this angle of the rows has an ill-conditioned disparity, so
    // it would only take one of the N places from a line that can be matched.
    const double s_min = std::sin(o.min_angle_from_horizontal_deg * M_PI / 180.0);
    std::erase_if(f.lines, [&](const LineSegment& l) {
      const double len = l.length();
      return len <= 0 || std::abs(l.end.y - l.start.y) < s_min * len;
    });
  }
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
