#include "plslam/io/dataset.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include <fmt/format.h>

#include "plslam/core/error.h"
#include "plslam/io/dataset_impl.h"

namespace plslam::io {

const char* to_string(DatasetFormat f) {
  switch (f) {
    case DatasetFormat::kAuto: return "auto";
    case DatasetFormat::kKitti: return "kitti";
    case DatasetFormat::kEuroc: return "euroc";
    case DatasetFormat::kVideo: return "video";
  }
  return "?";
}

DatasetFormat parse_dataset_format(const std::string& name) {
  if (name == "auto") return DatasetFormat::kAuto;
  if (name == "kitti") return DatasetFormat::kKitti;
  if (name == "euroc") return DatasetFormat::kEuroc;
  throw InputError("", "unknown dataset format '" + name + "' (expected auto, kitti or euroc)");
}

double Dataset::fps() const {
  if (timestamps_.size() < 2) return 0.0;
  std::vector<double> dt(timestamps_.size() - 1);
  for (std::size_t i = 1; i < timestamps_.size(); ++i) dt[i - 1] = timestamps_[i] - timestamps_[i - 1];
  std::nth_element(dt.begin(), dt.begin() + dt.size() / 2, dt.end());
  return 1.0 / dt[dt.size() / 2];
}

double Dataset::ground_truth_length() const {
  if (!gt_) return 0.0;
  double length = 0.0;
  for (std::size_t i = 1; i < gt_->size(); ++i) {
    length += ((*gt_)[i].T.translation() - (*gt_)[i - 1].T.translation()).norm();
  }
  return length;
}

namespace {

namespace fs = std::filesystem;

bool looks_like_kitti(const fs::path& p) {
  return fs::exists(p / "calib.txt") || fs::is_directory(p / "image_0");
}

// A KITTI odometry root (sequences/NN plus poses/, as `plslam synth --format kitti` writes it)
// holding exactly one sequence stands for that sequence; with several, the user must choose.
fs::path single_kitti_sequence(const fs::path& root) {
  std::vector<fs::path> found;
  std::error_code ec;
  for (const auto& e : fs::directory_iterator(root / "sequences", ec)) {
    if (e.is_directory() && looks_like_kitti(e.path())) found.push_back(e.path());
  }
  std::sort(found.begin(), found.end());
  if (found.empty()) {
    throw InputError((root / "sequences").string(), "no KITTI sequence (NN/ with calib.txt and image_0/) inside");
  }
  if (found.size() > 1) {
    throw InputError(root.string(), fmt::format("holds {} KITTI sequences; name one, e.g. {}", found.size(),
                                                found.front().string()));
  }
  return found.front();
}

}  // namespace

std::unique_ptr<Dataset> open_dataset(const fs::path& given, const DatasetOptions& options) {
  std::error_code ec;
  if (!options.imu_csv.empty() || !options.imu_calib.empty()) {
    throw InputError(given.string(), "--imu and --imu-calib are for video and camera input: an EuRoC folder's IMU "
                                     "is its mav0/imu0, and KITTI has none");
  }
  if (!fs::exists(given, ec)) throw InputError(given.string(), "no such folder");
  if (!fs::is_directory(given, ec)) throw InputError(given.string(), "not a folder");
  // "mav0/" and "sequences/06/" name the same folders as without the slash.
  fs::path path = given.lexically_normal();
  if (path.filename().empty() && path.has_parent_path()) path = path.parent_path();
  if (!looks_like_kitti(path) && !fs::is_directory(path / "mav0") && path.filename() != "mav0" &&
      fs::is_directory(path / "sequences") && options.format != DatasetFormat::kEuroc) {
    path = single_kitti_sequence(path);
  }
  fs::path mav0;
  if (path.filename() == "mav0") {
    mav0 = path;
  } else if (fs::is_directory(path / "mav0")) {
    mav0 = path / "mav0";
  }
  DatasetFormat format = options.format;
  if (format == DatasetFormat::kAuto) {
    if (!mav0.empty()) {
      format = DatasetFormat::kEuroc;
    } else if (looks_like_kitti(path)) {
      format = DatasetFormat::kKitti;
    } else {
      throw InputError(path.string(), "unknown dataset layout (expected a KITTI sequences/NN folder "
                                      "with calib.txt and image_0/image_1, or an EuRoC folder with mav0/)");
    }
  }
  if (format == DatasetFormat::kEuroc) {
    return detail::open_euroc(mav0.empty() ? path : mav0, options);
  }
  if (!options.calibration.empty()) {
    throw InputError(options.calibration.string(), "--calib is for EuRoC folders, videos and cameras: a KITTI "
                                                   "sequence comes rectified, with its calibration in calib.txt");
  }
  return detail::open_kitti(path, options);
}

namespace detail {

std::pair<std::size_t, std::size_t> select_range(std::size_t total, const DatasetOptions& options,
                                                 const fs::path& root) {
  if (options.start >= total) {
    throw InputError(root.string(), fmt::format("--start {} is past the last frame ({} frames)",
                                                options.start, total));
  }
  std::size_t n = total - options.start;
  if (options.max_frames) n = std::min(n, *options.max_frames);
  if (n == 0) throw InputError(root.string(), "no frames selected (--max-frames 0)");
  return {options.start, n};
}

void check_increasing(const std::vector<double>& t, const fs::path& file) {
  for (std::size_t i = 1; i < t.size(); ++i) {
    if (!(t[i] > t[i - 1])) {
      throw InputError(file.string(), fmt::format("timestamps not increasing at entry {} ({} after {})",
                                                  i + 1, t[i], t[i - 1]));
    }
  }
}

}  // namespace detail

void validate_calibration(const StereoCalibration& c, const fs::path& file) {
  const double v[] = {c.fx, c.fy, c.cx, c.cy, c.baseline};
  for (double x : v) {
    if (!std::isfinite(x)) throw InputError(file.string(), "non-finite value in the calibration");
  }
  if (c.fx <= 0 || c.fy <= 0) throw InputError(file.string(), "focal length must be positive");
  if (!(c.baseline > 0)) {
    // + 0.0 turns -0 (from -(0 / fx)) into 0, which is what the user wrote.
    throw InputError(file.string(), fmt::format("baseline must be positive, got {} m", c.baseline + 0.0));
  }
}

}  // namespace plslam::io
