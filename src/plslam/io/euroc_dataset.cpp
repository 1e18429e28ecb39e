// EuRoC / ASL: mav0/cam{0,1}/{data.csv, data/, sensor.yaml}, ground truth in
// mav0/state_groundtruth_estimate0/data.csv (body frame). The raw images are distorted and not
// rectified: rectification is computed once from the two sensor.yaml files and every frame is
// remapped, so the rest of the system sees an ideal rectified pinhole pair.
#include <charconv>
#include <cmath>
#include <fstream>

#include <fmt/format.h>
#include <Eigen/Core>
#include <opencv2/imgproc.hpp>
#include <spdlog/spdlog.h>

#include "plslam/core/error.h"
#include "plslam/io/dataset_impl.h"
#include "plslam/io/calibration_file.h"
#include "plslam/io/euroc_sensor.h"
#include "plslam/io/image_loading.h"
#include "plslam/io/imu_input.h"
#include "plslam/io/text_table.h"
#include "plslam/io/trajectory_io.h"

namespace plslam::io::detail {

namespace fs = std::filesystem;

std::vector<ImageEntry> read_image_list(const fs::path& csv) {
  std::ifstream in = open_text_file(csv);
  std::vector<ImageEntry> entries;
  std::string line;
  std::size_t line_no = 0;
  while (std::getline(in, line)) {
    ++line_no;
    strip_cr(line);
    if (line.empty() || line[0] == '#') continue;
    const auto comma = line.find(',');
    if (comma == std::string::npos) {
      throw InputError(csv.string(), fmt::format("line {}: expected 'timestamp,filename'", line_no));
    }
    ImageEntry e;
    const auto [ptr, ec] = std::from_chars(line.data(), line.data() + comma, e.ns);
    if (ec != std::errc() || ptr != line.data() + comma) {
      throw InputError(csv.string(), fmt::format("line {}: bad timestamp '{}'", line_no, line.substr(0, comma)));
    }
    e.file = line.substr(comma + 1);
    e.file.erase(0, e.file.find_first_not_of(' '));
    if (!entries.empty() && e.ns <= entries.back().ns) {
      throw InputError(csv.string(), fmt::format("line {}: timestamps not increasing ({} after {})", line_no,
                                                 e.ns, entries.back().ns));
    }
    entries.push_back(std::move(e));
  }
  if (entries.empty()) throw InputError(csv.string(), "no images listed");
  return entries;
}

namespace {

class EurocDataset final : public Dataset {
 public:
  EurocDataset(const fs::path& mav0, const DatasetOptions& options) {
    root_ = mav0;
    const auto yaml0 = mav0 / "cam0" / "sensor.yaml";
    const auto yaml1 = mav0 / "cam1" / "sensor.yaml";
    cam0_ = read_euroc_camera_yaml(yaml0);
    if (!options.calibration.empty()) {
      use_calibration_file(options.calibration, options.rectify_balance);
    } else {
      const auto cam1 = read_euroc_camera_yaml(yaml1);
      if (cam0_.width != cam1.width || cam0_.height != cam1.height) {
        throw InputError(yaml1.string(), fmt::format("resolution {}x{} differs from cam0's {}x{}", cam1.width,
                                                     cam1.height, cam0_.width, cam0_.height));
      }
      // p_c1 = T_BS1^-1 * T_BS0 * p_c0: the pose of cam0 in cam1's frame, as stereoRectify wants.
      compute_rectification({cam0_.lens(), cam1.lens(), cam1.T_BS.inverse() * cam0_.T_BS}, yaml1,
                            options.rectify_balance);
    }

    const auto left = read_image_list(mav0 / "cam0" / "data.csv");
    const auto right = read_image_list(mav0 / "cam1" / "data.csv");
    pair_images(left, right);
    if (!fs::is_directory(mav0 / "cam0" / "data")) {
      throw InputError((mav0 / "cam0" / "data").string(), "image folder not found");
    }

    const auto [start, count] = select_range(pairs_.size(), options, root_);
    pairs_ = std::vector<Pair>(pairs_.begin() + static_cast<std::ptrdiff_t>(start),
                               pairs_.begin() + static_cast<std::ptrdiff_t>(start + count));
    for (const auto& p : pairs_) timestamps_.push_back(static_cast<double>(p.ns) * 1e-9);

    load_ground_truth();
    load_imu();
    // Fail early on a corrupt first pair or a size that contradicts sensor.yaml.
    (void)load(0);
  }

  DatasetFormat format() const override { return DatasetFormat::kEuroc; }

  StereoFrame load(std::size_t i) const override {
    const auto& p = pairs_.at(i);
    StereoFrame f;
    f.index = i;
    f.timestamp = timestamps_[i];
    f.left_path = root_ / "cam0" / "data" / p.left;
    f.right_path = root_ / "cam1" / "data" / p.right;
    const cv::Mat raw_left = load_grey_image(f.left_path);
    const cv::Mat raw_right = load_grey_image(f.right_path);
    f.problem = blank_image_problem(raw_left, f.left_path);
    if (f.problem.empty()) f.problem = blank_image_problem(raw_right, f.right_path);
    f.blank = !f.problem.empty();
    for (const auto& [img, path] : {std::pair{&raw_left, &f.left_path}, std::pair{&raw_right, &f.right_path}}) {
      if (img->cols != cam0_.width || img->rows != cam0_.height) {
        throw InputError(path->string(), fmt::format("image is {}x{} but {} says {}x{}", img->cols, img->rows,
                                                     size_source_, cam0_.width, cam0_.height));
      }
    }
    cv::remap(raw_left, f.left, map_left_[0], map_left_[1], cv::INTER_LINEAR);
    cv::remap(raw_right, f.right, map_right_[0], map_right_[1], cv::INTER_LINEAR);
    return f;
  }

 private:
  struct Pair {
    std::int64_t ns;
    std::string left, right;
  };

  void compute_rectification(const geometry::RawStereoRig& rig, const fs::path& source, double balance) {
    RawRig raw;
    raw.rig = rig;
    const auto rect = geometry::rectify_stereo(raw.rig, balance, source.string());
    calib_ = rect.calibration;
    validate_calibration(calib_, source);
    R_rect_sensor_ = rect.R_rect_left;
    map_left_ = rect.map_left;
    map_right_ = rect.map_right;
    raw.balance = balance;
    raw.coverage = rect.coverage;
    raw_rig_ = raw;
  }

  // The user's raw calibration in place of the two sensor.yaml: cam0's T_BS stays (it ties the
  // ground truth and the IMU to the camera), the cameras and the pose between them are the file's.
  void use_calibration_file(const fs::path& file, double balance) {
    const UserCalibration user = read_user_calibration(file);
    if (!user.raw) {
      throw InputError(file.string(), "holds a rectified calibration, but EuRoC images are raw: --calib for a "
                                      "dataset folder needs the raw cameras (cam0, cam1), as plslam calibrate "
                                      "writes them");
    }
    cam0_.width = user.raw->left.width;
    cam0_.height = user.raw->left.height;
    cam0_.fu = user.raw->left.fx;
    cam0_.fv = user.raw->left.fy;
    cam0_.cu = user.raw->left.cx;
    cam0_.cv = user.raw->left.cy;
    cam0_.distortion_model = user.raw->left.model;
    cam0_.distortion = user.raw->left.coeffs;
    size_source_ = file.string();
    compute_rectification(*user.raw, file, balance);
  }

  void pair_images(const std::vector<ImageEntry>& left, const std::vector<ImageEntry>& right) {
    // The two cameras are hardware-triggered: equal stamps, with 1 ms of slack for clock jitter.
    constexpr std::int64_t kToleranceNs = 1'000'000;
    std::size_t j = 0;
    for (const auto& l : left) {
      while (j < right.size() && right[j].ns < l.ns - kToleranceNs) ++j;
      if (j < right.size() && std::llabs(right[j].ns - l.ns) <= kToleranceNs) {
        pairs_.push_back({l.ns, l.file, right[j].file});
        ++j;
      }
    }
    const std::size_t dropped = left.size() + right.size() - 2 * pairs_.size();
    if (dropped > 0) spdlog::warn("{}: dropped {} unpaired images", root_.string(), dropped);
    if (pairs_.empty()) throw InputError(root_.string(), "no left/right images with matching timestamps");
  }

  // EuRoC's state_groundtruth_estimate0, else TUM-VI's mocap0 (the same first 8 columns: the IMU's
  // pose), which covers only part of the sequences outside the rooms.
  void load_ground_truth() {
    auto path = root_ / "state_groundtruth_estimate0" / "data.csv";
    if (!fs::exists(path)) path = root_ / "mocap0" / "data.csv";
    if (!fs::exists(path)) return;
    const auto left = body_to_sensor(read_trajectory(path, TrajectoryFormat::kEuroc), cam0_.T_BS);
    // Keep the samples that overlap the selected frames (half a frame of slack at both ends).
    const double slack = 0.5 / std::max(fps(), 1.0);
    Trajectory gt;
    std::copy_if(left.begin(), left.end(), std::back_inserter(gt), [&](const StampedPose& sp) {
      return sp.t >= timestamps_.front() - slack && sp.t <= timestamps_.back() + slack;
    });
    if (gt.empty()) {
      spdlog::warn("{}: no ground truth overlaps the selected frames", path.string());
      return;
    }
    gt_ = std::move(gt);
    gt_path_ = path;
  }

  // mav0/imu0 when it is there: a sequence without it has no IMU, one with a broken file is refused.
  void load_imu() {
    const auto dir = root_ / "imu0";
    std::error_code ec;
    if (!fs::exists(dir, ec)) return;
    if (!fs::is_directory(dir, ec)) throw InputError(dir.string(), "is a file, expected the IMU's folder");
    // The rectified left camera in the body frame: cam0's T_BS after undoing the rectification's
    // rotation (p_raw = R_rect_sensor^T * p_rect).
    Eigen::Isometry3d T_sensor_rect = Eigen::Isometry3d::Identity();
    T_sensor_rect.linear() = R_rect_sensor_.transpose();
    imu_path_ = dir / "data.csv";
    imu_ = read_imu(imu_path_, dir / "sensor.yaml", cam0_.T_BS * T_sensor_rect);
    keep_imu_span(*imu_, timestamps_.front(), timestamps_.back(), imu_path_);
  }

  EurocCameraSensor cam0_;
  std::string size_source_ = "sensor.yaml";  // where the image size comes from, for errors
  std::array<cv::Mat, 2> map_left_, map_right_;
  std::vector<Pair> pairs_;
};

}  // namespace

std::unique_ptr<Dataset> open_euroc(const fs::path& mav0_dir, const DatasetOptions& options) {
  return std::make_unique<EurocDataset>(fs::absolute(mav0_dir).lexically_normal(), options);
}

}  // namespace plslam::io::detail
