// Rendering speed of one stereo pair (both cameras, sensor model, no PNG encoding) on one
// core. Target: < 30 ms at the EuRoC preset.
#include <benchmark/benchmark.h>

#include "plslam/synth/sequence.h"

namespace {

void render_pairs(benchmark::State& state, plslam::synth::SceneKind scene, plslam::synth::CameraPreset preset,
                  bool blur) {
  plslam::synth::SequenceOptions o;
  o.scene = scene;
  o.preset = preset;
  o.frames = 400;
  o.motion_blur = blur;
  const plslam::synth::Sequence seq(o);
  plslam::synth::StereoRenderer renderer(seq);
  std::size_t i = 0;
  for (auto _ : state) {
    auto images = renderer.render(i);
    benchmark::DoNotOptimize(images.left.data);
    i = (i + 7) % seq.size();
  }
}

void BM_OfficeEuroc(benchmark::State& s) { render_pairs(s, plslam::synth::SceneKind::kOffice, plslam::synth::euroc_preset(), false); }
void BM_CorridorEuroc(benchmark::State& s) { render_pairs(s, plslam::synth::SceneKind::kCorridor, plslam::synth::euroc_preset(), false); }
void BM_StreetEuroc(benchmark::State& s) { render_pairs(s, plslam::synth::SceneKind::kStreet, plslam::synth::euroc_preset(), false); }
void BM_StreetKitti(benchmark::State& s) { render_pairs(s, plslam::synth::SceneKind::kStreet, plslam::synth::kitti_preset(), false); }
void BM_OfficeEurocMotionBlur(benchmark::State& s) { render_pairs(s, plslam::synth::SceneKind::kOffice, plslam::synth::euroc_preset(), true); }

BENCHMARK(BM_OfficeEuroc)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_CorridorEuroc)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_StreetEuroc)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_StreetKitti)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_OfficeEurocMotionBlur)->Unit(benchmark::kMillisecond);

}  // namespace
