#pragma once
// The document the browser viewer draws (GET /api/scene, read by web/viewer.js): the map's
// keyframes, points, lines and graph, the trajectory, the ground truth aligned into the map's
// world, and the counts of the side panel. One builder per source: a finished run's folder, a map
// file, and (live) a snapshot of the running system.
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <nlohmann/json.hpp>

#include "plslam/core/types.h"
#include "plslam/geometry/se3.h"
#include "plslam/map/map_snapshot.h"

namespace plslam::viz {

// Everything of the document besides the map itself.
struct SceneInfo {
  std::string source;  // "run", "map" or "live"
  std::string name;    // the run folder, map file or dataset
  bool final = true;   // false while a live run goes on
  long revision = 1;   // grows with every change of the document (live)
  std::optional<long> frame, frames, tracked, relocalizations;
  std::optional<long> loops;  // loops closed (a map file records edges, not closures)
  std::optional<std::string> state;  // tracking state, "finished", "interrupted", ...
  std::optional<double> fps;
  std::vector<Eigen::Vector3d> trajectory;      // estimated camera centres, in order
  std::optional<geometry::SE3> camera;          // T_wc of the current (last) frame
  std::vector<Eigen::Vector3d> ground_truth;    // in the map's world; empty without one
  std::optional<double> ate_rmse_m;
  std::optional<StereoCalibration> camera_model;
  std::optional<std::pair<std::vector<long>, std::vector<long>>> local_map;  // keyframe, point ids
};

nlohmann::json scene_document(const map::MapSnapshot& map, const SceneInfo& info);

// Numbers as the page gets them: positions to a tenth of a millimetre and rotation entries to
// 1e-6, far below what it can show. Each prints in 5-8 characters, where a float widened to double
// prints in up to 20, so documents and deltas are less than half the size on the wire.
void append_page_position(nlohmann::json& flat, const Eigen::Vector3d& p);
nlohmann::json page_pose(const geometry::SE3& T_wc);  // row-major 3x4

// Parts of that document, for the live viewer's deltas, which must not pay for the whole.
struct SceneGraph {
  nlohmann::json loop_edges;    // [[a, b], ...], each edge once
  nlohmann::json covisibility;  // [[a, b, weight], ...]
};
SceneGraph scene_graph(const map::MapSnapshot& map);
nlohmann::json scene_counts(const map::MapSnapshot& map, const SceneInfo& info);
nlohmann::json scene_camera(const SceneInfo& info);     // T_wc row-major 3x4, or null
nlohmann::json scene_local_map(const SceneInfo& info);  // {keyframes, points}, or null

struct Scene {
  map::MapSnapshot map;
  SceneInfo info;
};

// A folder `plslam run --out` wrote: stats.json and trajectory.tum (required), map_graph.json
// (keyframes and their graph; keyframes.tum alone in folders written before it), map_points.ply,
// map_lines.ply, and the ground truth of the dataset stats.json names, when it is still there.
// InputError naming the file for a missing or malformed one.
Scene scene_from_run_folder(const std::filesystem::path& folder);

// A map file (`plslam run --save-map`): keyframes, graph, points and lines; the keyframe centres
// stand for the trajectory. InputError for a bad file.
Scene scene_from_map_file(const std::filesystem::path& file);

// The panel's counts, state and camera model from the text of a run's stats.json (`source` names
// it in errors); returns the parsed document. InputError for anything malformed.
nlohmann::json parse_run_stats(const std::string& text, const std::string& source, SceneInfo& info);

// map_graph.json, as `plslam run` writes it and scene_from_run_folder reads it: every keyframe
// with its time, pose (T_wc), spanning-tree parent, loop edges and covisibility weights.
nlohmann::json map_graph_json(const map::MapSnapshot& map);
// Reads the keyframes back into `map`; InputError naming `source` for anything malformed.
void parse_map_graph(const std::string& text, const std::string& source, map::MapSnapshot& map);

}  // namespace plslam::viz
