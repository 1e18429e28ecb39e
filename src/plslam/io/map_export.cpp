#include "plslam/io/map_export.h"

#include <fstream>

#include <fmt/format.h>

#include "plslam/core/error.h"

namespace plslam::io {
namespace {

std::ofstream open_for_writing(const std::filesystem::path& path) {
  if (path.has_parent_path()) std::filesystem::create_directories(path.parent_path());
  std::ofstream out(path);
  if (!out) throw InputError(path.string(), "cannot open for writing");
  return out;
}

}  // namespace

void write_ply_points(const std::filesystem::path& path, const std::vector<Eigen::Vector3d>& points) {
  auto out = open_for_writing(path);
  out << "ply\nformat ascii 1.0\ncomment plslam map points\n"
      << "element vertex " << points.size() << "\nproperty float x\nproperty float y\nproperty float z\nend_header\n";
  for (const auto& p : points) out << fmt::format("{:.6f} {:.6f} {:.6f}\n", p.x(), p.y(), p.z());
}

void write_ply_lines(const std::filesystem::path& path,
                     const std::vector<std::pair<Eigen::Vector3d, Eigen::Vector3d>>& segments) {
  auto out = open_for_writing(path);
  out << "ply\nformat ascii 1.0\ncomment plslam map lines\n"
      << "element vertex " << 2 * segments.size()
      << "\nproperty float x\nproperty float y\nproperty float z\n"
      << "element edge " << segments.size() << "\nproperty int vertex1\nproperty int vertex2\nend_header\n";
  for (const auto& [a, b] : segments) {
    out << fmt::format("{:.6f} {:.6f} {:.6f}\n{:.6f} {:.6f} {:.6f}\n", a.x(), a.y(), a.z(), b.x(), b.y(), b.z());
  }
  for (std::size_t i = 0; i < segments.size(); ++i) out << 2 * i << " " << 2 * i + 1 << "\n";
}

}  // namespace plslam::io
