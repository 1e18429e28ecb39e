#include "plslam/io/trajectory_io.h"

#include <cmath>
#include <fstream>

#include <fmt/format.h>

#include "plslam/core/error.h"
#include "plslam/io/atomic_file.h"
#include "plslam/io/text_table.h"

namespace plslam::io {
namespace {

std::string where(std::size_t line) { return "line " + std::to_string(line) + ": "; }

void check_columns(const NumericRow& row, std::size_t expected, bool at_least,
                   const std::filesystem::path& path, const char* format) {
  const std::size_t n = row.values.size();
  if (n == expected || (at_least && n > expected)) return;
  throw InputError(path.string(), fmt::format("{}expected {}{} columns for {} format, found {}",
                                              where(row.line), at_least ? "at least " : "",
                                              expected, format, n));
}

Eigen::Quaterniond checked_quaternion(double w, double x, double y, double z,
                                      const std::filesystem::path& path, std::size_t line) {
  Eigen::Quaterniond q(w, x, y, z);
  const double n = q.norm();
  // Files are written with a handful of digits; a quaternion far from unit norm is garbage.
  if (std::abs(n - 1.0) > 1e-2) {
    throw InputError(path.string(), where(line) + fmt::format("quaternion norm {:.4f} is not 1", n));
  }
  q.normalize();
  return q;
}

Eigen::Isometry3d make_pose(const Eigen::Quaterniond& q, const Eigen::Vector3d& p) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = q.toRotationMatrix();
  T.translation() = p;
  return T;
}

// Projects a near-rotation onto SO(3) so that KITTI's 6-9 digit matrices give valid poses.
Eigen::Matrix3d nearest_rotation(const Eigen::Matrix3d& M) {
  Eigen::JacobiSVD<Eigen::Matrix3d> svd(M, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d R = svd.matrixU() * svd.matrixV().transpose();
  if (R.determinant() < 0) {
    Eigen::Matrix3d U = svd.matrixU();
    U.col(2) *= -1;
    R = U * svd.matrixV().transpose();
  }
  return R;
}

void check_increasing(const Trajectory& traj, const std::vector<NumericRow>& rows,
                      const std::filesystem::path& path) {
  for (std::size_t i = 1; i < traj.size(); ++i) {
    // Repeated stamps are tolerated, as evo does: real files have them (evo's own V102.txt).
    if (!(traj[i].t >= traj[i - 1].t)) {
      throw InputError(path.string(), where(rows[i].line) +
                                          fmt::format("timestamp {} is not after {}", traj[i].t, traj[i - 1].t));
    }
  }
}

}  // namespace

const char* to_string(TrajectoryFormat f) {
  switch (f) {
    case TrajectoryFormat::kTum: return "tum";
    case TrajectoryFormat::kKitti: return "kitti";
    case TrajectoryFormat::kEuroc: return "euroc";
  }
  return "?";
}

TrajectoryFormat parse_trajectory_format(const std::string& name) {
  if (name == "tum") return TrajectoryFormat::kTum;
  if (name == "kitti") return TrajectoryFormat::kKitti;
  if (name == "euroc") return TrajectoryFormat::kEuroc;
  throw InputError("", "unknown trajectory format '" + name + "' (expected tum, kitti or euroc)");
}

TrajectoryFormat detect_trajectory_format(const std::filesystem::path& path) {
  const auto ext = path.extension().string();
  if (ext == ".csv") return TrajectoryFormat::kEuroc;
  if (ext == ".kitti") return TrajectoryFormat::kKitti;
  if (ext == ".tum") return TrajectoryFormat::kTum;
  std::ifstream in = open_text_file(path);
  std::string line;
  while (std::getline(in, line)) {
    strip_cr(line);
    const auto first = line.find_first_not_of(" \t\r");
    if (first == std::string::npos || line[first] == '#') continue;
    if (line.find(',') != std::string::npos) return TrajectoryFormat::kEuroc;
    std::size_t cols = 0;
    bool in_field = false;
    for (char c : line) {
      const bool space = c == ' ' || c == '\t' || c == '\r';
      if (!space && !in_field) ++cols;
      in_field = !space;
    }
    if (cols == 8) return TrajectoryFormat::kTum;
    if (cols == 12) return TrajectoryFormat::kKitti;
    throw InputError(path.string(), fmt::format("cannot tell the trajectory format: {} columns "
                                                "(expected 8 for TUM or 12 for KITTI)", cols));
  }
  throw InputError(path.string(), "empty trajectory file");
}

Trajectory read_trajectory(const std::filesystem::path& path, TrajectoryFormat format,
                           const std::vector<double>* kitti_times, KittiRotation kitti_rotation) {
  const auto rows = read_numeric_rows(path);
  if (rows.empty()) throw InputError(path.string(), "empty trajectory file");
  Trajectory traj;
  traj.reserve(rows.size());
  switch (format) {
    case TrajectoryFormat::kTum:
      for (const auto& r : rows) {
        check_columns(r, 8, false, path, "TUM");
        const auto& v = r.values;
        traj.push_back({v[0], make_pose(checked_quaternion(v[7], v[4], v[5], v[6], path, r.line),
                                        {v[1], v[2], v[3]})});
      }
      break;
    case TrajectoryFormat::kEuroc:
      for (const auto& r : rows) {
        check_columns(r, 8, true, path, "EuRoC");
        const auto& v = r.values;
        traj.push_back({v[0] * 1e-9, make_pose(checked_quaternion(v[4], v[5], v[6], v[7], path, r.line),
                                               {v[1], v[2], v[3]})});
      }
      break;
    case TrajectoryFormat::kKitti:
      if (kitti_times && kitti_times->size() != rows.size()) {
        throw InputError(path.string(), fmt::format("{} poses but {} timestamps", rows.size(),
                                                    kitti_times->size()));
      }
      for (std::size_t i = 0; i < rows.size(); ++i) {
        const auto& r = rows[i];
        check_columns(r, 12, false, path, "KITTI");
        Eigen::Matrix3d M;
        Eigen::Vector3d p;
        for (int a = 0; a < 3; ++a) {
          for (int b = 0; b < 3; ++b) M(a, b) = r.values[a * 4 + b];
          p(a) = r.values[a * 4 + 3];
        }
        if (std::abs(M.determinant() - 1.0) > 1e-2) {
          throw InputError(path.string(), where(r.line) + "rotation part is not a rotation");
        }
        Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
        T.linear() = kitti_rotation == KittiRotation::kAsWritten ? M : nearest_rotation(M);
        T.translation() = p;
        traj.push_back({kitti_times ? (*kitti_times)[i] : static_cast<double>(i), T});
      }
      break;
  }
  check_increasing(traj, rows, path);
  return traj;
}

void write_trajectory(const std::filesystem::path& path, const Trajectory& trajectory,
                      TrajectoryFormat format) {
  write_file_atomically(path, [&](std::ostream& out) {
  if (format == TrajectoryFormat::kEuroc) {
    out << "#timestamp [ns], p_RS_R_x [m], p_RS_R_y [m], p_RS_R_z [m], q_RS_w [], q_RS_x [], "
           "q_RS_y [], q_RS_z []\n";
  } else if (format == TrajectoryFormat::kTum) {
    out << "# timestamp tx ty tz qx qy qz qw\n";
  }
  for (const auto& sp : trajectory) {
    const Eigen::Vector3d p = sp.T.translation();
    const Eigen::Quaterniond q(sp.T.rotation());
    switch (format) {
      case TrajectoryFormat::kTum:
        out << fmt::format("{:.9f} {:.17g} {:.17g} {:.17g} {:.17g} {:.17g} {:.17g} {:.17g}\n", sp.t,
                           p.x(), p.y(), p.z(), q.x(), q.y(), q.z(), q.w());
        break;
      case TrajectoryFormat::kEuroc:
        out << fmt::format("{},{:.17g},{:.17g},{:.17g},{:.17g},{:.17g},{:.17g},{:.17g}\n",
                           std::llround(sp.t * 1e9), p.x(), p.y(), p.z(), q.w(), q.x(), q.y(), q.z());
        break;
      case TrajectoryFormat::kKitti: {
        const Eigen::Matrix3d R = sp.T.rotation();
        out << fmt::format("{:.17g} {:.17g} {:.17g} {:.17g} {:.17g} {:.17g} {:.17g} {:.17g} {:.17g} "
                           "{:.17g} {:.17g} {:.17g}\n",
                           R(0, 0), R(0, 1), R(0, 2), p.x(), R(1, 0), R(1, 1), R(1, 2), p.y(),
                           R(2, 0), R(2, 1), R(2, 2), p.z());
        break;
      }
    }
  }
  });
}

}  // namespace plslam::io
