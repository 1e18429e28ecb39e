#include "plslam/tracking/frame_extractor.h"

#include "plslam/core/stopwatch.h"

#include <chrono>

#include <vector>

#include "plslam/geometry/stereo_camera.h"
#include "plslam/matching/stereo_point_frame.h"

namespace plslam::tracking {

FrameExtractorOptions FrameExtractorOptions::euroc() {
  FrameExtractorOptions o;
  o.orb = features::OrbOptions::euroc();
  o.line_extractor = features::LineExtractorOptions::euroc();
  return o;
}

FrameExtractorOptions FrameExtractorOptions::kitti() {
  FrameExtractorOptions o;
  o.orb = features::OrbOptions::kitti();
  o.line_extractor = features::LineExtractorOptions::kitti();
  return o;
}

FrameExtractor::FrameExtractor(const StereoCalibration& calib, FrameExtractorOptions options)
    : calib_(calib),
      options_(std::move(options)),
      left_orb_(options_.orb),
      right_orb_(matching::right_image_options(options_.orb, options_.right_points_factor)),
      lanes_(std::make_unique<core::WorkerPool>(2, "plslam-lanes")) {
  options_.line_extractor.min_angle_from_horizontal_deg = options_.stereo_lines.min_angle_from_horizontal_deg;
  options_.stereo_points.bf = calib_.bf();
  options_.stereo_points.baseline = calib_.baseline;
  options_.stereo_points.validate();
  // The guided search compares right descriptors with the left ones, so it makes them alike.
  options_.guided_lines.lbd_scale = options_.line_extractor.detector.scale;
  options_.guided_lines.lbd = options_.line_extractor.lbd;
  options_.guided_lines.validate();
}

std::shared_ptr<map::FrameData> FrameExtractor::extract(long frame_id, double timestamp, const cv::Mat& left,
                                                        const cv::Mat& right, FrameTimings* timings) const {
  const auto t0 = std::chrono::steady_clock::now();
  features::PointFeatures pl, pr;
  features::LineFeatures ll, lr;
  features::ExtractionTimings tl;
  features::LineTimings tll;
  matching::StereoPointMatches sp;
  std::vector<matching::StereoLineMatch> sl;
  double sp_ms = 0, sl_ms = 0;
  {
    // Two lanes on a persistent pool of two threads (this one and a worker):
    // - not one thread per task: with the three tasks of the guided default on 2 cores, the
    //   kernel shared them out evenly, so the longest lane (left lines, then the guided search)
    //   ran at two-thirds speed until the point tasks ended (11.8 ms on the street loop, where
    //   that lane alone takes 9.2 ms and the points lane 8.8 ms);
    // - not a thread started per frame: after the idle time between frames at the camera's
    //   rate, the kernel put a new thread on its starter's core in 44 of 51 frames, and the
    //   lanes took turns there (KITTI 06 with 80 ms sleeps: 15.4-18.9 ms per frame against
    //   12.4-14.8 ms with the pool's waiting worker, which starts there less often).
    // This thread takes chunk 0, the lines, at once; if the worker is slow to wake, this thread
    // also runs the points when done. WorkerPool rather than TBB: its hand-over is a mutex and a
    // condition variable, which ThreadSanitizer sees (libtbb is not instrumented).
    const auto left_points = [&] { pl = left_orb_.extract(left, &tl); };
    const auto right_points = [&] { pr = right_orb_.extract(right); };
    const auto match_points = [&] {
      const auto s = std::chrono::steady_clock::now();
      sp = matching::match_stereo_points(pl, pr, options_.stereo_points);
      sp_ms = ms_since(s);
    };
    const auto lines_lane = [&] {
      ll = features::extract_lines(left, options_.line_extractor, &tll);
      // The guided search needs no right features, so it follows the left lines at once.
      if (options_.guided_stereo_lines) {
        const auto s = std::chrono::steady_clock::now();
        sl = matching::match_stereo_lines_guided(ll, left, right, calib_, options_.stereo_lines, options_.guided_lines);
        sl_ms = ms_since(s);
      }
    };
    std::lock_guard lock(lanes_mutex_);  // the pool runs one frame at a time
    if (options_.lines) {
      // Without guided lines, the right lines are a third chunk for whichever thread is free.
      lanes_->run(options_.guided_stereo_lines ? 2 : 3, [&](int c) {
        if (c == 0) {
          lines_lane();
        } else if (c == 1) {
          left_points();
          right_points();
          match_points();
        } else {
          lr = features::extract_lines(right, options_.line_extractor);
        }
      });
    } else {
      // Without lines the two images' points are the lanes.
      lanes_->run(2, [&](int c) { c == 0 ? left_points() : right_points(); });
      match_points();
    }
  }
  const auto t1 = std::chrono::steady_clock::now();
  // Detected right lines are matched once both line tasks are done.
  if (options_.lines && !options_.guided_stereo_lines) {
    const auto s = std::chrono::steady_clock::now();
    sl = matching::match_stereo_lines(ll, lr, calib_, options_.stereo_lines);
    sl_ms = ms_since(s);
  }
  const auto t2 = std::chrono::steady_clock::now();

  auto data = std::make_shared<map::FrameData>();
  data->frame_id = frame_id;
  data->timestamp = timestamp;
  data->calib = calib_;
  data->levels = options_.orb.levels;
  data->scale_factor = options_.orb.scale_factor;
  data->keypoints = std::move(pl.keypoints);
  data->descriptors = pl.descriptors;
  data->u_right = std::move(sp.u_right);
  data->depth = std::move(sp.depth);
  data->build_grid();

  // Only stereo lines are kept: the optimisers' line term uses both images (the paper's eq. 8).
  data->lines.reserve(sl.size());
  data->line_descriptors = cv::Mat(static_cast<int>(sl.size()), 32, CV_8U);
  for (const auto& m : sl) {
    const auto& a = ll.lines[static_cast<std::size_t>(m.left)];
    // A guided match has no right feature: its right line is the fitted one, through the left
    // endpoints shifted by their disparities along their rows.
    const features::LineSegment b =
        m.right >= 0 ? lr.lines[static_cast<std::size_t>(m.right)]
                     : features::LineSegment{a.start - cv::Point2f(static_cast<float>(m.disparity_start), 0.f),
                                             a.end - cv::Point2f(static_cast<float>(m.disparity_end), 0.f)};
    map::LineObservation obs;
    obs.segment = a;
    obs.left_line = geometry::line_through({a.start.x, a.start.y}, {a.end.x, a.end.y});
    obs.right_line = geometry::line_through({b.start.x, b.start.y}, {b.end.x, b.end.y});
    obs.stereo = true;
    obs.start_cam = m.P_start;
    obs.end_cam = m.P_end;
    ll.descriptors.row(m.left).copyTo(data->line_descriptors.row(static_cast<int>(data->lines.size())));
    data->lines.push_back(obs);
  }

  if (timings) {
    timings->extraction_ms = std::chrono::duration<double, std::milli>(t1 - t0).count();
    timings->stereo_ms = std::chrono::duration<double, std::milli>(t2 - t1).count();
    timings->total_ms = ms_since(t0);
    timings->left_points = tl;
    timings->left_lines = tll;
    timings->stereo_points_ms = sp_ms;
    timings->stereo_lines_ms = sl_ms;
    timings->stereo_points = sp.matched;
    timings->stereo_lines = static_cast<int>(sl.size());
  }
  return data;
}

}  // namespace plslam::tracking
