// Line front end on real frames, one core: OpenCV LSD vs our region-growing detector, merging,
// our LBD vs OpenCV's LBD on the same lines, the whole per-image extraction, and stereo line
// matching. Frames: the first 20 of EuRoC V1_01 micro (rectified by the reader) and KITTI 06.
#include <algorithm>
#include <filesystem>
#include <string>
#include <vector>

#include <benchmark/benchmark.h>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/line_descriptor.hpp>

#include "plslam/bench/line_benchmark.h"
#include "plslam/features/line_extractor.h"
#include "plslam/io/dataset.h"
#include "plslam/matching/stereo_line_matcher.h"

namespace fs = std::filesystem;
using namespace plslam;
using namespace plslam::features;

namespace {

struct Sequence {
  std::vector<std::pair<cv::Mat, cv::Mat>> frames;
  StereoCalibration calib;
  LineExtractorOptions options;
};

fs::path data_dir() {
  if (const char* env = std::getenv("PLSLAM_SHARED_DIR")) return fs::path(env) / "data";
  return fs::path(PLSLAM_DEFAULT_SHARED_DIR) / "data";
}

// First 20 frames through the project's dataset reader (EuRoC rectified, KITTI as is); empty
// when the shared data is absent.
Sequence load(const fs::path& path, LineExtractorOptions options) {
  Sequence q;
  q.options = options;
  if (!fs::exists(path)) return q;
  io::DatasetOptions d;
  d.max_frames = 20;
  const auto ds = io::open_dataset(path, d);
  q.calib = ds->calibration();
  for (std::size_t i = 0; i < ds->size(); ++i) {
    io::StereoFrame f = ds->load(i);
    q.frames.emplace_back(std::move(f.left), std::move(f.right));
  }
  return q;
}

const Sequence& euroc() {
  static const Sequence s = load(data_dir() / "euroc/V1_01_easy_micro", LineExtractorOptions::euroc());
  return s;
}

const Sequence& kitti() {
  static const Sequence s = load(data_dir() / "kitti/sequences/06", LineExtractorOptions::kitti());
  return s;
}

const Sequence& seq(int which) { return which == 0 ? euroc() : kitti(); }

bool ready(benchmark::State& state, const Sequence& s) {
  if (s.frames.empty() || s.frames.front().first.empty()) {
    state.SkipWithError("shared data not found");
    return false;
  }
  cv::setNumThreads(1);  // one core, as the targets state
  state.SetLabel(state.range(0) == 0 ? "euroc" : "kitti06");
  return true;
}

// OpenCV's imgproc LSD alone, full resolution, no refinement: the reference detector.
void BM_LsdOpenCV(benchmark::State& state) {
  const Sequence& s = seq(static_cast<int>(state.range(0)));
  if (!ready(state, s)) return;
  auto lsd = cv::createLineSegmentDetector(cv::LSD_REFINE_NONE);
  std::size_t i = 0, n = 0;
  for (auto _ : state) {
    std::vector<cv::Vec4f> raw;
    lsd->detect(s.frames[i++ % s.frames.size()].first, raw);
    n += raw.size();
    benchmark::DoNotOptimize(raw);
  }
  state.counters["lines"] = benchmark::Counter(static_cast<double>(n), benchmark::Counter::kAvgIterations);
}

void BM_LineGrow(benchmark::State& state) {
  const Sequence& s = seq(static_cast<int>(state.range(0)));
  if (!ready(state, s)) return;
  std::size_t i = 0, n = 0;
  for (auto _ : state) {
    auto d = detect_lines(s.frames[i++ % s.frames.size()].first, s.options.detector);
    n += d.segments.size();
    benchmark::DoNotOptimize(d);
  }
  state.counters["lines"] = benchmark::Counter(static_cast<double>(n), benchmark::Counter::kAvgIterations);
}

void BM_LineMerge(benchmark::State& state) {
  const Sequence& s = seq(static_cast<int>(state.range(0)));
  if (!ready(state, s)) return;
  std::vector<DetectedLines> det;
  for (const auto& f : s.frames) det.push_back(detect_lines(f.first, s.options.detector));
  std::size_t i = 0, n = 0;
  for (auto _ : state) {
    const auto& d = det[i++ % det.size()];
    auto m = merge_segments(d.segments, s.frames.front().first.size(), s.options.merge);
    keep_best(m, s.options.max_lines);
    n += m.size();
    benchmark::DoNotOptimize(m);
  }
  state.counters["lines"] = benchmark::Counter(static_cast<double>(n), benchmark::Counter::kAvgIterations);
}

// Kept lines and their gradient per frame, for the descriptor benchmarks.
std::vector<std::pair<DetectedLines, std::vector<LineSegment>>> kept_lines(const Sequence& s) {
  std::vector<std::pair<DetectedLines, std::vector<LineSegment>>> out;
  for (const auto& f : s.frames) {
    DetectedLines d = detect_lines(f.first, s.options.detector);
    auto m = merge_segments(d.segments, f.first.size(), s.options.merge);
    keep_best(m, s.options.max_lines);
    out.emplace_back(std::move(d), std::move(m));
  }
  return out;
}

void BM_LbdOwn(benchmark::State& state) {
  const Sequence& s = seq(static_cast<int>(state.range(0)));
  if (!ready(state, s)) return;
  const auto kept = kept_lines(s);
  std::size_t i = 0, n = 0;
  for (auto _ : state) {
    const auto& [d, lines] = kept[i++ % kept.size()];
    cv::Mat desc = describe_lines(d.gradient, lines, s.options.lbd);
    n += lines.size();
    benchmark::DoNotOptimize(desc);
  }
  state.counters["lines"] = benchmark::Counter(static_cast<double>(n), benchmark::Counter::kAvgIterations);
}

void BM_LbdOpenCV(benchmark::State& state) {
  const Sequence& s = seq(static_cast<int>(state.range(0)));
  if (!ready(state, s)) return;
  const auto kept = kept_lines(s);
  auto bd = cv::line_descriptor::BinaryDescriptor::createBinaryDescriptor();
  std::size_t i = 0, n = 0;
  for (auto _ : state) {
    const std::size_t k = i++ % kept.size();
    state.PauseTiming();
    auto kls = bench::to_keylines(kept[k].second, s.frames[k].first.size());
    state.ResumeTiming();
    cv::Mat desc;
    bd->compute(s.frames[k].first, kls, desc);
    n += kls.size();
    benchmark::DoNotOptimize(desc);
  }
  state.counters["lines"] = benchmark::Counter(static_cast<double>(n), benchmark::Counter::kAvgIterations);
}

void BM_ExtractLines(benchmark::State& state) {
  const Sequence& s = seq(static_cast<int>(state.range(0)));
  if (!ready(state, s)) return;
  std::size_t i = 0, n = 0;
  for (auto _ : state) {
    auto f = extract_lines(s.frames[i++ % s.frames.size()].first, s.options);
    n += f.lines.size();
    benchmark::DoNotOptimize(f);
  }
  state.counters["lines"] = benchmark::Counter(static_cast<double>(n), benchmark::Counter::kAvgIterations);
}

// The same one-image extraction with the reference detector selected (OpenCV LSD, full res).
void BM_ExtractLinesWithLsd(benchmark::State& state) {
  const Sequence& s = seq(static_cast<int>(state.range(0)));
  if (!ready(state, s)) return;
  LineExtractorOptions o = s.options;
  o.detector.kind = LineDetectorKind::kLsd;
  o.detector.scale = 1.0;
  std::size_t i = 0, n = 0;
  for (auto _ : state) {
    auto f = extract_lines(s.frames[i++ % s.frames.size()].first, o);
    n += f.lines.size();
    benchmark::DoNotOptimize(f);
  }
  state.counters["lines"] = benchmark::Counter(static_cast<double>(n), benchmark::Counter::kAvgIterations);
}

void BM_StereoLines(benchmark::State& state) {
  const Sequence& s = seq(static_cast<int>(state.range(0)));
  if (!ready(state, s)) return;
  std::vector<std::pair<LineFeatures, LineFeatures>> feats;
  for (const auto& f : s.frames) feats.emplace_back(extract_lines(f.first, s.options), extract_lines(f.second, s.options));
  std::size_t i = 0, n = 0;
  for (auto _ : state) {
    const auto& [l, r] = feats[i++ % feats.size()];
    auto m = matching::match_stereo_lines(l, r, s.calib);
    n += m.size();
    benchmark::DoNotOptimize(m);
  }
  state.counters["matches"] = benchmark::Counter(static_cast<double>(n), benchmark::Counter::kAvgIterations);
}

}  // namespace

BENCHMARK(BM_LsdOpenCV)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_LineGrow)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_LineMerge)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_LbdOwn)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_LbdOpenCV)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_ExtractLines)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_ExtractLinesWithLsd)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_StereoLines)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);
