// The vocabulary's costs that place recognition pays, for the default vocabulary plslam ships
// (data/vocabulary/, scripts/train-vocabulary.sh): loading the file, and turning one frame's
// descriptors (KITTI 06 frame 25, 2000 ORB features) into a bag of words plus a feature vector.
#include <cstdlib>
#include <filesystem>
#include <memory>

#include <benchmark/benchmark.h>

#include "plslam/features/orb_extractor.h"
#include "plslam/io/dataset.h"
#include "plslam/place/vocabulary.h"

namespace {

using namespace plslam;

struct Setup {
  std::filesystem::path file;
  std::size_t file_bytes = 0;
  std::size_t words = 0;
  cv::Mat frame_descriptors;  // KITTI 06 frame 25
};

const Setup* setup() {
  static std::unique_ptr<Setup> s = []() -> std::unique_ptr<Setup> {
    std::filesystem::path shared = PLSLAM_DEFAULT_SHARED_DIR;
    if (const char* env = std::getenv("PLSLAM_SHARED_DIR")) shared = env;
    const auto kitti = shared / "data/kitti/sequences/06";
    if (!std::filesystem::exists(kitti)) return nullptr;
    auto out = std::make_unique<Setup>();
    out->file = std::filesystem::path(PLSLAM_SOURCE_DIR) / "data/vocabulary/plslam_orb_k10_l4.plvoc";
    out->file_bytes = std::filesystem::file_size(out->file);
    out->words = place::Vocabulary::load(out->file).size();
    const auto ds = io::open_dataset(kitti);
    out->frame_descriptors = features::OrbExtractor(features::OrbOptions::kitti()).extract(ds->load(25).left).descriptors;
    return out;
  }();
  return s.get();
}

void BM_VocabularyLoad(benchmark::State& st) {
  const Setup* s = setup();
  if (!s) {
    st.SkipWithError("shared data not found");
    return;
  }
  for (auto _ : st) benchmark::DoNotOptimize(place::Vocabulary::load(s->file));
  st.counters["words"] = static_cast<double>(s->words);
  st.counters["file_MB"] = static_cast<double>(s->file_bytes) / 1e6;
}
BENCHMARK(BM_VocabularyLoad)->Unit(benchmark::kMillisecond);

void BM_VocabularyTransformFrame(benchmark::State& st) {
  const Setup* s = setup();
  if (!s) {
    st.SkipWithError("shared data not found");
    return;
  }
  const place::Vocabulary voc = place::Vocabulary::load(s->file);
  place::FeatureVector fv;
  for (auto _ : st) benchmark::DoNotOptimize(voc.transform(s->frame_descriptors, &fv, 2));
  st.counters["descriptors"] = s->frame_descriptors.rows;
}
BENCHMARK(BM_VocabularyTransformFrame)->Unit(benchmark::kMillisecond);

}  // namespace
