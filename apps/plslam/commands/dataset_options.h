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
  std::size_t start = 0;
  long long max_frames = -1;

  io::DatasetOptions options() const {
    io::DatasetOptions o;
    o.format = io::parse_dataset_format(format);
    o.start = start;
    if (max_frames >= 0) o.max_frames = static_cast<std::size_t>(max_frames);
    return o;
  }
};

inline void add_dataset_options(CLI::App& sub, DatasetArgs& args) {
  sub.add_option("dataset", args.path, "Sequence folder: KITTI sequences/NN, or EuRoC <seq> or <seq>/mav0")
      ->required();
  sub.add_option("--format", args.format, "Dataset format")
      ->check(CLI::IsMember({"auto", "kitti", "euroc"}))
      ->capture_default_str();
  sub.add_option("--start", args.start, "First frame to use")->capture_default_str();
  sub.add_option("--max-frames", args.max_frames, "Use at most this many frames (-1: all)")
      ->capture_default_str();
}

}  // namespace plslam::cli
