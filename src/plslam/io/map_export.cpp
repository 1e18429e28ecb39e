#include "plslam/io/map_export.h"


#include <fmt/format.h>

#include "plslam/io/atomic_file.h"

namespace plslam::io {
void write_ply_points(const std::filesystem::path& path, const std::vector<Eigen::Vector3d>& points) {
  write_file_atomically(path, [&](std::ostream& out) {
  out << "ply\nformat ascii 1.0\ncomment plslam map points\n"
      << "element vertex " << points.size() << "\nproperty float x\nproperty float y\nproperty float z\nend_header\n";
  for (const auto& p : points) out << fmt::format("{:.6f} {:.6f} {:.6f}\n", p.x(), p.y(), p.z());
  });
}

void write_ply_lines(const std::filesystem::path& path,
                     const std::vector<std::pair<Eigen::Vector3d, Eigen::Vector3d>>& segments) {
  write_file_atomically(path, [&](std::ostream& out) {
  out << "ply\nformat ascii 1.0\ncomment plslam map lines\n"
      << "element vertex " << 2 * segments.size()
      << "\nproperty float x\nproperty float y\nproperty float z\n"
      << "element edge " << segments.size() << "\nproperty int vertex1\nproperty int vertex2\nend_header\n";
  for (const auto& [a, b] : segments) {
    out << fmt::format("{:.6f} {:.6f} {:.6f}\n{:.6f} {:.6f} {:.6f}\n", a.x(), a.y(), a.z(), b.x(), b.y(), b.z());
  }
  for (std::size_t i = 0; i < segments.size(); ++i) out << 2 * i << " " << 2 * i + 1 << "\n";
  });
}

}  // namespace plslam::io
