// Per-stage cost of the point front end on real first frames of KITTI 06 and EuRoC V1_01 micro,
// one thread: pyramid, FAST, SSC vs quadtree on the same candidates, orientation+BRIEF, the whole
// left image, and stereo matching.
#include <cstdlib>
#include <filesystem>
#include <map>
#include <memory>

#include <benchmark/benchmark.h>
#include <opencv2/core/utility.hpp>

#include "plslam/features/orb_extractor.h"
#include "plslam/io/dataset.h"
#include "plslam/matching/stereo_point_frame.h"

namespace {

using namespace plslam;

struct Scene {
  io::StereoFrame frame;
  StereoCalibration calib;
  features::OrbOptions orb;
};

// Loads the first frame of a sequence once; the benchmark is skipped when the data is absent.
const Scene* scene(const std::string& which) {
  static std::map<std::string, std::unique_ptr<Scene>> cache;
  auto it = cache.find(which);
  if (it != cache.end()) return it->second.get();
  std::filesystem::path shared = PLSLAM_DEFAULT_SHARED_DIR;
  if (const char* env = std::getenv("PLSLAM_SHARED_DIR")) shared = env;
  const auto path = shared / "data" / (which == "kitti" ? "kitti/sequences/06" : "euroc/V1_01_easy_micro");
  std::unique_ptr<Scene> s;
  if (std::filesystem::exists(path)) {
    const auto ds = io::open_dataset(path);
    s = std::make_unique<Scene>();
    s->frame = ds->load(0);
    s->calib = ds->calibration();
    s->orb = which == "kitti" ? features::OrbOptions::kitti() : features::OrbOptions::euroc();
  }
  return (cache[which] = std::move(s)).get();
}

#define REQUIRE_SCENE(st, s)                                   \
  const Scene* s = scene(st.range(0) == 0 ? "kitti" : "euroc"); \
  if (!s) {                                                    \
    st.SkipWithError("shared data not found");                 \
    return;                                                    \
  }                                                            \
  cv::setNumThreads(1);                                        \
  st.SetLabel(st.range(0) == 0 ? "KITTI 06" : "EuRoC micro")

void BM_Pyramid(benchmark::State& st) {
  REQUIRE_SCENE(st, s);
  const features::OrbExtractor ex(s->orb);
  features::ImagePyramid p;
  for (auto _ : st) {
    ex.build_pyramid(s->frame.left, p);
    benchmark::DoNotOptimize(p.level(7).data);
  }
}

void fast(benchmark::State& st, features::FastImpl impl) {
  REQUIRE_SCENE(st, s);
  features::OrbOptions o = s->orb;
  o.fast_impl = impl;
  const features::OrbExtractor ex(o);
  features::ImagePyramid p;
  ex.build_pyramid(s->frame.left, p);
  for (auto _ : st) benchmark::DoNotOptimize(ex.detect(p));
}
// Own SIMD FAST (AVX2 when the CPU has it) against cv::FAST, same corners.
void BM_Fast(benchmark::State& st) { fast(st, features::FastImpl::kAuto); }
void BM_FastSse2(benchmark::State& st) { fast(st, features::FastImpl::kSse2); }
void BM_FastOpenCv(benchmark::State& st) { fast(st, features::FastImpl::kOpenCv); }

void distribution(benchmark::State& st, features::Distribution method) {
  REQUIRE_SCENE(st, s);
  const features::OrbExtractor ex(s->orb);
  features::ImagePyramid p;
  ex.build_pyramid(s->frame.left, p);
  const auto candidates = ex.detect(p);
  for (auto _ : st) benchmark::DoNotOptimize(ex.distribute(candidates, method));
}
void BM_Ssc(benchmark::State& st) { distribution(st, features::Distribution::kSsc); }
void BM_Quadtree(benchmark::State& st) { distribution(st, features::Distribution::kQuadtree); }

void BM_OrientationAndBrief(benchmark::State& st) {
  REQUIRE_SCENE(st, s);
  const features::OrbExtractor ex(s->orb);
  features::PointFeatures f;
  ex.build_pyramid(s->frame.left, f.pyramid);
  const auto kept = ex.distribute(ex.detect(f.pyramid), features::Distribution::kSsc);
  for (auto _ : st) {
    ex.describe(f.pyramid, kept, f);
    benchmark::DoNotOptimize(f.descriptors.data);
  }
}

void left_image(benchmark::State& st, features::FastImpl impl) {
  REQUIRE_SCENE(st, s);
  features::OrbOptions o = s->orb;
  o.fast_impl = impl;
  const features::OrbExtractor ex(o);
  for (auto _ : st) benchmark::DoNotOptimize(ex.extract(s->frame.left));
}
void BM_LeftImage(benchmark::State& st) { left_image(st, features::FastImpl::kAuto); }
void BM_LeftImageOpenCvFast(benchmark::State& st) { left_image(st, features::FastImpl::kOpenCv); }

void BM_StereoMatching(benchmark::State& st) {
  REQUIRE_SCENE(st, s);
  const features::OrbExtractor left(s->orb), right(matching::right_image_options(s->orb));
  const auto fl = left.extract(s->frame.left);
  const auto fr = right.extract(s->frame.right);
  matching::StereoPointOptions o;
  o.bf = s->calib.bf();
  o.baseline = s->calib.baseline;
  int matched = 0;
  for (auto _ : st) {
    const auto m = matching::match_stereo_points(fl, fr, o);
    matched = m.matched;
  }
  st.counters["matched_share"] = static_cast<double>(matched) / static_cast<double>(fl.keypoints.size());
}

// Left and right extraction concurrently plus matching (uses two threads: wall time matters).
void BM_StereoFrameParallel(benchmark::State& st) {
  REQUIRE_SCENE(st, s);
  const features::OrbExtractor left(s->orb), right(matching::right_image_options(s->orb));
  matching::StereoPointOptions o;
  o.bf = s->calib.bf();
  o.baseline = s->calib.baseline;
  for (auto _ : st) benchmark::DoNotOptimize(matching::extract_stereo_points(left, right, s->frame.left, s->frame.right, o));
}

#define SCENES ->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond)->Repetitions(5)->ReportAggregatesOnly(true)
BENCHMARK(BM_Pyramid) SCENES;
BENCHMARK(BM_Fast) SCENES;
BENCHMARK(BM_FastSse2) SCENES;
BENCHMARK(BM_FastOpenCv) SCENES;
BENCHMARK(BM_Ssc) SCENES;
BENCHMARK(BM_Quadtree) SCENES;
BENCHMARK(BM_OrientationAndBrief) SCENES;
BENCHMARK(BM_LeftImage) SCENES;
BENCHMARK(BM_LeftImageOpenCvFast) SCENES;
BENCHMARK(BM_StereoMatching) SCENES;
BENCHMARK(BM_StereoFrameParallel) SCENES->UseRealTime();

}  // namespace
