#pragma once
// The dataset selection options shared by every command that reads a sequence.
#include <memory>
#include <string>

#include <CLI/CLI.hpp>

#include "plslam/io/dataset.h"

namespace plslam::cli {

struct DatasetArgs {
  std::string path;
  std::string format = "auto";
  // Signed, so that "-5" is refused by the range check instead of wrapping around.
  long long start = 0;
  long long max_frames = -1;

  io::DatasetOptions options() const {
    io::DatasetOptions o;
    o.format = io::parse_dataset_format(format);
    o.start = static_cast<std::size_t>(start);
    if (max_frames >= 0) o.max_frames = static_cast<std::size_t>(max_frames);
    return o;
  }
};

// The largest frame count or index taken from the command line: far above any real sequence, and
// small enough that every count derived from it stays exact.
inline constexpr long long kMaxFrameArg = 1'000'000'000;

// `max_frames_names` lets `bench` keep its shorter "--frames" alias; `run` takes other inputs
// too, so its dataset folder is optional.
inline void add_dataset_options(CLI::App& sub, DatasetArgs& args,
                                const std::string& max_frames_names = "--max-frames", bool required = true) {
  sub.add_option("dataset", args.path, "Sequence folder: KITTI sequences/NN, or EuRoC <seq> or <seq>/mav0")
      ->required(required);
  sub.add_option("--format", args.format, "Dataset format")
      ->check(CLI::IsMember({"auto", "kitti", "euroc"}))
      ->capture_default_str();
  sub.add_option("--start", args.start, "First frame to use")
      ->check(CLI::Range(0LL, kMaxFrameArg))
      ->capture_default_str();
  sub.add_option(max_frames_names, args.max_frames, "Use at most this many frames (-1: all)")
      ->check(CLI::Range(-1LL, kMaxFrameArg))
      ->capture_default_str();
}

}  // namespace plslam::cli
