// plslam vocab train <dataset>... --out FILE: plslam's own visual vocabulary, from the ORB
// descriptors its extractor computes on the left images of any number of datasets.
// plslam vocab info FILE [--json]: a vocabulary file's parameters (after the loader's checks).
// plslam vocab eval <dataset> [--vocabulary F] [--every N] [--json]: place recognition's
// precision-recall on a sequence with ground truth (src/plslam/place/recognition_eval.h).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <iostream>
#include <filesystem>
#include <memory>
#include <vector>

#include <fmt/format.h>
#include <nlohmann/json.hpp>
#include <spdlog/spdlog.h>

#include "command_registry.h"
#include "json_stdout.h"
#include "plslam/core/error.h"
#include "plslam/features/orb_extractor.h"
#include "plslam/io/atomic_file.h"
#include "plslam/io/dataset.h"
#include "plslam/place/recognition_eval.h"
#include "plslam/place/vocabulary_training.h"
#include "plslam/system/system_config.h"
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

struct VocabInfoArgs {
  std::string file;
  bool json = false;
};

int run_vocab_info(const VocabInfoArgs& args) {
  const auto t0 = Clock::now();
  const auto voc = place::Vocabulary::load(args.file);  // InputError (exit 2) for a bad file
  const double load_ms = 1e3 * seconds_since(t0);
  std::size_t used_levels = 0;
  for (const auto& n : voc.nodes()) used_levels = std::max<std::size_t>(used_levels, n.depth);
  const auto bytes = std::filesystem::file_size(args.file);
  if (args.json) {
    nlohmann::json j = {{"file", args.file},     {"format_version", 1},          {"descriptor", "ORB (256 bits)"},
                        {"k", voc.k()},          {"levels", voc.levels()},      {"deepest_leaf", used_levels},
                        {"words", voc.size()},   {"nodes", voc.nodes().size()}, {"bytes", bytes},
                        {"load_ms", load_ms}};
    print_json(j.dump(2) + "\n");
    return 0;
  }
  std::cout << fmt::format(
      "{}: plslam vocabulary v1, ORB (256 bits), k = {}, L = {} (deepest leaf {}), {} words, {} nodes, "
      "{:.2f} MB, checksum ok, loaded in {:.1f} ms\n",
      args.file, voc.k(), voc.levels(), used_levels, voc.size(), voc.nodes().size(), static_cast<double>(bytes) / 1e6,
      load_ms);
  return 0;
}

struct VocabEvalArgs {
  std::string dataset;
  std::string vocabulary;  // empty: the default
  int every = 10;
  double precision = 0.95;
  bool json = false;
};

int run_vocab_eval(const VocabEvalArgs& args) {
  app::install_stop_signals();
  const auto ds = io::open_dataset(args.dataset);
  if (!ds->ground_truth()) throw InputError(ds->root().string(), "no ground truth: place recognition cannot be scored");
  const std::filesystem::path voc_path =
      args.vocabulary.empty() ? system::default_vocabulary_path() : std::filesystem::path(args.vocabulary);
  auto vocabulary = std::make_shared<const place::Vocabulary>(place::Vocabulary::load(voc_path));
  const features::OrbExtractor extractor(ds->format() == io::DatasetFormat::kKitti ? features::OrbOptions::kitti()
                                                                                    : features::OrbOptions::euroc());
  const auto& gt = *ds->ground_truth();
  const double tolerance = ds->fps() > 0 ? 0.5 / ds->fps() : 0.01;
  std::vector<place::PlaceSample> samples;
  std::vector<std::size_t> frame_of;  // the dataset frame of each sample
  const auto t0 = Clock::now();
  const std::size_t total = (ds->size() + static_cast<std::size_t>(args.every) - 1) / static_cast<std::size_t>(args.every);
  for (std::size_t i = 0; i < ds->size(); i += static_cast<std::size_t>(args.every)) {
    if (app::stop_requested()) return stopped();
    const double t = ds->timestamps()[i];
    const auto it = std::lower_bound(gt.begin(), gt.end(), t - tolerance,
                                     [](const StampedPose& p, double v) { return p.t < v; });
    if (it == gt.end() || std::abs(it->t - t) > tolerance) continue;  // no ground truth for this frame
    place::PlaceSample s;
    s.timestamp = t;
    s.centre = it->T.translation();
    s.direction = it->T.linear() * Eigen::Vector3d::UnitZ();
    s.descriptors = extractor.extract(ds->load(i).left).descriptors;
    samples.push_back(std::move(s));
    frame_of.push_back(i);
    if (!args.json && samples.size() % 20 == 0) {
      spdlog::info("vocab eval: features of {}/{} keyframes, ETA {:.0f} s", samples.size(), total,
                   eta_seconds(t0, samples.size(), total));
    }
  }
  const auto r = place::evaluate_place_recognition(samples, vocabulary);
  const double recall = r.recall_at_precision(args.precision);
  double threshold = 0;
  for (const auto& p : r.curve) {
    if (p.precision >= args.precision && p.recall == recall) threshold = p.threshold;
  }
  if (args.json) {
    nlohmann::json curve = nlohmann::json::array();
    for (const auto& p : r.curve) {
      curve.push_back({{"threshold", p.threshold}, {"accepted", p.accepted}, {"correct", p.correct},
                       {"precision", p.precision}, {"recall", p.recall}});
    }
    // Every answered query in the curve's order, with how far its top candidate is: what a false
    // one is (a near miss, a look-alike, a view from the other end) decides what could remove it.
    nlohmann::json answers = nlohmann::json::array();
    for (const std::size_t k : r.ranked) {
      const auto& q = r.queries[k];
      answers.push_back({{"frame", frame_of[q.sample]}, {"top_frame", frame_of[static_cast<std::size_t>(q.top)]},
                         {"score", q.score}, {"raw_score", q.raw_score}, {"correct", q.correct},
                         {"has_true_match", q.has_true_match}, {"distance_m", q.top_distance_m},
                         {"angle_deg", q.top_angle_deg}});
    }
    nlohmann::json j = {{"dataset", ds->root().string()}, {"vocabulary", voc_path.string()},
                        {"keyframes", samples.size()},     {"every", args.every},
                        {"queries", r.queries.size()},      {"queries_with_true_match", r.with_true_match},
                        {"precision", args.precision},      {"recall_at_precision", recall},
                        {"threshold", threshold},           {"curve", curve},
                        {"answers", answers}};
    print_json(j.dump(2) + "\n");
    return 0;
  }
  const double top1 = r.curve.empty() ? 0 : r.curve.back().precision;
  std::cout << fmt::format(
      "{}: {} keyframes (every {} frames), {} queries, {} with a revisit (within 2 m and 30 deg, over 2 s "
      "earlier)\nrecall {:.3f} at precision >= {:.2f} (score >= {:.4f}); accepting every top candidate: "
      "precision {:.3f}, recall {:.3f}\n",
      ds->root().string(), samples.size(), args.every, r.queries.size(), r.with_true_match, recall, args.precision,
      threshold, top1, r.curve.empty() ? 0.0 : r.curve.back().recall);
  const auto first_false =
      std::find_if(r.ranked.begin(), r.ranked.end(), [&](std::size_t k) { return !r.queries[k].correct; });
  if (first_false != r.ranked.end()) {
    const auto& q = r.queries[*first_false];
    std::cout << fmt::format("best-scoring false candidate (rank {}): frame {} -> frame {}, score {:.4f}, {:.2f} m and "
                             "{:.0f} deg apart{}\n",
                             first_false - r.ranked.begin() + 1, frame_of[q.sample],
                             frame_of[static_cast<std::size_t>(q.top)], q.score, q.top_distance_m, q.top_angle_deg,
                             q.has_true_match ? "" : " (the query has no true match)");
  }
  return 0;
}

CommandRegistration register_vocab_command({"vocab", "Train plslam's visual vocabulary (bag of words for place recognition)",
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
                           auto info_args = std::make_shared<VocabInfoArgs>();
                           CLI::App* info = sub.add_subcommand("info", "Print a vocabulary file's parameters");
                           info->add_option("file", info_args->file, "Vocabulary file")->required();
                           info->add_flag("--json", info_args->json, "Print a JSON object");
                           auto eval_args = std::make_shared<VocabEvalArgs>();
                           CLI::App* eval = sub.add_subcommand(
                               "eval", "Precision-recall of place recognition on a sequence with ground truth");
                           eval->add_option("dataset", eval_args->dataset, "KITTI sequences/NN or EuRoC folder")->required();
                           eval->add_option("--vocabulary", eval_args->vocabulary, "Vocabulary file (default: data/vocabulary)");
                           eval->add_option("--every", eval_args->every, "One keyframe every N frames")
                               ->check(CLI::Range(1, 1'000'000))->capture_default_str();
                           eval->add_option("--precision", eval_args->precision, "Report the recall at this precision")
                               ->check(CLI::Range(0.0, 1.0))->capture_default_str();
                           eval->add_flag("--json", eval_args->json, "Print a JSON object");
                           return std::function<int()>([args, train, info_args, info, eval_args, eval] {
                             if (info->parsed()) return run_vocab_info(*info_args);
                             if (eval->parsed()) return run_vocab_eval(*eval_args);
                             return train->parsed() ? run_vocab_train(*args) : 2;
                           });
                         }});

}  // namespace
}  // namespace plslam::cli
