// plslam info <dataset>: what the readers see — format, size, rate, rectified calibration, and
// ground truth.
#include <iostream>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "command_registry.h"
#include "json_stdout.h"
#include "commands/dataset_options.h"

namespace plslam::cli {
namespace {

struct InfoArgs {
  DatasetArgs dataset;
  bool json = false;
};

int run_info(const InfoArgs& args) {
  const auto ds = io::open_dataset(args.dataset.path, args.dataset.options());
  const auto& c = ds->calibration();
  const auto& t = ds->timestamps();
  const double duration = t.back() - t.front();
  if (args.json) {
    nlohmann::json j = {{"format", io::to_string(ds->format())},
                        {"frames", ds->size()},
                        {"width", c.width},
                        {"height", c.height},
                        {"fps", ds->fps()},
                        {"fx", c.fx},
                        {"fy", c.fy},
                        {"cx", c.cx},
                        {"cy", c.cy},
                        {"baseline_m", c.baseline},
                        {"duration_s", duration},
                        {"has_ground_truth", ds->ground_truth().has_value()},
                        {"gt_path_length_m", ds->ground_truth_length()}};
    print_json(j.dump(2) + "\n");
    return 0;
  }
  std::cout << fmt::format("dataset      {}\n", ds->root().string())
            << fmt::format("format       {}\n", io::to_string(ds->format()))
            << fmt::format("frames       {}\n", ds->size())
            << fmt::format("resolution   {}x{}\n", c.width, c.height)
            << fmt::format("rate         {:.2f} fps\n", ds->fps())
            << fmt::format("duration     {:.2f} s\n", duration)
            << fmt::format("rectified    fx {:.3f}  fy {:.3f}  cx {:.3f}  cy {:.3f}\n", c.fx, c.fy, c.cx, c.cy)
            << fmt::format("baseline     {:.4f} m  (bf {:.3f})\n", c.baseline, c.bf());
  if (ds->ground_truth()) {
    std::cout << fmt::format("ground truth {} poses, {:.2f} m path  ({})\n", ds->ground_truth()->size(),
                             ds->ground_truth_length(), ds->ground_truth_path().string());
  } else {
    std::cout << "ground truth none\n";
  }
  return 0;
}

CommandRegistration reg({"info", "Describe a stereo dataset (format, frames, calibration, ground truth)",
                         [](CLI::App& sub) {
                           auto args = std::make_shared<InfoArgs>();
                           add_dataset_options(sub, args->dataset);
                           sub.add_flag("--json", args->json, "Print a JSON object");
                           return std::function<int()>([args] { return run_info(*args); });
                         }});

}  // namespace
}  // namespace plslam::cli
