#pragma once
// Map export as ASCII PLY: points as vertices, lines as vertex pairs joined by edges, readable by
// MeshLab, CloudCompare and Open3D. The readers take back what the writers write (the viewer
// shows a finished run's map from them).
#include <filesystem>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include <Eigen/Core>

namespace plslam::io {

void write_ply_points(const std::filesystem::path& path, const std::vector<Eigen::Vector3d>& points);
void write_ply_lines(const std::filesystem::path& path,
                     const std::vector<std::pair<Eigen::Vector3d, Eigen::Vector3d>>& segments);

// ASCII PLY with float x y z vertices, and for lines an edge element pairing vertices 2i and 2i+1.
// InputError naming the file (and line) for anything else: another format, a count that the text
// does not hold, a number that is not finite.
std::vector<Eigen::Vector3d> read_ply_points(const std::filesystem::path& path);
std::vector<std::pair<Eigen::Vector3d, Eigen::Vector3d>> read_ply_lines(const std::filesystem::path& path);

struct PlyVertices {
  std::vector<Eigen::Vector3d> vertices;
  std::vector<std::pair<long, long>> edges;
};
// The parser under both readers; `source` names the text in errors.
PlyVertices parse_ply(std::string_view text, const std::string& source);

}  // namespace plslam::io
