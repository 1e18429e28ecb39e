// plslam map info FILE [--json] | map export FILE --out DIR: what a saved map (.plmap) holds, and
// its points, lines and keyframe poses as the PLY and TUM files that `plslam run` writes.
#include <algorithm>
#include <fstream>
#include <iterator>
#include <iostream>
#include <limits>

#include <fmt/format.h>
#include <nlohmann/json.hpp>
#include <spdlog/spdlog.h>

#include "command_registry.h"
#include "json_stdout.h"
#include "plslam/core/stopwatch.h"
#include "plslam/io/map_export.h"
#include "plslam/io/output_folder.h"
#include "plslam/io/trajectory_io.h"
#include "plslam/core/error.h"
#include "plslam/core/input_file.h"
#include "plslam/system/map_file.h"
#include "plslam/system/system_config.h"

namespace plslam::cli {
namespace {

namespace fs = std::filesystem;

struct MapInfoArgs {
  std::string file;
  std::string vocabulary;
  bool json = false;
  bool check = false;
};

std::string read_whole_file(const fs::path& path) {
  std::ifstream in = open_input_file(path, "map file not found");
  return std::string(std::istreambuf_iterator<char>(in), {});
}

// --check: the file restores into a map (and keyframe database) that saves to the file's own bytes
// (a file of an older format version: to its contents written in the current one).
nlohmann::json check_round_trip(const system::MapContents& contents, const MapInfoArgs& args) {
  const std::string original = contents.meta.version == system::kMapFileVersion ? read_whole_file(args.file)
                                                                                 : system::map_to_bytes(contents);
  system::SystemOptions options;
  if (!args.vocabulary.empty()) options.vocabulary = args.vocabulary;
  const auto vocabulary = system::load_vocabulary(options);
  if (contents.meta.vocabulary_checksum != 0 && vocabulary->checksum() != contents.meta.vocabulary_checksum) {
    throw InputError(args.file, fmt::format("made with vocabulary {:016x}, not {:016x} (pass --vocabulary)",
                                            contents.meta.vocabulary_checksum, vocabulary->checksum()));
  }
  map::Map map;
  place::KeyframeDatabase database(vocabulary);
  auto t0 = std::chrono::steady_clock::now();
  system::restore_map(contents, map, &database);
  const double restore_ms = ms_since(t0);
  t0 = std::chrono::steady_clock::now();
  auto meta = contents.meta;
  const std::string again = system::map_to_bytes(system::capture_map(map, &database, meta));
  const double write_ms = ms_since(t0);
  return {{"restore_ms", restore_ms}, {"capture_and_serialize_ms", write_ms}, {"identical", again == original}};
}

struct MapExportArgs {
  std::string file;
  std::string out;
};

// Keyframe poses T_wc by time: the map's keyframe trajectory.
Trajectory keyframe_trajectory(const system::MapContents& c) {
  Trajectory t;
  for (const auto& k : c.keyframes) t.push_back({k.data->timestamp, k.T_cw.inverse().isometry()});
  std::sort(t.begin(), t.end(), [](const auto& a, const auto& b) { return a.t < b.t; });
  return t;
}

nlohmann::json map_info_json(const system::MapContents& c, const fs::path& file, double load_ms) {
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
  Eigen::Vector3d hi = -lo;
  auto extend = [&](const Eigen::Vector3d& p) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  };
  for (const auto& p : c.points) extend(p.a);
  for (const auto& l : c.lines) {
    extend(l.a);
    extend(l.b);
  }
  Eigen::Vector3d klo = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity()), khi = -klo;
  std::size_t covisibility_edges = 0, loop_edges = 0, described = 0, observations = 0;
  for (const auto& k : c.keyframes) {
    const Eigen::Vector3d centre = k.T_cw.inverse().translation();
    klo = klo.cwiseMin(centre);
    khi = khi.cwiseMax(centre);
    covisibility_edges += k.covisibility.size();
    loop_edges += k.loop_edges.size();
    described += k.place != nullptr;
  }
  for (const auto* set : {&c.points, &c.lines}) {
    for (const auto& l : *set) observations += l.observations.size();
  }
  auto box = [](const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
    if (!std::isfinite(a.x())) return nlohmann::json(nullptr);
    return nlohmann::json{{"min", {a.x(), a.y(), a.z()}}, {"max", {b.x(), b.y(), b.z()}}};
  };
  const auto& m = c.meta;
  std::error_code ec;
  const auto bytes = fs::file_size(file, ec);
  nlohmann::json j = {
      {"file", file.string()},
      {"bytes", ec ? 0 : bytes},
      {"load_ms", load_ms},
      {"version", m.version},
      {"created_by", m.created_by},
      {"calibration",
       {{"width", m.calib.width}, {"height", m.calib.height}, {"fx", m.calib.fx}, {"fy", m.calib.fy},
        {"cx", m.calib.cx}, {"cy", m.calib.cy}, {"baseline", m.calib.baseline}}},
      {"vocabulary",
       m.vocabulary_checksum == 0
           ? nlohmann::json(nullptr)
           : nlohmann::json{{"checksum", fmt::format("{:016x}", m.vocabulary_checksum)},
                            {"words", m.vocabulary_words}}},
      {"keyframes", c.keyframes.size()},
      {"keyframes_with_bag_of_words", described},
      {"points", c.points.size()},
      {"lines", c.lines.size()},
      {"observations", observations},
      {"covisibility_edges", covisibility_edges / 2},
      {"loop_edges", loop_edges / 2},
      {"extent_m", box(lo, hi)},
      {"keyframe_extent_m", box(klo, khi)},
      {"ground_truth_anchor", m.T_gt_map.has_value()},
      {"gravity_aligned", m.gravity_aligned},
      {"keyframes_with_imu_state", std::count_if(c.keyframes.begin(), c.keyframes.end(), [](const auto& k) { return k.imu.has_value(); })},
      {"config", m.config}};
  return j;
}

int run_map_info(const MapInfoArgs& args) {
  const auto t0 = std::chrono::steady_clock::now();
  const auto contents = system::load_map_file(args.file);
  auto j = map_info_json(contents, args.file, ms_since(t0));
  if (args.check) j["check"] = check_round_trip(contents, args);
  const int rc = args.check && !j["check"]["identical"].get<bool>() ? 1 : 0;
  if (args.json) {
    print_json(j.dump(2) + "\n");
    return rc;
  }
  std::cout << fmt::format("{}: plslam map version {}, {} bytes, read in {:.1f} ms\n", args.file,
                           j["version"].get<int>(), j["bytes"].get<std::size_t>(), j["load_ms"].get<double>());
  std::cout << fmt::format("created by: {}\n", contents.meta.created_by);
  const auto& c = contents.meta.calib;
  std::cout << fmt::format("calibration: {}x{}, fx {:.3f} fy {:.3f} cx {:.3f} cy {:.3f}, baseline {:.4f} m\n", c.width,
                           c.height, c.fx, c.fy, c.cx, c.cy, c.baseline);
  std::cout << fmt::format("vocabulary: {}\n", j["vocabulary"].is_null()
                                                   ? std::string("none")
                                                   : fmt::format("{} ({} words)", j["vocabulary"]["checksum"].get<std::string>(),
                                                                 contents.meta.vocabulary_words));
  std::cout << fmt::format("keyframes {}, points {}, lines {}, covisibility edges {}, loop edges {}\n",
                           contents.keyframes.size(), contents.points.size(), contents.lines.size(),
                           j["covisibility_edges"].get<std::size_t>(), j["loop_edges"].get<std::size_t>());
  std::cout << fmt::format("world: {}, {} keyframes with an IMU state\n",
                           contents.meta.gravity_aligned ? "gravity-aligned (z up)" : "the first keyframe's",
                           j["keyframes_with_imu_state"].get<long>());
  if (!j["extent_m"].is_null()) {
    const auto& e = j["extent_m"];
    std::cout << fmt::format("extent: x {:.2f} .. {:.2f}, y {:.2f} .. {:.2f}, z {:.2f} .. {:.2f} m\n",
                             e["min"][0].get<double>(), e["max"][0].get<double>(), e["min"][1].get<double>(),
                             e["max"][1].get<double>(), e["min"][2].get<double>(), e["max"][2].get<double>());
  }
  std::cout << "config:\n" << contents.meta.config << "\n";
  if (args.check) {
    const auto& c = j["check"];
    std::cout << fmt::format("check: restored in {:.1f} ms, saved again in {:.1f} ms: {}\n", c["restore_ms"].get<double>(),
                             c["capture_and_serialize_ms"].get<double>(),
                             c["identical"].get<bool>() ? "identical bytes" : "DIFFERENT BYTES");
  }
  return rc;
}

int run_map_export(const MapExportArgs& args) {
  io::prepare_output_folder(args.out);
  const auto contents = system::load_map_file(args.file);
  const fs::path out = args.out;
  std::vector<Eigen::Vector3d> points;
  for (const auto& p : contents.points) points.push_back(p.a);
  io::write_ply_points(out / "map_points.ply", points);
  std::vector<std::pair<Eigen::Vector3d, Eigen::Vector3d>> lines;
  for (const auto& l : contents.lines) lines.emplace_back(l.a, l.b);
  io::write_ply_lines(out / "map_lines.ply", lines);
  io::write_trajectory(out / "keyframes.tum", keyframe_trajectory(contents), io::TrajectoryFormat::kTum);
  spdlog::info("{}: {} points, {} lines, {} keyframes written to {}", args.file, points.size(), lines.size(),
               contents.keyframes.size(), out.string());
  return 0;
}

CommandRegistration register_map_command({"map", "Inspect and export a saved map (.plmap)", [](CLI::App& sub) {
                           sub.require_subcommand(1);
                           auto info_args = std::make_shared<MapInfoArgs>();
                           CLI::App* info = sub.add_subcommand("info", "Counts, extent, calibration, vocabulary and config");
                           info->add_option("file", info_args->file, "Map file")->required();
                           info->add_flag("--json", info_args->json, "Print a JSON object");
                           info->add_flag("--check", info_args->check,
                                          "Restore the map and save it again in memory: the bytes must be the same "
                                          "(exit 1 if not); with the times");
                           info->add_option("--vocabulary", info_args->vocabulary,
                                            "Vocabulary for --check (default: the one in data/vocabulary)");
                           auto export_args = std::make_shared<MapExportArgs>();
                           CLI::App* exp = sub.add_subcommand(
                               "export", "Write map_points.ply, map_lines.ply and keyframes.tum, as run does");
                           exp->add_option("file", export_args->file, "Map file")->required();
                           exp->add_option("--out", export_args->out, "Output folder")->required();
                           return std::function<int()>([info_args, info, export_args, exp] {
                             if (info->parsed()) return run_map_info(*info_args);
                             return exp->parsed() ? run_map_export(*export_args) : 2;
                           });
                         }});

}  // namespace
}  // namespace plslam::cli
