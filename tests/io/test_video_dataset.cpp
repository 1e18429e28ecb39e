// Side-by-side stereo videos as datasets: exact frames from a lossless video, timestamps from the
// frame rate, ground truth beside the video, --start/--max-frames, and a one-line error naming the
// file for every bad input.
#include <filesystem>

#include <gtest/gtest.h>
#include <opencv2/videoio.hpp>

#include "io/fake_datasets.h"
#include "plslam/core/error.h"
#include "plslam/io/calibration_file.h"
#include "plslam/io/frame_stream.h"
#include "plslam/io/trajectory_io.h"
#include "plslam/io/video_dataset.h"
#include "support/test_support.h"

namespace plslam::io {
namespace video_dataset_test {  // named: the unity build joins the test files

namespace fs = std::filesystem;

constexpr int kW = 64, kH = 48;

StereoCalibration calibration(int width = kW, int height = kH) {
  StereoCalibration c;
  c.width = width;
  c.height = height;
  c.fx = c.fy = 100;
  c.cx = 32;
  c.cy = 24;
  c.baseline = 0.1;
  return c;
}

struct TestVideo {
  fs::path video, calib;
  std::vector<cv::Mat> left, right;
};

// `frames` side-by-side FFV1 frames of noise at 20 Hz, its calibration file, and ground truth
// (one pose per frame, 0.1 m apart along x) unless `with_gt` is false.
TestVideo make_video(const fs::path& dir, int frames, bool with_gt = true) {
  quiet_ffmpeg_log();
  TestVideo t;
  t.video = dir / "stereo.mkv";
  t.calib = dir / "calibration.yaml";
  fs::create_directories(dir);
  cv::VideoWriter writer(t.video.string(), cv::CAP_FFMPEG, cv::VideoWriter::fourcc('F', 'F', 'V', '1'), 20.0,
                         cv::Size(2 * kW, kH), false);
  EXPECT_TRUE(writer.isOpened());
  Trajectory gt;
  for (int i = 0; i < frames; ++i) {
    t.left.push_back(test::noise_image(kW, kH, 2 * i));
    t.right.push_back(test::noise_image(kW, kH, 2 * i + 1));
    cv::Mat sbs;
    cv::hconcat(t.left.back(), t.right.back(), sbs);
    writer.write(sbs);
    StampedPose p;
    p.t = i / 20.0;
    p.T.translation().x() = 0.1 * i;
    gt.push_back(p);
  }
  writer.release();
  write_calibration_file(t.calib, calibration());
  if (with_gt) write_trajectory(video_ground_truth_path(t.video), gt, TrajectoryFormat::kTum);
  return t;
}

bool same(const cv::Mat& a, const cv::Mat& b) {
  return a.size() == b.size() && a.type() == b.type() && cv::norm(a, b, cv::NORM_INF) == 0;
}

// The InputError message of opening the video (empty when it opened).
std::string open_error(const fs::path& video, const fs::path& calib, const DatasetOptions& options = {}) {
  try {
    (void)open_video_dataset(video, calib, options);
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos) << e.what();
    return e.what();
  }
  return "";
}

TEST(VideoDataset, ReadsEveryFrameExactlyWithTimesAndGroundTruth) {
  test::TempDir tmp;
  const auto t = make_video(tmp.path(), 12);
  const auto ds = open_video_dataset(t.video, t.calib);
  EXPECT_EQ(ds->format(), DatasetFormat::kVideo);
  EXPECT_EQ(ds->root(), t.video);
  ASSERT_EQ(ds->size(), 12u);
  EXPECT_NEAR(ds->fps(), 20.0, 1e-9);
  for (std::size_t i = 0; i < 12; ++i) EXPECT_DOUBLE_EQ(ds->timestamps()[i], i / 20.0);
  EXPECT_EQ(ds->calibration().width, kW);
  EXPECT_EQ(ds->calibration().height, kH);
  EXPECT_EQ(ds->calibration().baseline, 0.1);
  ASSERT_TRUE(ds->ground_truth());
  EXPECT_EQ(ds->ground_truth()->size(), 12u);
  EXPECT_EQ(ds->ground_truth_path(), t.video.parent_path() / "ground_truth.tum");
  EXPECT_NEAR(ds->ground_truth_length(), 1.1, 1e-9);
  FrameStream stream(*ds);
  std::size_t n = 0;
  while (auto f = stream.next()) {
    ASSERT_EQ(f->index, n);
    EXPECT_EQ(f->left.type(), CV_8UC1);
    EXPECT_TRUE(same(f->left, t.left[n])) << n;  // FFV1 is lossless
    EXPECT_TRUE(same(f->right, t.right[n])) << n;
    EXPECT_EQ(f->left_path, t.video);
    ++n;
  }
  EXPECT_EQ(n, 12u);
  EXPECT_EQ(stream.input_frames(), 12u);
  EXPECT_EQ(stream.skipped(), 0u);
}

TEST(VideoDataset, StartAndMaxFramesSelectARange) {
  test::TempDir tmp;
  const auto t = make_video(tmp.path(), 12);
  DatasetOptions o;
  o.start = 3;
  o.max_frames = 4;
  const auto ds = open_video_dataset(t.video, t.calib, o);
  ASSERT_EQ(ds->size(), 4u);
  EXPECT_DOUBLE_EQ(ds->timestamps().front(), 3 / 20.0);
  ASSERT_TRUE(ds->ground_truth());
  EXPECT_EQ(ds->ground_truth()->size(), 4u);
  EXPECT_TRUE(same(ds->load(0).left, t.left[3]));
  EXPECT_TRUE(same(ds->load(3).right, t.right[6]));
  o.start = 12;
  EXPECT_NE(open_error(t.video, t.calib, o).find("--start 12 is past the last frame"), std::string::npos);
}

TEST(VideoDataset, AnEarlierFrameIsDecodedAgainFromTheStart) {
  test::TempDir tmp;
  const auto t = make_video(tmp.path(), 8, false);
  const auto ds = open_video_dataset(t.video, t.calib);
  EXPECT_FALSE(ds->ground_truth());
  EXPECT_TRUE(same(ds->load(6).left, t.left[6]));
  EXPECT_TRUE(same(ds->load(2).left, t.left[2]));
  EXPECT_TRUE(same(ds->load(7).right, t.right[7]));
  EXPECT_THROW((void)ds->load(8), std::out_of_range);
}

TEST(VideoDataset, ATruncatedVideoEndsWhereItsFramesEnd) {
  test::TempDir tmp;
  const auto t = make_video(tmp.path(), 12);
  fs::resize_file(t.video, fs::file_size(t.video) / 2);
  const auto ds = open_video_dataset(t.video, t.calib);
  ASSERT_EQ(ds->size(), 12u);  // what the container says
  FrameStream stream(*ds);
  std::size_t n = 0;
  while (auto f = stream.next()) EXPECT_TRUE(same(f->left, t.left[n++]));
  EXPECT_GT(n, 0u);
  EXPECT_LT(n, 12u);
  EXPECT_EQ(stream.input_frames(), n);
  EXPECT_EQ(stream.skipped(), 0u);
  // Cut before the first frame: nothing decodes, which opening says.
  fs::resize_file(t.video, 1000);
  const auto msg = open_error(t.video, t.calib);
  EXPECT_EQ(msg, t.video.string() + ": no frame decodes, though the file counts 12 (truncated?)");
}

TEST(VideoDataset, BadInputsNameTheFile) {
  test::TempDir tmp;
  const auto t = make_video(tmp.path() / "v", 3);
  const auto missing = tmp.path() / "none.mkv";
  EXPECT_EQ(open_error(missing, t.calib), missing.string() + ": no such file");
  EXPECT_EQ(open_error(tmp.path(), t.calib), tmp.path().string() + ": is a folder, expected a video file");
  const auto text = tmp.path() / "notes.mkv";
  test::write_file(text, "not a video\n");
  EXPECT_EQ(open_error(text, t.calib), text.string() + ": not a video FFmpeg can decode");
  const auto empty = tmp.path() / "empty.mkv";
  test::write_file(empty, "");
  EXPECT_EQ(open_error(empty, t.calib), empty.string() + ": not a video FFmpeg can decode");
  // A video of one camera only, or a calibration for another size.
  const auto other = tmp.path() / "other.yaml";
  write_calibration_file(other, calibration(kW * 2, kH));
  EXPECT_EQ(open_error(t.video, other), t.video.string() + ": frames are 128x48, but the 128x48 images of " +
                                            other.string() + " side by side make 256x48");
  write_calibration_file(other, calibration(kW, kH / 2));
  EXPECT_NE(open_error(t.video, other).find(t.video.string() + ": frames are 128x48"), std::string::npos);
  // The calibration's own errors name it.
  EXPECT_EQ(open_error(t.video, tmp.path() / "none.yaml").rfind((tmp.path() / "none.yaml").string(), 0), 0u);
  // Ground truth that does not parse is an error too, naming it.
  test::write_file(video_ground_truth_path(t.video), "0 1 2\n");
  EXPECT_EQ(open_error(t.video, t.calib).rfind(video_ground_truth_path(t.video).string(), 0), 0u);
}

TEST(VideoDataset, SideBySideSplitNeedsTwiceTheWidth) {
  cv::Mat left, right;
  const cv::Mat colour(kH, 2 * kW, CV_8UC3, cv::Scalar(10, 10, 10));
  split_side_by_side(colour, kW, kH, "cam", left, right);
  EXPECT_EQ(left.type(), CV_8UC1);
  EXPECT_EQ(left.size(), cv::Size(kW, kH));
  EXPECT_EQ(right.at<std::uint8_t>(5, 5), 10);
  try {
    split_side_by_side(cv::Mat(kH, kW, CV_8UC1), kW, kH, "/dev/video0", left, right);
    ADD_FAILURE();
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()), "/dev/video0: frames are 64x48, but the calibration's 64x48 images side by side "
                                     "make 128x48");
  }
}

}  // namespace video_dataset_test
}  // namespace plslam::io
