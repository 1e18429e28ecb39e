#include "plslam/bench/point_benchmark.h"

#include "plslam/core/sample_stats.h"

#include <algorithm>
#include <cmath>
#include <ctime>
#include <numeric>

#include <opencv2/core/utility.hpp>

#include "plslam/core/log.h"
#include "plslam/features/keypoint_uniformity.h"
#include "plslam/matching/stereo_point_frame.h"

namespace plslam::bench {
namespace {

// Thread CPU time: the machine may be shared, and the stages are single-threaded, so CPU time is
// the per-core cost without other processes' time slices mixed in.
struct ThreadCpuClock {
  using time_point = double;
  static double now() {
    timespec ts{};
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
    return static_cast<double>(ts.tv_sec) * 1e3 + static_cast<double>(ts.tv_nsec) * 1e-6;
  }
};
double cpu_ms_since(double t0) { return ThreadCpuClock::now() - t0; }

// Level-0 positions of distributed candidates, for the uniformity score.
std::vector<cv::KeyPoint> to_level0(const features::PyramidCandidates& kept, const features::ImagePyramid& pyramid) {
  std::vector<cv::KeyPoint> out;
  for (std::size_t l = 0; l < kept.size(); ++l) {
    const int level = static_cast<int>(l);
    const features::FastCorners& c = kept[l].corners;
    for (std::size_t i = 0; i < c.size(); ++i) {
      cv::KeyPoint p = c.keypoint(i);
      p.pt = {pyramid.from_level_x(p.pt.x + static_cast<float>(kept[l].offset.x), level),
              pyramid.from_level_y(p.pt.y + static_cast<float>(kept[l].offset.y), level)};
      p.octave = level;
      out.push_back(p);
    }
  }
  return out;
}

int count(const features::PyramidCandidates& c) {
  int n = 0;
  for (const auto& lc : c) n += static_cast<int>(lc.corners.size());
  return n;
}

// Keeps OpenCV's own thread pool out of the measurement and restores it afterwards.
class SingleThreadedOpenCv {
 public:
  SingleThreadedOpenCv() : previous_(cv::getNumThreads()) { cv::setNumThreads(1); }
  ~SingleThreadedOpenCv() { cv::setNumThreads(previous_); }
  SingleThreadedOpenCv(const SingleThreadedOpenCv&) = delete;
  SingleThreadedOpenCv& operator=(const SingleThreadedOpenCv&) = delete;

 private:
  int previous_;
};

}  // namespace

nlohmann::json run_point_benchmark(const io::Dataset& dataset, const PointBenchmarkOptions& options) {
  features::OrbOptions orb = options.orb;
  orb.n_features = options.n_features > 0 ? options.n_features
                                          : (dataset.format() == io::DatasetFormat::kKitti ? 2000 : 1200);
  const features::OrbExtractor left_extractor(orb);
  const features::OrbExtractor right_extractor(matching::right_image_options(orb, options.right_feature_factor));
  matching::StereoPointOptions stereo;
  stereo.bf = dataset.calibration().bf();
  stereo.baseline = dataset.calibration().baseline;

  const std::size_t frames = options.max_frames > 0 ? std::min(options.max_frames, dataset.size()) : dataset.size();
  const SingleThreadedOpenCv single_thread;
  std::vector<double> pyramid_ms, fast_ms, ssc_ms, quadtree_ms, ssc_first_ms, quadtree_first_ms, orb_ms, left_ms, right_ms, stereo_ms;
  std::vector<double> candidates, kept_ssc, kept_quadtree, matches, match_share, cv_ssc, cv_quadtree;
  cv::Size size;
  for (std::size_t i = 0; i < frames; ++i) {
    if (i > 0 && options.stop && options.stop()) break;
    const io::StereoFrame frame = dataset.load(i);
    size = frame.left.size();
    // The first frame runs twice: the first pass only warms caches and allocations.
    for (int pass = (i == 0 ? 0 : 1); pass < 2; ++pass) {
      features::PointFeatures left;
      auto t0 = ThreadCpuClock::now();
      left_extractor.build_pyramid(frame.left, left.pyramid);
      const double t_pyr = cpu_ms_since(t0);
      t0 = ThreadCpuClock::now();
      const features::PyramidCandidates cand = left_extractor.detect(left.pyramid);
      const double t_fast = cpu_ms_since(t0);
      // SSC and quadtree on the same candidates, `distribution_repeats` times each with the order
      // alternating (whichever runs second finds the candidates in cache); the frame's time for
      // each is the median of its repeats, so that one interrupted run does not decide a ratio
      // of two sub-millisecond stages.
      features::PyramidCandidates ssc, quad;
      std::vector<double> ssc_reps, quad_reps;
      auto run_ssc = [&] {
        const auto t = ThreadCpuClock::now();
        ssc = left_extractor.distribute(cand, features::Distribution::kSsc);
        ssc_reps.push_back(cpu_ms_since(t));
      };
      auto run_quadtree = [&] {
        const auto t = ThreadCpuClock::now();
        quad = left_extractor.distribute(cand, features::Distribution::kQuadtree);
        quad_reps.push_back(cpu_ms_since(t));
      };
      const int repeats = std::max(1, options.distribution_repeats);
      for (int r = 0; r < repeats; ++r) {
        if ((i + static_cast<std::size_t>(r)) % 2 == 0) {
          run_ssc();
          run_quadtree();
        } else {
          run_quadtree();
          run_ssc();
        }
      }
      const double t_ssc = percentile(ssc_reps, 0.5), t_quad = percentile(quad_reps, 0.5);
      t0 = ThreadCpuClock::now();
      left_extractor.describe(left.pyramid, ssc, left);
      const double t_orb = cpu_ms_since(t0);
      t0 = ThreadCpuClock::now();
      const features::PointFeatures right = right_extractor.extract(frame.right);
      const double t_right = cpu_ms_since(t0);
      t0 = ThreadCpuClock::now();
      const matching::StereoPointMatches m = matching::match_stereo_points(left, right, stereo);
      const double t_stereo = cpu_ms_since(t0);
      if (pass == 0) continue;
      pyramid_ms.push_back(t_pyr);
      fast_ms.push_back(t_fast);
      ssc_ms.push_back(t_ssc);
      quadtree_ms.push_back(t_quad);
      ssc_first_ms.push_back(ssc_reps.front());
      quadtree_first_ms.push_back(quad_reps.front());
      orb_ms.push_back(t_orb);
      left_ms.push_back(t_pyr + t_fast + t_ssc + t_orb);
      right_ms.push_back(t_right);
      stereo_ms.push_back(t_stereo);
      candidates.push_back(count(cand));
      kept_ssc.push_back(count(ssc));
      kept_quadtree.push_back(count(quad));
      matches.push_back(m.matched);
      match_share.push_back(left.keypoints.empty() ? 0.0 : static_cast<double>(m.matched) / static_cast<double>(left.keypoints.size()));
      cv_ssc.push_back(features::grid_count_cv(to_level0(ssc, left.pyramid), size));
      cv_quadtree.push_back(features::grid_count_cv(to_level0(quad, left.pyramid), size));
    }
  }

  nlohmann::json j;
  j["dataset"] = dataset.root().string();
  j["format"] = io::to_string(dataset.format());
  j["frames"] = pyramid_ms.size();
  j["width"] = size.width;
  j["height"] = size.height;
  j["threads"] = 1;
  j["clock"] = "thread_cpu";
  j["config"] = {{"n_features", orb.n_features},
                 {"levels", orb.levels},
                 {"scale_factor", orb.scale_factor},
                 {"fast_mode", to_string(orb.fast_mode)},
                 {"fast_threshold", orb.fast_threshold},
                 {"fast_ini_threshold", orb.fast_ini_threshold},
                 {"fast_min_threshold", orb.fast_min_threshold},
                 {"fast_impl", to_string(resolve_fast_impl(orb.fast_impl))},
                 {"ssc_tolerance", orb.ssc_tolerance},
                 {"distribution_repeats", std::max(1, options.distribution_repeats)},
                 {"right_feature_factor", options.right_feature_factor}};
  j["pyramid_ms"] = summarize(pyramid_ms);
  j["fast_ms"] = summarize(fast_ms);
  j["ssc_ms"] = summarize(ssc_ms);
  j["quadtree_ms"] = summarize(quadtree_ms);
  j["orb_ms"] = summarize(orb_ms);
  j["left_extract_ms"] = summarize(left_ms);
  j["right_extract_ms"] = summarize(right_ms);
  j["stereo_points_ms"] = summarize(stereo_ms);
  // quadtree / SSC, medians over frames: of the per-frame medians of the repeats, and of the
  // first run of each per frame (colder caches; what a single timing per frame sees).
  const auto speedup = [](const std::vector<double>& quad, const std::vector<double>& ssc) {
    const double s = percentile(ssc, 0.5);
    return s > 0 ? percentile(quad, 0.5) / s : 0.0;
  };
  j["ssc_speedup"] = speedup(quadtree_ms, ssc_ms);
  j["ssc_speedup_first_run"] = speedup(quadtree_first_ms, ssc_first_ms);
  j["keypoints"] = summarize(kept_ssc);
  j["keypoints"]["fast_candidates"] = summarize(candidates);
  j["keypoints"]["quadtree"] = summarize(kept_quadtree);
  j["stereo_matches"] = summarize(matches);
  j["stereo_matches"]["share"] = summarize(match_share);
  j["uniformity_cv"] = summarize(cv_ssc);
  j["uniformity_cv"]["ssc"] = summarize(cv_ssc);
  j["uniformity_cv"]["quadtree"] = summarize(cv_quadtree);
  return j;
}

}  // namespace plslam::bench
