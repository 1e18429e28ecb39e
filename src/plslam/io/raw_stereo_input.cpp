#include "plslam/io/raw_stereo_input.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <vector>

#include <fmt/format.h>
#include <opencv2/videoio.hpp>
#include <spdlog/spdlog.h>

#include "plslam/core/error.h"
#include "plslam/io/dataset_impl.h"
#include "plslam/io/image_loading.h"
#include "plslam/io/video_dataset.h"

namespace plslam::io {
namespace {

namespace fs = std::filesystem;
constexpr std::int64_t kSyncToleranceNs = 1'000'000;

struct FilePair {
  fs::path left, right;
};

void check_size(const cv::Mat& image, cv::Size& size, const fs::path& file) {
  if (size.area() == 0) size = image.size();
  if (image.size() != size) {
    throw InputError(file.string(), fmt::format("image is {}x{}, the first pair's {}x{}", image.cols, image.rows,
                                                size.width, size.height));
  }
}

class ImagePairs final : public RawStereoInput {
 public:
  ImagePairs(std::vector<FilePair> pairs, std::string name) : pairs_(std::move(pairs)), name_(std::move(name)) {}
  std::size_t size() const override { return pairs_.size(); }
  std::string name() const override { return name_; }
  std::optional<RawStereoPair> next() override {
    if (next_ >= pairs_.size()) return std::nullopt;
    const auto& p = pairs_[next_];
    RawStereoPair out{next_++, p.left.filename().string(), load_grey_image(p.left), load_grey_image(p.right)};
    check_size(out.left, size_, p.left);
    check_size(out.right, size_, p.right);
    return out;
  }

 private:
  std::vector<FilePair> pairs_;
  std::string name_;
  std::size_t next_ = 0;
  cv::Size size_;
};

std::vector<FilePair> euroc_pairs(const fs::path& given) {
  const fs::path mav0 = given.filename() == "mav0" || !fs::is_directory(given / "mav0") ? given : given / "mav0";
  const auto left = detail::read_image_list(mav0 / "cam0" / "data.csv");
  const auto right = detail::read_image_list(mav0 / "cam1" / "data.csv");
  std::vector<FilePair> pairs;
  std::size_t j = 0;
  for (const auto& l : left) {
    while (j < right.size() && right[j].ns < l.ns - kSyncToleranceNs) ++j;
    if (j < right.size() && std::llabs(right[j].ns - l.ns) <= kSyncToleranceNs) {
      pairs.push_back({mav0 / "cam0" / "data" / l.file, mav0 / "cam1" / "data" / right[j].file});
      ++j;
    }
  }
  const std::size_t most = std::max(left.size(), right.size());
  const std::size_t unpaired = most - pairs.size();
  if (unpaired * 10 > most) {
    throw InputError(mav0.string(), fmt::format("{} of {} images have no partner within 1 ms in the other camera's "
                                                "data.csv: the cameras are not synchronised",
                                                unpaired, most));
  }
  if (unpaired > 0) spdlog::warn("{}: {} images without a partner in the other camera are left out", mav0.string(), unpaired);
  return pairs;
}

bool is_image(const fs::path& p) {
  std::string ext = p.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  for (const char* e : {".png", ".jpg", ".jpeg", ".bmp", ".tif", ".tiff", ".pgm", ".ppm"})
    if (ext == e) return true;
  return false;
}

std::vector<fs::path> list_images(const fs::path& dir) {
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) throw InputError(dir.string(), "image folder not found");
  std::vector<fs::path> files;
  for (const auto& e : fs::directory_iterator(dir)) {
    if (e.is_regular_file() && is_image(e.path())) files.push_back(e.path());
  }
  if (files.empty()) throw InputError(dir.string(), "no images (png, jpg, bmp, tif, pgm) in the folder");
  std::sort(files.begin(), files.end());
  return files;
}

std::optional<std::int64_t> stamp_ns(const std::string& stem) {
  std::int64_t v = 0;
  const auto [ptr, ec] = std::from_chars(stem.data(), stem.data() + stem.size(), v);
  if (ec != std::errc() || ptr != stem.data() + stem.size() || stem.size() < 16) return std::nullopt;
  return v;
}

std::vector<FilePair> folder_pairs(const fs::path& left_dir, const fs::path& right_dir) {
  const auto left = list_images(left_dir), right = list_images(right_dir);
  if (left.size() != right.size()) {
    throw InputError(right_dir.string(), fmt::format("holds {} images, the left folder {}: the pairs cannot be told",
                                                     right.size(), left.size()));
  }
  std::vector<FilePair> pairs;
  for (std::size_t i = 0; i < left.size(); ++i) {
    const std::string a = left[i].stem().string(), b = right[i].stem().string();
    const auto ta = stamp_ns(a), tb = stamp_ns(b);
    const bool same = a == b || (ta && tb && std::llabs(*ta - *tb) <= kSyncToleranceNs);
    if (!same) {
      throw InputError(right[i].string(), fmt::format("pairs with {} of the left folder, but their names differ (the "
                                                      "same names, or nanosecond stamps within 1 ms, make a pair): "
                                                      "unsynchronised?",
                                                      left[i].filename().string()));
    }
    pairs.push_back({left[i], right[i]});
  }
  return pairs;
}

cv::VideoCapture open_video(const fs::path& file) {
  std::error_code ec;
  if (!fs::is_regular_file(file, ec)) throw InputError(file.string(), "no such video file");
  quiet_ffmpeg_log();
  cv::VideoCapture capture;
  if (!capture.open(file.string(), cv::CAP_FFMPEG)) throw InputError(file.string(), "not a video FFmpeg can decode");
  return capture;
}

std::size_t frame_count(cv::VideoCapture& capture) {
  const double n = capture.get(cv::CAP_PROP_FRAME_COUNT);
  return std::isfinite(n) && n >= 0 && n < 1e9 ? static_cast<std::size_t>(n) : 0;
}

class VideoPairs final : public RawStereoInput {
 public:
  VideoPairs(const fs::path& video, const fs::path& video_right) : video_(video), video_right_(video_right) {
    left_ = open_video(video);
    count_ = frame_count(left_);
    if (!video_right.empty()) {
      right_ = open_video(video_right);
      const std::size_t n = frame_count(right_);
      const double fl = left_.get(cv::CAP_PROP_FPS), fr = right_.get(cv::CAP_PROP_FPS);
      if (n != count_) {
        throw InputError(video_right.string(), fmt::format("has {} frames, the left video {}: the two cameras' videos "
                                                           "must hold the same synchronised frames", n, count_));
      }
      if (std::isfinite(fl) && std::isfinite(fr) && std::abs(fl - fr) > 1e-3 * std::max(fl, fr)) {
        throw InputError(video_right.string(), fmt::format("runs at {:.4g} Hz, the left video at {:.4g} Hz: not "
                                                           "synchronised", fr, fl));
      }
    }
  }
  std::size_t size() const override { return count_; }
  std::string name() const override { return video_.string(); }
  std::optional<RawStereoPair> next() override {
    cv::Mat frame;
    if (!left_.read(frame) || frame.empty()) return std::nullopt;
    RawStereoPair out;
    out.index = next_++;
    out.label = fmt::format("frame {}", out.index);
    if (video_right_.empty()) {
      if (frame.cols % 2 != 0) {
        throw InputError(video_.string(), fmt::format("frames are {} pixels wide, an odd number: not two images side "
                                                      "by side", frame.cols));
      }
      split_side_by_side(frame, frame.cols / 2, frame.rows, video_.string(), out.left, out.right);
    } else {
      cv::Mat right;
      if (!right_.read(right) || right.empty()) {
        throw InputError(video_right_.string(), fmt::format("ends at frame {}, before the left video", out.index));
      }
      out.left = to_grey(frame);
      out.right = to_grey(right);
      check_size(out.right, size_, video_right_);
    }
    check_size(out.left, size_, video_);
    return out;
  }

 private:
  fs::path video_, video_right_;
  cv::VideoCapture left_, right_;
  std::size_t count_ = 0, next_ = 0;
  cv::Size size_;
};

}  // namespace

std::unique_ptr<RawStereoInput> open_raw_stereo_input(const RawStereoInputSpec& spec) {
  const int forms = !spec.folder.empty() + !(spec.left_dir.empty() && spec.right_dir.empty()) + !spec.video.empty();
  if (forms != 1) throw InputError("", "give one input: a dataset folder, --left and --right folders, or --video");
  if (!spec.video_right.empty() && spec.video.empty()) throw InputError("", "--video-right needs --video");
  if (!spec.folder.empty()) {
    std::error_code ec;
    if (!fs::is_directory(spec.folder, ec)) throw InputError(spec.folder.string(), "folder not found");
    return std::make_unique<ImagePairs>(euroc_pairs(spec.folder), spec.folder.string());
  }
  if (!spec.video.empty()) return std::make_unique<VideoPairs>(spec.video, spec.video_right);
  if (spec.left_dir.empty() || spec.right_dir.empty()) throw InputError("", "--left and --right go together");
  return std::make_unique<ImagePairs>(folder_pairs(spec.left_dir, spec.right_dir), spec.left_dir.string());
}

}  // namespace plslam::io
