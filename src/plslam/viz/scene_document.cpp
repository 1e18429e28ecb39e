#include "plslam/viz/scene_document.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <iterator>
#include <limits>
#include <set>

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include "plslam/core/error.h"
#include "plslam/core/input_file.h"
#include "plslam/eval/evaluate.h"
#include "plslam/io/dataset.h"
#include "plslam/io/map_export.h"
#include "plslam/io/trajectory_io.h"
#include "plslam/system/map_file.h"

namespace plslam::viz {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

// `v` rounded to `1 / scale` (scale a power of ten). Dividing the whole number by the exact scale
// gives the double nearest to the short decimal, which nlohmann::json prints in that many digits;
// multiplying by 1e-4 instead would often give its neighbour, printed in 17.
double rounded(double v, double scale) { return std::round(v * scale) / scale; }

// map_graph.json's poses: floats, as the other outputs of a run.
json pose_row_major(const geometry::SE3& T) {
  json out = json::array();
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) out.push_back(static_cast<float>(T.rotation()(r, c)));
    out.push_back(static_cast<float>(T.translation()[r]));
  }
  return out;
}

template <typename T>
json optional_json(const std::optional<T>& v) {
  return v ? json(*v) : json(nullptr);
}

std::string read_text(const fs::path& path) {
  auto in = open_input_file(path);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

// `v` as a long when it is a JSON whole number in long's range, else nullopt. Every whole number
// read here goes through it: get<long>() of a float out of range (an id of 30 digits parses as
// one) is undefined behaviour, and of an unsigned above long's range a wrap-around.
std::optional<long> whole_number(const json& v) {
  if (!v.is_number_integer()) return std::nullopt;
  if (v.is_number_unsigned() && v.get<std::uint64_t>() > static_cast<std::uint64_t>(std::numeric_limits<long>::max())) {
    return std::nullopt;
  }
  return v.get<long>();
}

// A whole number from stats.json, or nullopt when the key is absent or null.
std::optional<long> optional_count(const json& j, const char* key, const std::string& file) {
  if (!j.contains(key) || j[key].is_null()) return std::nullopt;
  const auto n = whole_number(j[key]);
  if (!n) throw InputError(file, fmt::format("'{}' is not a whole number", key));
  return n;
}

// The dataset's ground truth, paired with the run's poses by time and brought into the map's
// world by the inverse of the se3 alignment that scored the run (the same ATE as stats.json).
void add_ground_truth(const json& stats, SceneInfo& info, const Trajectory& estimate) {
  if (!stats.contains("input") || !stats["input"].is_object() || !stats["input"].contains("path") ||
      !stats["input"]["path"].is_string()) {
    return;  // a live camera, or a folder written before runs recorded their input
  }
  const fs::path dataset_path = stats["input"]["path"].get<std::string>();
  std::error_code ec;
  if (!fs::exists(dataset_path, ec)) {
    spdlog::warn("{}: not found, the ground truth is not shown", dataset_path.string());
    return;  // moved since: the map is still worth seeing
  }
  try {
    const auto dataset = io::open_dataset(dataset_path);
    if (!dataset->ground_truth()) return;
    eval::EvalOptions options;
    options.align = eval::AlignMode::kSE3;
    const auto result = eval::evaluate(*dataset->ground_truth(), estimate, options);
    const auto& a = result.alignment;
    for (const auto& g : result.gt) {
      info.ground_truth.push_back(a.R.transpose() * (g.T.translation() - a.t) / a.s);
    }
    info.ate_rmse_m = result.ape_trans_stats.rmse;
  } catch (const InputError& e) {
    // A video input, or too few tracked poses to align: the map without the ground truth.
    spdlog::warn("no ground truth shown: {}", e.what());
  }
}

}  // namespace

void append_page_position(json& flat, const Eigen::Vector3d& p) {
  for (int i = 0; i < 3; ++i) flat.push_back(rounded(p[i], 1e4));
}

json page_pose(const geometry::SE3& T_wc) {
  json out = json::array();
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) out.push_back(rounded(T_wc.rotation()(r, c), 1e6));
    out.push_back(rounded(T_wc.translation()[r], 1e4));
  }
  return out;
}

json map_graph_json(const map::MapSnapshot& map) {
  json keyframes = json::array();
  for (const auto& kf : map.keyframes) {
    json covisibility = json::array();
    for (const auto& [id, weight] : kf.covisibility) covisibility.push_back({id, weight});
    keyframes.push_back({{"id", kf.id},
                         {"t", kf.timestamp},
                         {"T_wc", pose_row_major(kf.T_wc)},
                         {"parent", kf.parent},
                         {"loop_edges", kf.loop_edges},
                         {"covisibility", covisibility}});
  }
  return {{"version", 1}, {"keyframes", keyframes}};
}

void parse_map_graph(const std::string& text, const std::string& source, map::MapSnapshot& map) {
  json j;
  try {
    j = json::parse(text);
  } catch (const json::exception& e) {
    throw InputError(source, std::string("not JSON: ") + e.what());
  }
  auto fail = [&](std::size_t i, const std::string& problem) {
    return InputError(source, fmt::format("keyframe {}: {}", i, problem));
  };
  if (!j.is_object() || !j.contains("version") || j["version"] != 1 || !j.contains("keyframes") ||
      !j["keyframes"].is_array()) {
    throw InputError(source, "expected {\"version\": 1, \"keyframes\": [...]}");
  }
  std::set<long> ids;
  for (std::size_t i = 0; i < j["keyframes"].size(); ++i) {
    const auto& k = j["keyframes"][i];
    if (!k.is_object()) throw fail(i, "not an object");
    map::KeyframeSnapshot kf;
    auto whole = [&](const json& v, const char* what) {
      const auto n = whole_number(v);
      if (!n) throw fail(i, fmt::format("{} is not a whole number in range", what));
      return *n;
    };
    try {
      kf.id = whole(k.at("id"), "id");
      kf.timestamp = k.at("t").get<double>();
      kf.parent = whole(k.at("parent"), "parent");
      const auto T = k.at("T_wc").get<std::vector<double>>();
      if (T.size() != 12) throw fail(i, "T_wc must hold 12 numbers");
      Eigen::Matrix4d M = Eigen::Matrix4d::Identity();
      for (int r = 0; r < 3; ++r) {
        for (int c = 0; c < 4; ++c) M(r, c) = T[static_cast<std::size_t>(4 * r + c)];
      }
      if (!M.allFinite()) throw fail(i, "T_wc is not finite");
      kf.T_wc = geometry::SE3::from_matrix(M);
      if (!k.at("loop_edges").is_array() || !k.at("covisibility").is_array()) {
        throw fail(i, "loop_edges and covisibility must be arrays");
      }
      for (const auto& e : k.at("loop_edges")) kf.loop_edges.push_back(whole(e, "a loop edge"));
      for (const auto& e : k.at("covisibility")) {
        if (!e.is_array() || e.size() != 2) throw fail(i, "a covisibility entry is [keyframe id, weight]");
        const long weight = whole(e[1], "a covisibility weight");
        if (weight < 0 || weight > std::numeric_limits<int>::max()) throw fail(i, "a covisibility weight is out of range");
        kf.covisibility.emplace_back(whole(e[0], "a covisibility id"), static_cast<int>(weight));
      }
    } catch (const json::exception& e) {
      throw fail(i, e.what());
    }
    if (!ids.insert(kf.id).second) throw fail(i, fmt::format("id {} appears twice", kf.id));
    map.keyframes.push_back(std::move(kf));
  }
}

SceneGraph scene_graph(const map::MapSnapshot& map) {
  SceneGraph g{json::array(), json::array()};
  for (const auto& kf : map.keyframes) {
    // Each edge once, from its lower id.
    for (const long other : kf.loop_edges) {
      if (kf.id < other) g.loop_edges.push_back({kf.id, other});
    }
    for (const auto& [other, weight] : kf.covisibility) {
      if (kf.id < other) g.covisibility.push_back({kf.id, other, weight});
    }
  }
  return g;
}

json scene_counts(const map::MapSnapshot& map, const SceneInfo& info) {
  std::size_t loop_edges = 0;
  for (const auto& kf : map.keyframes) {
    loop_edges += static_cast<std::size_t>(std::count_if(kf.loop_edges.begin(), kf.loop_edges.end(),
                                                         [&](long other) { return kf.id < other; }));
  }
  return {{"frame", optional_json(info.frame)},
          {"frames", optional_json(info.frames)},
          {"tracked", optional_json(info.tracked)},
          {"keyframes", map.keyframes.size()},
          {"points", map.points.size()},
          {"lines", map.lines.size()},
          {"loops", optional_json(info.loops)},
          {"loop_edges", loop_edges},
          {"relocalizations", optional_json(info.relocalizations)},
          {"state", optional_json(info.state)},
          {"fps", optional_json(info.fps)}};
}

json scene_camera(const SceneInfo& info) { return info.camera ? page_pose(*info.camera) : json(nullptr); }

json scene_local_map(const SceneInfo& info) {
  if (!info.local_map) return nullptr;
  return {{"keyframes", info.local_map->first}, {"points", info.local_map->second}};
}

json scene_document(const map::MapSnapshot& map, const SceneInfo& info) {
  json ids = json::array(), poses = json::array(), parents = json::array();
  for (const auto& kf : map.keyframes) {
    ids.push_back(kf.id);
    for (auto& v : page_pose(kf.T_wc)) poses.push_back(std::move(v));
    parents.push_back(kf.parent);
  }
  auto graph = scene_graph(map);
  json point_ids = json::array(), point_xyz = json::array(), line_ids = json::array(), line_xyz = json::array();
  for (const auto& p : map.points) {
    point_ids.push_back(p.id);
    append_page_position(point_xyz, p.position);
  }
  for (const auto& l : map.lines) {
    line_ids.push_back(l.id);
    append_page_position(line_xyz, l.start);
    append_page_position(line_xyz, l.end);
  }
  json trajectory = json::array();
  for (const auto& c : info.trajectory) append_page_position(trajectory, c);
  json ground_truth = nullptr;
  if (!info.ground_truth.empty()) {
    json positions = json::array();
    for (const auto& g : info.ground_truth) append_page_position(positions, g);
    ground_truth = {{"positions", positions}, {"ate_rmse_m", optional_json(info.ate_rmse_m)}};
  }
  json camera_model = nullptr;
  if (const auto& c = info.camera_model) {
    camera_model = {{"width", c->width}, {"height", c->height}, {"fx", c->fx}, {"fy", c->fy}, {"cx", c->cx}, {"cy", c->cy}};
  }
  return {{"version", 1},
          {"source", info.source},
          {"name", info.name},
          {"final", info.final},
          {"revision", info.revision},
          {"counts", scene_counts(map, info)},
          {"keyframes", {{"ids", ids}, {"poses", poses}, {"parents", parents}}},
          {"loop_edges", std::move(graph.loop_edges)},
          {"covisibility", std::move(graph.covisibility)},
          {"trajectory", trajectory},
          {"camera", scene_camera(info)},
          {"ground_truth", ground_truth},
          {"points", {{"ids", point_ids}, {"xyz", point_xyz}}},
          {"lines", {{"ids", line_ids}, {"xyz", line_xyz}}},
          {"local_map", scene_local_map(info)},
          {"camera_model", camera_model}};
}

json parse_run_stats(const std::string& text, const std::string& source, SceneInfo& info) {
  json stats;
  try {
    stats = json::parse(text);
  } catch (const json::exception& e) {
    throw InputError(source, std::string("not JSON: ") + e.what());
  }
  if (!stats.is_object()) throw InputError(source, "not a JSON object");
  info.frames = optional_count(stats, "frames", source);
  info.tracked = optional_count(stats, "tracked_frames", source);
  if (info.frames && *info.frames > 0) info.frame = *info.frames - 1;
  if (stats.contains("loops") && stats["loops"].is_array()) info.loops = static_cast<long>(stats["loops"].size());
  if (stats.contains("relocalizations") && stats["relocalizations"].is_object()) {
    info.relocalizations = optional_count(stats["relocalizations"], "count", source);
  }
  const bool interrupted = stats.contains("interrupted_by") && !stats["interrupted_by"].is_null();
  const bool complete = stats.contains("complete") && stats["complete"] == true;
  info.state = interrupted ? "interrupted" : complete ? "finished" : "incomplete";
  if (stats.contains("input") && stats["input"].is_object() && stats["input"].contains("calibration")) {
    const auto& c = stats["input"]["calibration"];
    if (!c.is_object()) throw InputError(source, "input.calibration: not a JSON object");
    auto size = [&](const char* key) {
      const auto n = c.contains(key) ? whole_number(c[key]) : std::nullopt;
      if (!n || *n <= 0 || *n > 100000) {
        throw InputError(source, fmt::format("input.calibration.{}: not a whole number in 1..100000", key));
      }
      return static_cast<int>(*n);
    };
    auto number = [&](const char* key) {
      if (!c.contains(key) || !c[key].is_number() || !std::isfinite(c[key].get<double>())) {
        throw InputError(source, fmt::format("input.calibration.{}: not a finite number", key));
      }
      return c[key].get<double>();
    };
    StereoCalibration calib;
    calib.width = size("width");
    calib.height = size("height");
    calib.fx = number("fx");
    calib.fy = number("fy");
    calib.cx = number("cx");
    calib.cy = number("cy");
    calib.baseline = number("baseline");
    info.camera_model = calib;
  }
  return stats;
}

Scene scene_from_run_folder(const fs::path& folder) {
  std::error_code ec;
  if (!fs::is_directory(folder, ec)) throw InputError(folder.string(), "not a folder");
  Scene scene;
  auto& info = scene.info;
  info.source = "run";
  info.name = folder.string();
  const auto stats_path = folder / "stats.json";
  const json stats = parse_run_stats(read_text(stats_path), stats_path.string(), info);

  const auto trajectory = io::read_trajectory(folder / "trajectory.tum", io::TrajectoryFormat::kTum);
  for (const auto& p : trajectory) info.trajectory.push_back(p.T.translation());
  if (!trajectory.empty()) info.camera = geometry::SE3(trajectory.back().T);

  const auto graph_path = folder / "map_graph.json";
  if (fs::exists(graph_path, ec)) {
    parse_map_graph(read_text(graph_path), graph_path.string(), scene.map);
  } else {
    // Written before map_graph.json: the keyframes' poses, with ids in time order and no graph.
    const auto kfs = io::read_trajectory(folder / "keyframes.tum", io::TrajectoryFormat::kTum);
    for (std::size_t i = 0; i < kfs.size(); ++i) {
      map::KeyframeSnapshot k;
      k.id = static_cast<long>(i);
      k.timestamp = kfs[i].t;
      k.T_wc = geometry::SE3(kfs[i].T);
      scene.map.keyframes.push_back(std::move(k));
    }
  }
  const auto points = io::read_ply_points(folder / "map_points.ply");
  for (std::size_t i = 0; i < points.size(); ++i) scene.map.points.push_back({static_cast<long>(i), points[i]});
  const auto lines = io::read_ply_lines(folder / "map_lines.ply");
  for (std::size_t i = 0; i < lines.size(); ++i) {
    scene.map.lines.push_back({static_cast<long>(i), lines[i].first, lines[i].second});
  }
  add_ground_truth(stats, info, trajectory);
  return scene;
}

Scene scene_from_map_file(const fs::path& file) {
  const auto contents = system::load_map_file(file);
  Scene scene;
  auto& info = scene.info;
  info.source = "map";
  info.name = file.string();
  info.state = "map";
  info.camera_model = contents.meta.calib;
  for (const auto& kf : contents.keyframes) {
    map::KeyframeSnapshot k;
    k.id = kf.id;
    k.timestamp = kf.data ? kf.data->timestamp : 0.0;
    k.T_wc = kf.T_cw.inverse();
    k.parent = kf.parent;
    k.loop_edges = kf.loop_edges;
    k.covisibility = kf.covisibility;
    info.trajectory.push_back(k.T_wc.translation());
    scene.map.keyframes.push_back(std::move(k));
  }
  if (!scene.map.keyframes.empty()) info.camera = scene.map.keyframes.back().T_wc;
  for (const auto& p : contents.points) scene.map.points.push_back({p.id, p.a});
  for (const auto& l : contents.lines) scene.map.lines.push_back({l.id, l.a, l.b});
  return scene;
}

}  // namespace plslam::viz
