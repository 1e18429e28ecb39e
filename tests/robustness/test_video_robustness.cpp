// Bad video and camera input for `plslam run` (issue 21): each is refused before the first frame
// with exit 2 and one line naming the file or device; a video cut short is run up to where its
// frames end. The video is rendered once by `plslam synth --format video` and copied per case.
#include <fstream>
#include <functional>
#include <string>

#include <fmt/format.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "support/test_support.h"

namespace plslam {
namespace video_robustness_test {  // named: the unity build joins the test files

namespace fs = std::filesystem;

std::string q(const fs::path& p) { return fmt::format("\"{}\"", p.string()); }

// A 6-frame office video (stereo.mkv, calibration.yaml, ground_truth.tum) rendered once per
// process, copied into `dir`.
fs::path copy_of_video(const fs::path& dir) {
  static test::TempDir rendered;
  static const bool ok = [] {
    const auto r = test::run_cli("synth --out " + q(rendered.path() / "v") +
                                 " --scene office --frames 6 --seed 3 --format video");
    EXPECT_EQ(r.exit_code, 0) << r.err;
    return r.exit_code == 0;
  }();
  EXPECT_TRUE(ok);
  fs::copy(rendered.path() / "v", dir, fs::copy_options::recursive);
  return dir;
}

// `run` with `input` refused with exit 2: one error line that holds every fragment.
void expect_refused(const std::string& input, const fs::path& out, const std::vector<std::string>& fragments) {
  const auto r = test::run_cli("run " + input + " --quiet --out " + q(out));
  SCOPED_TRACE(input);
  EXPECT_EQ(r.exit_code, 2) << r.err;
  std::size_t lines = 0;
  for (char c : r.err) lines += c == '\n';
  EXPECT_EQ(lines, 1u) << r.err;
  EXPECT_EQ(r.err.rfind("plslam: error: ", 0), 0u) << r.err;
  for (const auto& f : fragments) EXPECT_NE(r.err.find(f), std::string::npos) << f << " not in " << r.err;
  EXPECT_FALSE(fs::exists(out / "stats.json"));
}

TEST(VideoRobustness, BadVideoFilesAreRefusedNamingTheFile) {
  test::TempDir tmp;
  const auto v = copy_of_video(tmp.path() / "v");
  const auto calib = " --calib " + q(v / "calibration.yaml");
  const auto out = tmp.path() / "out";
  expect_refused("--video " + q(v / "none.mkv") + calib, out, {(v / "none.mkv").string(), "no such file"});
  expect_refused("--video " + q(v) + calib, out, {v.string(), "is a folder, expected a video file"});
  // A file FFmpeg cannot read: another file renamed, and an empty one.
  fs::copy_file(v / "ground_truth.tum", v / "trajectory.mkv");
  expect_refused("--video " + q(v / "trajectory.mkv") + calib, out,
                 {(v / "trajectory.mkv").string(), "not a video FFmpeg can decode"});
  std::ofstream(v / "empty.mkv").close();
  expect_refused("--video " + q(v / "empty.mkv") + calib, out,
                 {(v / "empty.mkv").string(), "not a video FFmpeg can decode"});
  // Cut before its first frame: the container still counts 6.
  fs::copy_file(v / "stereo.mkv", v / "cut.mkv");
  fs::resize_file(v / "cut.mkv", 1000);
  expect_refused("--video " + q(v / "cut.mkv") + calib, out,
                 {(v / "cut.mkv").string(), "no frame decodes, though the file counts 6"});
  // --start past its end.
  expect_refused("--video " + q(v / "stereo.mkv") + calib + " --start 6", out,
                 {(v / "stereo.mkv").string(), "--start 6 is past the last frame (6 frames)"});
}

TEST(VideoRobustness, ACalibrationThatDoesNotFitIsRefused) {
  test::TempDir tmp;
  const auto v = copy_of_video(tmp.path() / "v");
  const auto video = "--video " + q(v / "stereo.mkv");
  const auto out = tmp.path() / "out";
  const auto calib = v / "calibration.yaml";
  const std::string good = test::read_file(calib);
  const auto edit = [&](const std::string& from, const std::string& to) {
    std::string text = good;
    text.replace(text.find(from), from.size(), to);
    std::ofstream(calib, std::ios::trunc) << text;
  };
  // A video of one 752x480 camera would be 752 wide; this one is 1504: a calibration of 1504x480
  // images does not fit it.
  edit("width: 752", "width: 1504");
  expect_refused(video + " --calib " + q(calib), out,
                 {(v / "stereo.mkv").string(), "frames are 1504x480", calib.string(), "make 3008x480"});
  edit("height: 480", "height: 240");
  expect_refused(video + " --calib " + q(calib), out, {(v / "stereo.mkv").string(), "frames are 1504x480"});
  edit("baseline: 0.11", "baseline: -0.11");
  expect_refused(video + " --calib " + q(calib), out, {calib.string(), "baseline: must be positive, got -0.11"});
  edit("fx: 458", "fx: 458\nk1: 0.1");
  expect_refused(video + " --calib " + q(calib), out, {calib.string(), "unknown key 'k1'"});
  edit("cy: 239.5\n", "");
  expect_refused(video + " --calib " + q(calib), out, {calib.string(), "cy: missing"});
  expect_refused(video + " --calib " + q(v / "none.yaml"), out,
                 {(v / "none.yaml").string(), "calibration file not found"});
}

TEST(VideoRobustness, InputsMustBeOneAndComplete) {
  test::TempDir tmp;
  const auto out = tmp.path() / "out";
  const auto v = copy_of_video(tmp.path() / "v");
  const auto calib = " --calib " + q(v / "calibration.yaml");
  expect_refused("", out, {"no input"});
  expect_refused("--video " + q(v / "stereo.mkv"), out, {"--video and --camera need --calib FILE"});
  expect_refused(q(tmp.path()) + " --video " + q(v / "stereo.mkv") + calib, out, {"give one input only"});
  expect_refused("--video " + q(v / "stereo.mkv") + " --camera /dev/video0" + calib, out, {"give one input only"});
  expect_refused("--video " + q(v / "stereo.mkv") + calib + " --format euroc", out,
                 {"--format is for dataset folders"});
}

TEST(VideoRobustness, AMissingCameraIsOneLineAndExit2) {
  test::TempDir tmp;
  const auto v = copy_of_video(tmp.path() / "v");
  const auto calib = " --calib " + q(v / "calibration.yaml");
  const auto out = tmp.path() / "out";
  // No camera on a test machine: /dev/video97 and 98 do not exist, and /dev/null is no camera.
  expect_refused("--camera /dev/video97" + calib, out, {"/dev/video97: no such device"});
  expect_refused("--camera /dev/video97 --camera-right /dev/video98" + calib, out, {"/dev/video97: no such device"});
  expect_refused("--camera /dev/null" + calib, out, {"/dev/null: cannot open it as a V4L2 camera"});
  // A file in place of the device is a video played as a camera: it must be one, holding both images.
  expect_refused("--camera " + q(v / "calibration.yaml") + calib, out,
                 {(v / "calibration.yaml").string(), "not a video FFmpeg can decode"});
  expect_refused("--camera " + q(v / "stereo.mkv") + " --camera-right /dev/video98" + calib, out,
                 {"/dev/video98: a video file played as a camera holds both images"});
  expect_refused("--camera /dev/video97", out, {"--video and --camera need --calib FILE"});
  expect_refused("--camera /dev/video97 --start 3" + calib, out, {"--start is not for a live camera"});
  const auto r = test::run_cli("run --camera /dev/video97 --realtime --out " + q(out) + calib);
  EXPECT_EQ(r.exit_code, 2);
}

TEST(VideoRobustness, AVideoCutShortIsRunUpToItsLastFrame) {
  test::TempDir tmp;
  const auto v = copy_of_video(tmp.path() / "v");
  // The container still counts 6 frames; about half of them remain.
  fs::resize_file(v / "stereo.mkv", fs::file_size(v / "stereo.mkv") * 6 / 10);
  const auto out = tmp.path() / "out";
  const auto r = test::run_cli("run --video " + q(v / "stereo.mkv") + " --calib " + q(v / "calibration.yaml") +
                               " --quiet --sequential --out " + q(out));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.err.find("ends after"), std::string::npos) << r.err;
  std::ifstream in(out / "stats.json");
  const auto stats = nlohmann::json::parse(in);
  const int frames = stats["input_frames"].get<int>();
  EXPECT_GE(frames, 2);
  EXPECT_LT(frames, 6);
  EXPECT_EQ(stats["frames"], frames);
  EXPECT_EQ(stats["complete"], true);
  EXPECT_TRUE(stats["skipped"].empty());
  EXPECT_EQ(stats["live"], nullptr);
}

}  // namespace video_robustness_test
}  // namespace plslam
