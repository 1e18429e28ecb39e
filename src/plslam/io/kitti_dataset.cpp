// KITTI odometry: sequences/NN/{calib.txt, times.txt, image_0/, image_1/}, ground truth in
// ../../poses/NN.txt. Images are already rectified; P1's fourth entry is -fx * baseline.
#include <algorithm>
#include <cctype>
#include <fstream>
#include <map>
#include <sstream>

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include "plslam/core/error.h"
#include "plslam/io/dataset_impl.h"
#include "plslam/io/image_loading.h"
#include "plslam/io/text_table.h"
#include "plslam/io/trajectory_io.h"

namespace plslam::io::detail {
namespace {

namespace fs = std::filesystem;
using Projection = std::array<double, 12>;

// Reads labelled lines ("P0: ..."); a file of bare 12-number lines is read as P0, P1 in order.
std::map<std::string, Projection> read_calib(const fs::path& path) {
  std::ifstream in = open_text_file(path, "calibration file not found");
  std::map<std::string, Projection> result;
  std::string line;
  std::size_t line_no = 0, unlabelled = 0;
  while (std::getline(in, line)) {
    ++line_no;
    strip_cr(line);
    if (line.find_first_not_of(" \t") == std::string::npos) continue;
    std::string label;
    const auto colon = line.find(':');
    if (colon != std::string::npos) {
      label = line.substr(0, colon);
      label.erase(std::remove_if(label.begin(), label.end(), ::isspace), label.end());
      line = line.substr(colon + 1);
    } else {
      label = fmt::format("P{}", unlabelled++);
    }
    std::istringstream ss(line);
    std::vector<double> values;
    std::string field;
    while (ss >> field) values.push_back(parse_finite(field, path, line_no));
    if (label.size() == 2 && label[0] == 'P' && values.size() != 12) {
      throw InputError(path.string(), fmt::format("line {}: {} needs 12 numbers, found {}", line_no,
                                                  label, values.size()));
    }
    if (values.size() == 12) {
      Projection p;
      std::copy(values.begin(), values.end(), p.begin());
      result[label] = p;
    }
  }
  for (const char* needed : {"P0", "P1"}) {
    if (!result.count(needed)) throw InputError(path.string(), std::string("missing ") + needed);
  }
  return result;
}

StereoCalibration calibration_from(const std::map<std::string, Projection>& P, const fs::path& file) {
  const auto& p0 = P.at("P0");
  const auto& p1 = P.at("P1");
  StereoCalibration c;
  c.fx = p1[0];
  c.fy = p1[5];
  c.cx = p1[2];
  c.cy = p1[6];
  c.baseline = c.fx != 0 ? -p1[3] / c.fx : 0.0;
  validate_calibration(c, file);
  // A rectified pair shares its intrinsics; anything else means P0/P1 are not from one rig.
  const double tol = 1e-6 * c.fx;
  if (std::abs(p0[0] - p1[0]) > tol || std::abs(p0[5] - p1[5]) > tol || std::abs(p0[2] - p1[2]) > tol ||
      std::abs(p0[6] - p1[6]) > tol) {
    throw InputError(file.string(), "inconsistent calibration: P0 and P1 intrinsics differ "
                                    "(images must be rectified)");
  }
  return c;
}

bool is_image_name(const fs::path& p) {
  std::string ext = p.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
  return ext == ".png" || ext == ".jpg" || ext == ".jpeg" || ext == ".pgm" || ext == ".ppm" || ext == ".bmp" ||
         ext == ".tif" || ext == ".tiff";
}

// The image files of one camera (PNG as KITTI ships them, or JPEG, PGM, PPM, BMP, TIFF), by name.
std::vector<std::string> list_images(const fs::path& dir) {
  if (!fs::exists(dir)) throw InputError(dir.string(), "image folder not found");
  if (!fs::is_directory(dir)) throw InputError(dir.string(), "is a file, expected the image folder");
  std::vector<std::string> names;
  for (const auto& e : fs::directory_iterator(dir)) {
    if (!is_image_name(e.path())) continue;
    if (e.is_directory()) throw InputError(e.path().string(), "is a folder, expected an image file");
    if (e.is_regular_file()) names.push_back(e.path().filename().string());
  }
  std::sort(names.begin(), names.end());
  return names;
}

class KittiDataset final : public Dataset {
 public:
  KittiDataset(const fs::path& root, const DatasetOptions& options) {
    root_ = root;
    const auto calib_path = root / "calib.txt";
    calib_ = calibration_from(read_calib(calib_path), calib_path);

    auto left = list_images(root / "image_0");
    const auto right = list_images(root / "image_1");
    if (left.empty()) throw InputError((root / "image_0").string(), "empty image folder");
    if (right.empty()) throw InputError((root / "image_1").string(), "empty image folder");
    const std::size_t all_left = left.size();
    // Pair by file name; unpaired frames are dropped with a warning.
    std::vector<std::string> paired;
    std::set_intersection(left.begin(), left.end(), right.begin(), right.end(), std::back_inserter(paired));
    const std::size_t dropped = (left.size() - paired.size()) + (right.size() - paired.size());
    if (dropped > 0) spdlog::warn("{}: dropped {} unpaired images", root.string(), dropped);
    if (paired.empty()) throw InputError(root.string(), "no left/right image pairs with the same name");

    std::vector<double> times;
    const auto times_path = root / "times.txt";
    if (fs::exists(times_path)) {
      for (const auto& row : read_numeric_rows(times_path)) {
        if (row.values.size() != 1) {
          throw InputError(times_path.string(), fmt::format("line {}: expected one timestamp", row.line));
        }
        times.push_back(row.values[0]);
      }
      if (times.size() != all_left) {
        throw InputError(times_path.string(), fmt::format("{} timestamps for {} images in image_0",
                                                          times.size(), all_left));
      }
      check_increasing(times, times_path);
    } else {
      spdlog::warn("{}: times.txt not found, assuming 10 Hz", root.string());
      for (std::size_t i = 0; i < all_left; ++i) times.push_back(0.1 * static_cast<double>(i));
    }
    // Index of each paired frame in the original image_0 listing (for times and poses).
    std::vector<std::size_t> original_index;
    for (const auto& name : paired) {
      original_index.push_back(std::lower_bound(left.begin(), left.end(), name) - left.begin());
    }

    const auto [start, count] = select_range(paired.size(), options, root);
    for (std::size_t i = start; i < start + count; ++i) {
      names_.push_back(paired[i]);
      timestamps_.push_back(times[original_index[i]]);
    }

    load_ground_truth(times, original_index, start, count);

    // Resolution from the first pair; left/right must agree.
    const auto first = load(0);
    calib_.width = first.left.cols;
    calib_.height = first.left.rows;
  }

  DatasetFormat format() const override { return DatasetFormat::kKitti; }

  StereoFrame load(std::size_t i) const override {
    StereoFrame f;
    f.index = i;
    f.timestamp = timestamps_.at(i);
    f.left_path = root_ / "image_0" / names_[i];
    f.right_path = root_ / "image_1" / names_[i];
    f.left = load_grey_image(f.left_path);
    f.right = load_grey_image(f.right_path);
    f.problem = blank_image_problem(f.left, f.left_path);
    if (f.problem.empty()) f.problem = blank_image_problem(f.right, f.right_path);
    f.blank = !f.problem.empty();
    if (f.left.size() != f.right.size()) {
      throw InputError(f.right_path.string(), fmt::format("right image is {}x{} but left is {}x{}",
                                                          f.right.cols, f.right.rows, f.left.cols, f.left.rows));
    }
    if (calib_.width > 0 && (f.left.cols != calib_.width || f.left.rows != calib_.height)) {
      throw InputError(f.left_path.string(), fmt::format("image is {}x{} but the sequence is {}x{}",
                                                         f.left.cols, f.left.rows, calib_.width, calib_.height));
    }
    return f;
  }

 private:
  void load_ground_truth(const std::vector<double>& times, const std::vector<std::size_t>& original_index,
                         std::size_t start, std::size_t count) {
    // poses/NN.txt beside sequences/; a sequence folder reached through a symlink finds it beside
    // the folder the link points to.
    const auto beside = [](const fs::path& seq) {
      return seq.parent_path().parent_path() / "poses" / (seq.filename().string() + ".txt");
    };
    auto poses = beside(root_);
    std::error_code ec;
    if (!fs::exists(poses)) {
      const auto real = fs::canonical(root_, ec);
      if (ec || !fs::exists(beside(real))) return;
      poses = beside(real);
    }
    const auto all = read_trajectory(poses, TrajectoryFormat::kKitti);
    Trajectory gt;
    for (std::size_t i = start; i < start + count; ++i) {
      const std::size_t k = original_index[i];
      if (k >= all.size()) break;
      gt.push_back({times[k], all[k].T});
    }
    if (gt.size() < count) {
      spdlog::warn("{}: ground truth covers {} of {} selected frames", poses.string(), gt.size(), count);
    }
    if (!gt.empty()) {
      gt_ = std::move(gt);
      gt_path_ = poses;
    }
  }

  std::vector<std::string> names_;
};

}  // namespace

std::unique_ptr<Dataset> open_kitti(const fs::path& sequence_dir, const DatasetOptions& options) {
  // open_dataset has already dropped a trailing slash.
  return std::make_unique<KittiDataset>(fs::absolute(sequence_dir).lexically_normal(), options);
}

}  // namespace plslam::io::detail
