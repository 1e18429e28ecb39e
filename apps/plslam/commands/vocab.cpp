// plslam vocab train <dataset>... --out FILE: plslam's own visual vocabulary, from the ORB
// descriptors its extractor computes on the left images of any number of datasets.
#include <chrono>
#include <cmath>
#include <iostream>
#include <memory>

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include "command_registry.h"
#include "plslam/core/error.h"
#include "plslam/features/orb_extractor.h"
#include "plslam/io/atomic_file.h"
#include "plslam/io/dataset.h"
#include "plslam/place/vocabulary_training.h"
#include "progress_eta.h"
#include "stop_signals.h"

namespace plslam::cli {
namespace {

struct VocabTrainArgs {
  std::vector<std::string> datasets;
  std::string out;
  int k = 10;
  int levels = 4;
  std::uint64_t seed = 1;
  long long max_images = 0;  // 0: every image
};

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

// Evenly spaced frame indices of a dataset, at most `n` of them (all when n is 0 or more).
std::vector<std::size_t> pick_frames(std::size_t size, std::size_t n) {
  std::vector<std::size_t> picked;
  if (n == 0 || n >= size) n = size;
  for (std::size_t i = 0; i < n; ++i) picked.push_back(i * size / n);
  return picked;
}

// A signal stops training before anything is written.
int stopped() {
  spdlog::warn("vocab: stopped by {}; nothing written", app::stop_signal_name());
  return app::stop_exit_code();
}

int run_vocab_train(const VocabTrainArgs& args) {
  place::VocabularyTrainingOptions options;
  options.k = args.k;
  options.levels = args.levels;
  options.seed = args.seed;
  options.validate();
  app::install_stop_signals();
  std::vector<std::unique_ptr<io::Dataset>> datasets;
  std::size_t total_frames = 0;
  for (const auto& path : args.datasets) {
    datasets.push_back(io::open_dataset(path));
    total_frames += datasets.back()->size();
  }
  // The image budget is shared in proportion to the datasets' lengths.
  std::vector<std::vector<std::size_t>> frames;
  std::size_t images = 0;
  for (const auto& ds : datasets) {
    const std::size_t share =
        args.max_images > 0
            ? std::max<std::size_t>(1, static_cast<std::size_t>(std::llround(static_cast<double>(args.max_images) *
                                                                              static_cast<double>(ds->size()) /
                                                                              static_cast<double>(total_frames))))
            : 0;
    frames.push_back(pick_frames(ds->size(), share));
    images += frames.back().size();
  }
  spdlog::info("vocab: {} images from {} datasets, k = {}, L = {} (at most {} words), seed {}", images, datasets.size(),
               args.k, args.levels, static_cast<long long>(std::pow(args.k, args.levels)), args.seed);

  const auto t0 = Clock::now();
  std::vector<std::vector<place::Descriptor256>> descriptors;
  std::size_t done = 0, total_descriptors = 0;
  for (std::size_t d = 0; d < datasets.size(); ++d) {
    const auto& ds = *datasets[d];
    const features::OrbExtractor extractor(ds.format() == io::DatasetFormat::kKitti ? features::OrbOptions::kitti()
                                                                                      : features::OrbOptions::euroc());
    for (std::size_t i : frames[d]) {
      if (app::stop_requested()) return stopped();
      const auto features = extractor.extract(ds.load(i).left);
      descriptors.push_back(place::descriptors_from_mat(features.descriptors));
      total_descriptors += descriptors.back().size();
      if (++done % 20 == 0 || done == images) {
        spdlog::info("vocab: features of {}/{} images, ETA {:.0f} s", done, images, eta_seconds(t0, done, images));
      }
    }
  }
  const auto t1 = Clock::now();
  std::size_t last = 0;
  const place::Vocabulary voc = place::train_vocabulary(descriptors, options, [&](std::size_t placed, std::size_t all) {
    if (placed == all || placed >= last + all / 10) {
      last = placed;
      spdlog::info("vocab: clustered {}/{} descriptors, ETA {:.0f} s", placed, all, eta_seconds(t1, placed, all));
    }
  });
  if (app::stop_requested()) return stopped();
  const std::string bytes = voc.to_bytes();
  io::write_file_atomically(args.out, [&](std::ostream& out) { out.write(bytes.data(), static_cast<std::streamsize>(bytes.size())); });
  std::cout << fmt::format("vocabulary {}: {} words, {} nodes, {:.2f} MB, from {} descriptors of {} images in {:.1f} s\n",
                           args.out, voc.size(), voc.nodes().size(), static_cast<double>(bytes.size()) / 1e6,
                           total_descriptors, images, seconds_since(t0));
  return 0;
}

CommandRegistration reg({"vocab", "Train plslam's visual vocabulary (bag of words for place recognition)",
                         [](CLI::App& sub) {
                           sub.require_subcommand(1);
                           auto args = std::make_shared<VocabTrainArgs>();
                           CLI::App* train = sub.add_subcommand("train", "Cluster the ORB descriptors of datasets into a vocabulary file");
                           train->add_option("datasets", args->datasets, "KITTI sequences/NN or EuRoC folders")->required();
                           train->add_option("--out", args->out, "Vocabulary file to write")->required();
                           train->add_option("--k", args->k, "Branching factor")->check(CLI::Range(2, 256))->capture_default_str();
                           train->add_option("--levels", args->levels, "Depth of the tree")->check(CLI::Range(1, 16))->capture_default_str();
                           train->add_option("--seed", args->seed, "Seed of the k-means++ seeding")
                               ->check(CLI::NonNegativeNumber)->capture_default_str();
                           train->add_option("--max-images", args->max_images, "At most this many images in all (0: every image)")
                               ->check(CLI::Range(0LL, 1'000'000'000LL))->capture_default_str();
                           return std::function<int()>([args, train] { return train->parsed() ? run_vocab_train(*args) : 2; });
                         }});

}  // namespace
}  // namespace plslam::cli
