// A side-by-side stereo video as a Dataset.
//
// A video is decoded in order: frame i comes after frames 0..i-1, and FrameStream asks for the
// frames in that order, so each is decoded once. Seeking (CAP_PROP_POS_FRAMES) is exact only for
// some codecs and containers, so a request for an earlier frame reopens the file and decodes
// forward: slow but exact, and only the check of the first frame at opening does it.
//
// size() is the container's frame count (CAP_PROP_FRAME_COUNT: a header field, or the duration
// times the rate), which a truncated file overstates. Decoding is the truth: a video that ends
// early throws InputEnded at its first missing frame and FrameStream ends the sequence there;
// frames beyond the count are reported and left out. A container without a count has its frames
// counted by decoding it once at opening.
#include "plslam/io/video_dataset.h"

#include <array>
#include <cmath>
#include <cstdlib>
#include <mutex>

#include <fmt/format.h>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>
#include <spdlog/spdlog.h>

#include "plslam/core/error.h"
#include "plslam/io/calibration_file.h"
#include "plslam/io/dataset_impl.h"
#include "plslam/io/image_loading.h"
#include "plslam/io/imu_input.h"
#include "plslam/io/trajectory_io.h"

namespace plslam::io {

namespace fs = std::filesystem;

void quiet_ffmpeg_log() {
  // OpenCV reads this before each open (AV_LOG_QUIET); a value the user set is kept.
  ::setenv("OPENCV_FFMPEG_LOGLEVEL", "-8", 0);
}

fs::path video_ground_truth_path(const fs::path& video) { return video.parent_path() / "ground_truth.tum"; }

cv::Mat to_grey(const cv::Mat& frame) {
  cv::Mat grey;
  if (frame.channels() == 3) {
    cv::cvtColor(frame, grey, cv::COLOR_BGR2GRAY);
  } else if (frame.channels() == 4) {
    cv::cvtColor(frame, grey, cv::COLOR_BGRA2GRAY);
  } else {
    grey = frame.clone();  // a capture reuses its buffer for the next frame
  }
  if (grey.depth() != CV_8U) grey.convertTo(grey, CV_8U, grey.depth() == CV_16U ? 1.0 / 256 : 1.0);
  return grey;
}

void split_side_by_side(const cv::Mat& frame, int width, int height, const std::string& source, cv::Mat& left,
                        cv::Mat& right) {
  if (frame.cols != 2 * width || frame.rows != height) {
    throw InputError(source, fmt::format("frames are {}x{}, but the calibration's {}x{} images side by side make "
                                         "{}x{}",
                                         frame.cols, frame.rows, width, height, 2 * width, height));
  }
  const cv::Mat grey = to_grey(frame);
  left = grey(cv::Rect(0, 0, width, height)).clone();
  right = grey(cv::Rect(width, 0, width, height)).clone();
}

namespace {

class VideoDataset final : public Dataset {
 public:
  VideoDataset(const fs::path& video, const fs::path& calibration, const DatasetOptions& options) {
    root_ = video;
    use_calibration(calibration, options.rectify_balance);
    std::error_code ec;
    if (!fs::exists(video, ec)) throw InputError(video.string(), "no such file");
    if (fs::is_directory(video, ec)) throw InputError(video.string(), "is a folder, expected a video file");
    quiet_ffmpeg_log();
    reopen();
    const int w = static_cast<int>(capture_.get(cv::CAP_PROP_FRAME_WIDTH));
    const int h = static_cast<int>(capture_.get(cv::CAP_PROP_FRAME_HEIGHT));
    if (w > 0 && h > 0 && (w != 2 * calib_.width || h != calib_.height)) {
      throw InputError(video.string(), fmt::format("frames are {}x{}, but the {}x{} images of {} side by side make "
                                                   "{}x{}",
                                                   w, h, calib_.width, calib_.height, calibration.string(),
                                                   2 * calib_.width, calib_.height));
    }
    double fps = capture_.get(cv::CAP_PROP_FPS);
    if (!(std::isfinite(fps) && fps > 0 && fps <= 1000)) {
      spdlog::warn("{}: no frame rate in the file, assuming 30 Hz", video.string());
      fps = 30.0;
    }
    fps_ = fps;
    const double count = capture_.get(cv::CAP_PROP_FRAME_COUNT);
    total_ = std::isfinite(count) && count >= 1 && count < 1e9 ? static_cast<std::size_t>(count) : count_frames();
    if (total_ == 0) throw InputError(video.string(), "no frames");

    const auto [start, n] = detail::select_range(total_, options, root_);
    start_ = start;
    for (std::size_t i = 0; i < n; ++i) timestamps_.push_back(static_cast<double>(start + i) / fps_);
    load_ground_truth();
    load_imu(options);
    try {
      (void)load(0);  // fail early on a file that decodes nothing, or frames of another size
    } catch (const InputEnded& e) {
      throw InputError(e.file(), e.problem());
    }
  }

  DatasetFormat format() const override { return DatasetFormat::kVideo; }

  StereoFrame load(std::size_t i) const override {
    if (i >= size()) throw std::out_of_range(fmt::format("video frame {} of {}", i, size()));
    const std::size_t want = start_ + i;
    std::lock_guard lock(mutex_);
    if (want < next_) reopen();
    cv::Mat frame;
    while (next_ <= want) {
      const bool ok = next_ < want ? capture_.grab() : capture_.read(frame);
      if (!ok || (next_ == want && frame.empty())) {
        throw InputEnded(root_.string(),
                         next_ == 0 ? fmt::format("no frame decodes, though the file counts {} (truncated?)", total_)
                                    : fmt::format("ends after {} frames, though it counts {}", next_, total_));
      }
      ++next_;
    }
    check_frame_time(want);
    StereoFrame f;
    f.index = i;
    f.timestamp = timestamps_[i];
    f.left_path = f.right_path = root_;
    split_side_by_side(frame, calib_.width, calib_.height, root_.string(), f.left, f.right);
    if (raw_rig_) {  // a raw calibration: rectify here, as the EuRoC reader does
      cv::Mat left, right;
      cv::remap(f.left, left, map_left_[0], map_left_[1], cv::INTER_LINEAR);
      cv::remap(f.right, right, map_right_[0], map_right_[1], cv::INTER_LINEAR);
      f.left = left;
      f.right = right;
    }
    f.problem = blank_image_problem(f.left, root_);
    if (f.problem.empty()) f.problem = blank_image_problem(f.right, root_);
    if (next_ == total_ && capture_.grab()) {
      ++next_;
      spdlog::warn("{}: holds more frames than the {} it counts; they are left out", root_.string(), total_);
    }
    return f;
  }

 private:
  // The rectified form is used as it is; a raw (camchain) one is rectified with `balance`. Either
  // way calib_ ends up the rectified pair, whose width and height are one raw image's.
  void use_calibration(const fs::path& file, double balance) {
    const UserCalibration user = read_user_calibration(file);
    const InputRectification in = rectify_user_calibration(user, balance, file);
    calib_ = in.calibration;
    if (!in.rectification) return;
    validate_calibration(calib_, file);
    R_rect_sensor_ = in.rectification->R_rect_left;
    map_left_ = in.rectification->map_left;
    map_right_ = in.rectification->map_right;
    raw_rig_ = RawRig{*user.raw, balance, in.rectification->coverage};
  }

  // Opens the file again at its first frame.
  void reopen() const {
    capture_.release();
    if (!capture_.open(root_.string(), cv::CAP_FFMPEG)) {
      throw InputError(root_.string(), "not a video FFmpeg can decode");
    }
    next_ = 0;
  }

  std::size_t count_frames() const {
    std::size_t n = 0;
    while (capture_.grab()) ++n;
    reopen();
    return n;
  }

  // Timestamps come from the index at a constant rate; a variable-rate video puts its frames
  // elsewhere, which the motion model would then misjudge. Said once.
  void check_frame_time(std::size_t index) const {
    const double in_file = capture_.get(cv::CAP_PROP_POS_MSEC) * 1e-3;
    const double by_index = static_cast<double>(index) / fps_;
    if (!warned_time_ && std::isfinite(in_file) && std::abs(in_file - by_index) > 0.5 / fps_) {
      warned_time_ = true;
      spdlog::warn("{}: frame {} is at {:.3f} s in the file but at {:.3f} s by its index at {:.4g} Hz (a variable "
                   "frame rate?); timestamps follow the index",
                   root_.string(), index, in_file, by_index, fps_);
    }
  }

  void load_ground_truth() {
    const auto path = video_ground_truth_path(root_);
    if (!fs::exists(path)) return;
    const auto all = read_trajectory(path, TrajectoryFormat::kTum);
    // The samples that overlap the selected frames (half a frame of slack at both ends).
    const double slack = 0.5 / fps_;
    Trajectory gt;
    std::copy_if(all.begin(), all.end(), std::back_inserter(gt), [&](const StampedPose& sp) {
      return sp.t >= timestamps_.front() - slack && sp.t <= timestamps_.back() + slack;
    });
    if (gt.empty()) {
      spdlog::warn("{}: no ground truth overlaps the selected frames (times are seconds from the video's first "
                   "frame)",
                   path.string());
      return;
    }
    gt_ = std::move(gt);
    gt_path_ = path;
  }

  // --imu and --imu-calib: the body frame of the IMU's T_BS is the left camera (the raw one for a
  // raw calibration), and the samples' nanoseconds are on the frames' clock (0 at the video's
  // first frame).
  void load_imu(const DatasetOptions& options) {
    if (options.imu_csv.empty() != options.imu_calib.empty()) {
      throw InputError(root_.string(), "--imu and --imu-calib go together");
    }
    if (options.imu_csv.empty()) return;
    imu_path_ = options.imu_csv;
    Eigen::Isometry3d T_sensor_rect = Eigen::Isometry3d::Identity();
    T_sensor_rect.linear() = R_rect_sensor_.transpose();  // identity for a rectified calibration
    imu_ = read_imu(options.imu_csv, options.imu_calib, T_sensor_rect);
    keep_imu_span(*imu_, timestamps_.front(), timestamps_.back(), options.imu_csv);
  }

  std::array<cv::Mat, 2> map_left_, map_right_;  // for a raw calibration
  double fps_ = 0;
  std::size_t total_ = 0;  // frames the container counts
  std::size_t start_ = 0;  // first selected frame
  mutable std::mutex mutex_;
  mutable cv::VideoCapture capture_;
  mutable std::size_t next_ = 0;  // index of the frame the capture decodes next
  mutable bool warned_time_ = false;
};

}  // namespace

std::unique_ptr<Dataset> open_video_dataset(const fs::path& video, const fs::path& calibration,
                                            const DatasetOptions& options) {
  return std::make_unique<VideoDataset>(fs::absolute(video).lexically_normal(), calibration, options);
}

}  // namespace plslam::io
