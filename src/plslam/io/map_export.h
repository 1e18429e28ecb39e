#pragma once
// Map export as ASCII PLY: points as vertices, lines as vertex pairs joined by edges, readable by
// MeshLab, CloudCompare and Open3D.
#include <filesystem>
#include <utility>
#include <vector>

#include <Eigen/Core>

namespace plslam::io {

void write_ply_points(const std::filesystem::path& path, const std::vector<Eigen::Vector3d>& points);
void write_ply_lines(const std::filesystem::path& path,
                     const std::vector<std::pair<Eigen::Vector3d, Eigen::Vector3d>>& segments);

}  // namespace plslam::io
