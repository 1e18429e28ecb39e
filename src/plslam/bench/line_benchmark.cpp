#include "plslam/bench/line_benchmark.h"

#include "plslam/core/stopwatch.h"

#include "plslam/core/sample_stats.h"

#include <algorithm>
#include <chrono>
#include <stdexcept>

#include <opencv2/imgproc.hpp>
#include <opencv2/line_descriptor.hpp>

namespace plslam::bench {

std::vector<cv::line_descriptor::KeyLine> to_keylines(const std::vector<features::LineSegment>& lines,
                                                      cv::Size image_size) {
  std::vector<cv::line_descriptor::KeyLine> kls;
  kls.reserve(lines.size());
  for (std::size_t i = 0; i < lines.size(); ++i) {
    const features::LineSegment& s = lines[i];
    cv::line_descriptor::KeyLine k;
    k.startPointX = k.sPointInOctaveX = s.start.x;
    k.startPointY = k.sPointInOctaveY = s.start.y;
    k.endPointX = k.ePointInOctaveX = s.end.x;
    k.endPointY = k.ePointInOctaveY = s.end.y;
    k.lineLength = s.length();
    k.numOfPixels = static_cast<int>(s.length());
    k.angle = s.angle();
    k.octave = 0;
    k.class_id = static_cast<int>(i);
    k.pt = 0.5f * (s.start + s.end);
    k.response = s.length() / std::max(image_size.width, image_size.height);
    kls.push_back(k);
  }
  return kls;
}

namespace {

// OpenCV's binary LBD on our segments, for the cost comparison.
double opencv_lbd_ms(const cv::Mat& grey, const std::vector<features::LineSegment>& lines) {
  std::vector<cv::line_descriptor::KeyLine> kls = to_keylines(lines, grey.size());
  auto bd = cv::line_descriptor::BinaryDescriptor::createBinaryDescriptor();
  cv::Mat desc;
  const auto t0 = std::chrono::steady_clock::now();
  bd->compute(grey, kls, desc);
  return ms_since(t0);
}

}  // namespace

nlohmann::json benchmark_lines(const std::vector<std::pair<cv::Mat, cv::Mat>>& frames, const StereoCalibration& calib,
                               const LineBenchmarkOptions& o) {
  if (frames.empty()) throw std::invalid_argument("benchmark_lines: no frames");
  std::vector<double> lsd, fast, merge, lbd, image, cv_lbd, stereo, detected, merged, kept, matches;
  features::LineExtractorOptions fast_opts = o.extractor;
  fast_opts.detector.kind = features::LineDetectorKind::kGrow;
  for (const auto& [left, right] : frames) {
    if (o.reference) {
      // OpenCV's own LSD alone (default parameters, no refinement), full resolution.
      auto detector = cv::createLineSegmentDetector(cv::LSD_REFINE_NONE);
      std::vector<cv::Vec4f> raw;
      const auto t0 = std::chrono::steady_clock::now();
      detector->detect(left, raw);
      lsd.push_back(ms_since(t0));
    }
    features::LineTimings tl, tr;
    const features::LineFeatures fl = features::extract_lines(left, fast_opts, &tl);
    const features::LineFeatures fr = features::extract_lines(right, fast_opts, &tr);
    for (const features::LineTimings* t : {&tl, &tr}) {
      fast.push_back(t->detect_ms);
      merge.push_back(t->merge_ms);
      lbd.push_back(t->describe_ms);
      image.push_back(t->total_ms());
      detected.push_back(static_cast<double>(t->detected));
      merged.push_back(static_cast<double>(t->merged));
      kept.push_back(static_cast<double>(t->kept));
    }
    if (o.reference) cv_lbd.push_back(opencv_lbd_ms(left, fl.lines));
    const auto t0 = std::chrono::steady_clock::now();
    const auto m = matching::match_stereo_lines(fl, fr, calib, o.stereo);
    stereo.push_back(ms_since(t0));
    matches.push_back(static_cast<double>(m.size()));
  }
  nlohmann::json j;
  j["frames"] = frames.size();
  j["fast_lines_ms"] = summarize(fast);
  j["merge_ms"] = summarize(merge);
  j["lbd_ms"] = summarize(lbd);
  j["lines_image_ms"] = summarize(image);
  j["stereo_lines_ms"] = summarize(stereo);
  j["lines_detected"] = summarize(detected);
  j["lines_after_merge"] = summarize(merged);
  j["lines_kept"] = summarize(kept);
  j["stereo_line_matches"] = summarize(matches);
  if (o.reference) {
    j["lsd_ms"] = summarize(lsd);
    j["opencv_lbd_ms"] = summarize(cv_lbd);
    j["lines_speedup_vs_opencv"] = (percentile(lsd, 0.5) + percentile(cv_lbd, 0.5)) / percentile(image, 0.5);
  }
  return j;
}

nlohmann::json benchmark_lines(const io::Dataset& dataset, std::size_t n, const LineBenchmarkOptions& o) {
  const std::size_t count = n == 0 ? dataset.size() : std::min(n, dataset.size());
  std::vector<std::pair<cv::Mat, cv::Mat>> frames;
  frames.reserve(count);
  for (std::size_t i = 0; i < count; ++i) {
    if (i > 0 && o.stop && o.stop()) break;
    io::StereoFrame f = dataset.load(i);
    frames.emplace_back(std::move(f.left), std::move(f.right));
  }
  return benchmark_lines(frames, dataset.calibration(), o);
}

}  // namespace plslam::bench
