#include "plslam/io/camera_source.h"

#include <array>
#include <chrono>
#include <filesystem>
#include <thread>

#include <fmt/format.h>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>

#include "plslam/core/error.h"
#include "plslam/io/video_dataset.h"

namespace plslam::io {
namespace {

class V4l2StereoCamera final : public FrameSource {
 public:
  V4l2StereoCamera(const std::string& device, const std::string& right_device, const StereoCalibration& c)
      : device_(device), right_device_(right_device), width_(c.width), height_(c.height) {
    open(left_, device_, right_device_.empty() ? 2 * width_ : width_);
    if (!right_device_.empty()) open(right_, right_device_, width_);
    start_ = std::chrono::steady_clock::now();
    // A wrong size fails here, before the run starts. The frame itself is not kept: tracking
    // starts later, and its first frame should be a fresh one.
    (void)read_frame();
  }

  std::optional<CapturedFrame> capture() override { return read_frame(); }

  std::string name() const override { return right_device_.empty() ? device_ : device_ + "+" + right_device_; }

 private:
  void open(cv::VideoCapture& capture, const std::string& device, int width) {
    std::error_code ec;
    if (!std::filesystem::exists(device, ec)) throw InputError(device, "no such device");
    if (!capture.open(device, cv::CAP_V4L2)) throw InputError(device, "cannot open it as a V4L2 camera");
    capture.set(cv::CAP_PROP_FRAME_WIDTH, width);
    capture.set(cv::CAP_PROP_FRAME_HEIGHT, height_);
  }

  CapturedFrame read_frame() {
    // Both devices grab before either decodes: the two exposures are as close as the devices allow.
    if (!left_.grab()) throw InputError(device_, "no frame: the camera stopped delivering (unplugged?)");
    if (right_.isOpened() && !right_.grab()) {
      throw InputError(right_device_, "no frame: the camera stopped delivering (unplugged?)");
    }
    CapturedFrame f;
    f.timestamp = std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
    cv::Mat raw;
    if (!left_.retrieve(raw) || raw.empty()) throw InputError(device_, "a frame could not be decoded");
    if (!right_.isOpened()) {
      split_side_by_side(raw, width_, height_, device_, f.left, f.right);
      return f;
    }
    f.left = checked_grey(raw, device_);
    if (!right_.retrieve(raw) || raw.empty()) throw InputError(right_device_, "a frame could not be decoded");
    f.right = checked_grey(raw, right_device_);
    return f;
  }

  cv::Mat checked_grey(const cv::Mat& raw, const std::string& device) const {
    if (raw.cols != width_ || raw.rows != height_) {
      throw InputError(device, fmt::format("frames are {}x{}, but the calibration says {}x{}", raw.cols, raw.rows,
                                           width_, height_));
    }
    return to_grey(raw);
  }

  std::string device_, right_device_;
  int width_, height_;
  cv::VideoCapture left_, right_;
  std::chrono::steady_clock::time_point start_;
};

// A video file replayed in real time: frame i is delivered at its time i / fps after the first
// capture() call, whether or not anybody takes it.
class VideoFileCamera final : public FrameSource {
 public:
  VideoFileCamera(const std::string& file, const StereoCalibration& c) : file_(file), width_(c.width), height_(c.height) {
    quiet_ffmpeg_log();
    if (!capture_.open(file, cv::CAP_FFMPEG)) throw InputError(file, "not a video FFmpeg can decode");
    fps_ = capture_.get(cv::CAP_PROP_FPS);
    if (!(fps_ > 0 && fps_ <= 1000)) fps_ = 30.0;
    cv::Mat frame;
    if (!capture_.read(frame)) throw InputError(file, "no frame decodes");
    cv::Mat left, right;
    split_side_by_side(frame, width_, height_, file_, left, right);
    capture_.open(file, cv::CAP_FFMPEG);  // back to the first frame
  }

  std::optional<CapturedFrame> capture() override {
    const auto now = std::chrono::steady_clock::now();
    if (index_ == 0) start_ = now;
    std::this_thread::sleep_until(start_ + std::chrono::duration<double>(static_cast<double>(index_) / fps_));
    cv::Mat frame;
    if (!capture_.read(frame)) return std::nullopt;  // the end of the video ends the "camera"
    CapturedFrame f;
    f.timestamp = static_cast<double>(index_++) / fps_;
    split_side_by_side(frame, width_, height_, file_, f.left, f.right);
    return f;
  }

  std::string name() const override { return file_; }

 private:
  std::string file_;
  int width_, height_;
  double fps_ = 30.0;
  cv::VideoCapture capture_;
  std::size_t index_ = 0;
  std::chrono::steady_clock::time_point start_;
};

}  // namespace

std::unique_ptr<FrameSource> open_stereo_camera(const std::string& device, const std::string& right_device,
                                                     const StereoCalibration& calibration) {
  std::error_code ec;
  if (std::filesystem::is_regular_file(device, ec)) {
    if (!right_device.empty()) throw InputError(right_device, "a video file played as a camera holds both images");
    return std::make_unique<VideoFileCamera>(device, calibration);
  }
  return std::make_unique<V4l2StereoCamera>(device, right_device, calibration);
}

namespace {

class RectifyingSource final : public FrameSource {
 public:
  RectifyingSource(std::unique_ptr<FrameSource> raw, const geometry::StereoRectification& r)
      : raw_(std::move(raw)), map_left_(r.map_left), map_right_(r.map_right) {}

  std::optional<CapturedFrame> capture() override {
    auto frame = raw_->capture();
    if (!frame) return frame;
    CapturedFrame out;
    out.timestamp = frame->timestamp;
    cv::remap(frame->left, out.left, map_left_[0], map_left_[1], cv::INTER_LINEAR);
    cv::remap(frame->right, out.right, map_right_[0], map_right_[1], cv::INTER_LINEAR);
    return out;
  }
  std::string name() const override { return raw_->name(); }

 private:
  std::unique_ptr<FrameSource> raw_;
  std::array<cv::Mat, 2> map_left_, map_right_;
};

}  // namespace

std::unique_ptr<FrameSource> rectify_frames(std::unique_ptr<FrameSource> raw,
                                            const geometry::StereoRectification& rectification) {
  return std::make_unique<RectifyingSource>(std::move(raw), rectification);
}

}  // namespace plslam::io
