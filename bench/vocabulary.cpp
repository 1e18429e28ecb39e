// The vocabulary's costs that place recognition pays: loading the file, and turning one frame's
// descriptors (KITTI 06, 2000 ORB features) into a bag of words plus a feature vector. The
// vocabulary is trained here once, as `plslam vocab train` does with its defaults (k = 10,
// L = 4), on every second left image of KITTI 06 and EuRoC V1_01 micro.
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <memory>

#include <benchmark/benchmark.h>
#include <opencv2/core/utility.hpp>

#include "plslam/features/orb_extractor.h"
#include "plslam/io/dataset.h"
#include "plslam/place/vocabulary_training.h"

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
    const auto kitti = shared / "data/kitti/sequences/06", euroc = shared / "data/euroc/V1_01_easy_micro";
    if (!std::filesystem::exists(kitti) || !std::filesystem::exists(euroc)) return nullptr;
    auto out = std::make_unique<Setup>();
    std::vector<std::vector<place::Descriptor256>> images;
    for (const auto& path : {kitti, euroc}) {
      const auto ds = io::open_dataset(path);
      const features::OrbExtractor ex(ds->format() == io::DatasetFormat::kKitti ? features::OrbOptions::kitti()
                                                                                  : features::OrbOptions::euroc());
      for (std::size_t i = 0; i < ds->size(); i += 2) {
        const auto f = ex.extract(ds->load(i).left);
        images.push_back(place::descriptors_from_mat(f.descriptors));
      }
      if (path == kitti) out->frame_descriptors = ex.extract(ds->load(25).left).descriptors;
    }
    const place::Vocabulary voc = place::train_vocabulary(images, place::VocabularyTrainingOptions{});
    const std::string bytes = voc.to_bytes();
    out->file = std::filesystem::temp_directory_path() / "plslam_bench_vocabulary.bin";
    std::ofstream(out->file, std::ios::binary).write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
    out->file_bytes = bytes.size();
    out->words = voc.size();
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
