// Raw stereo pairs for calibration (EuRoC folders, image folders, videos) with their
// synchronisation checks, and a raw calibration file in place of an EuRoC folder's sensor.yaml.
#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/videoio.hpp>

#include "io/fake_datasets.h"
#include "plslam/core/error.h"
#include "plslam/io/camchain_file.h"
#include "plslam/io/dataset.h"
#include "plslam/io/raw_stereo_input.h"
#include "support/test_support.h"

namespace plslam::io {
namespace raw_stereo_input_test {  // named: the unity build joins the test files

namespace fs = std::filesystem;

RawStereoInputSpec folder(const fs::path& p) {
  RawStereoInputSpec s;
  s.folder = p;
  return s;
}
RawStereoInputSpec dirs(const fs::path& left, const fs::path& right) {
  RawStereoInputSpec s;
  s.left_dir = left;
  s.right_dir = right;
  return s;
}
RawStereoInputSpec videos(const fs::path& video, const fs::path& right = {}) {
  RawStereoInputSpec s;
  s.video = video;
  s.video_right = right;
  return s;
}

std::string error_of(const RawStereoInputSpec& spec) {
  try {
    auto in = open_raw_stereo_input(spec);
    while (in->next()) {
    }
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

void write_images(const fs::path& dir, const std::vector<std::string>& names, int w = 64, int h = 48) {
  fs::create_directories(dir);
  int seed = 0;
  for (const auto& n : names) cv::imwrite((dir / n).string(), test::noise_image(w, h, ++seed));
}

TEST(RawStereoInput, EurocFolderPairsByStamp) {
  test::TempDir tmp;
  const auto root = test::make_euroc(tmp.path(), 4);
  auto in = open_raw_stereo_input(folder(root));
  EXPECT_EQ(in->size(), 4u);
  std::size_t n = 0;
  while (auto p = in->next()) {
    EXPECT_EQ(p->left.size(), cv::Size(64, 48));
    EXPECT_EQ(p->index, n++);
  }
  EXPECT_EQ(n, 4u);
  // The right camera's stamps 20 ms off: no pair, and that is said.
  std::string csv = "#timestamp [ns],filename\n";
  for (int i = 0; i < 4; ++i) {
    const std::string ns = std::to_string(1403715273000000000LL + 50000000LL * i);
    csv += std::to_string(1403715273020000000LL + 50000000LL * i) + "," + ns + ".png\n";
  }
  test::write_file(root / "mav0" / "cam1" / "data.csv", csv);
  const std::string msg = error_of(folder(root));
  EXPECT_NE(msg.find("not synchronised"), std::string::npos) << msg;
}

TEST(RawStereoInput, ImageFoldersPairByName) {
  test::TempDir tmp;
  write_images(tmp.path() / "l", {"a.png", "b.png", "c.png"});
  write_images(tmp.path() / "r", {"a.png", "b.png", "c.png"});
  auto in = open_raw_stereo_input(dirs(tmp.path() / "l", tmp.path() / "r"));
  EXPECT_EQ(in->size(), 3u);
  EXPECT_EQ(in->next()->label, "a.png");

  // Nanosecond stamps within 1 ms pair; 5 ms apart do not.
  write_images(tmp.path() / "sl", {"1403715273000000000.png", "1403715273050000000.png"});
  write_images(tmp.path() / "sr", {"1403715273000400000.png", "1403715273050400000.png"});
  EXPECT_EQ(error_of(dirs(tmp.path() / "sl", tmp.path() / "sr")), "");
  write_images(tmp.path() / "ur", {"1403715273005000000.png", "1403715273055000000.png"});
  std::string msg = error_of(dirs(tmp.path() / "sl", tmp.path() / "ur"));
  EXPECT_NE(msg.find("unsynchronised"), std::string::npos) << msg;

  write_images(tmp.path() / "r2", {"a.png", "b.png"});
  msg = error_of(dirs(tmp.path() / "l", tmp.path() / "r2"));
  EXPECT_NE(msg.find("holds 2 images, the left folder 3"), std::string::npos) << msg;
  write_images(tmp.path() / "r3", {"a.png", "b.png", "c.png"}, 32, 48);
  msg = error_of(dirs(tmp.path() / "l", tmp.path() / "r3"));
  EXPECT_NE(msg.find("first pair's 64x48"), std::string::npos) << msg;
  fs::create_directories(tmp.path() / "empty");
  msg = error_of(dirs(tmp.path() / "empty", tmp.path() / "r"));
  EXPECT_NE(msg.find("no images"), std::string::npos) << msg;
  EXPECT_NE(error_of({}).find("give one input"), std::string::npos);
  EXPECT_NE(error_of(dirs(tmp.path() / "l", {})).find("go together"), std::string::npos);
}

TEST(RawStereoInput, VideosSideBySideOrTwoOfTheSameLength) {
  test::TempDir tmp;
  auto write_video = [&](const fs::path& p, int frames, int w) {
    cv::VideoWriter v(p.string(), cv::CAP_FFMPEG, cv::VideoWriter::fourcc('F', 'F', 'V', '1'), 20, cv::Size(w, 48), false);
    ASSERT_TRUE(v.isOpened());
    for (int i = 0; i < frames; ++i) v.write(test::noise_image(w, 48, i));
  };
  write_video(tmp.path() / "sbs.mkv", 3, 128);
  auto in = open_raw_stereo_input(videos(tmp.path() / "sbs.mkv"));
  const auto p = in->next();
  ASSERT_TRUE(p);
  EXPECT_EQ(p->left.size(), cv::Size(64, 48));
  EXPECT_EQ(p->label, "frame 0");
  write_video(tmp.path() / "l.mkv", 3, 64);
  write_video(tmp.path() / "r.mkv", 3, 64);
  write_video(tmp.path() / "r4.mkv", 4, 64);
  EXPECT_EQ(error_of(videos(tmp.path() / "l.mkv", tmp.path() / "r.mkv")), "");
  const std::string msg = error_of(videos(tmp.path() / "l.mkv", tmp.path() / "r4.mkv"));
  EXPECT_NE(msg.find("has 4 frames, the left video 3"), std::string::npos) << msg;
}

// --calib for an EuRoC folder: the file's cameras replace the sensor.yaml ones; cam0's T_BS (and
// so the ground truth) stays. A rectified calibration is refused there, as is --calib for KITTI.
TEST(RawStereoInput, ARawCalibrationReplacesAnEurocFoldersSensorYaml) {
  test::TempDir tmp;
  const auto root = test::make_euroc(tmp.path() / "e", 3);
  geometry::RawStereoRig rig;
  rig.left = {geometry::LensModel::kRadialTangential, 64, 48, 90, 90, 31.5, 23.5, {}};
  rig.right = rig.left;
  rig.T_right_left.translation() = Eigen::Vector3d(-0.2, 0, 0);
  write_camchain_file(tmp.path() / "c.yaml", rig, "test");
  DatasetOptions o;
  o.calibration = tmp.path() / "c.yaml";
  const auto ds = open_dataset(root, o);
  EXPECT_NEAR(ds->calibration().baseline, 0.2, 1e-12);
  EXPECT_NEAR(ds->calibration().fx, 90, 1e-9);
  ASSERT_TRUE(ds->raw_rig());
  EXPECT_EQ(ds->raw_rig()->rig.left.fx, 90);
  ASSERT_TRUE(ds->ground_truth());

  test::write_file(tmp.path() / "rect.yaml", "width: 64\nheight: 48\nfx: 90\nfy: 90\ncx: 32\ncy: 24\nbaseline: 0.2\n");
  o.calibration = tmp.path() / "rect.yaml";
  try {
    (void)open_dataset(root, o);
    FAIL() << "accepted";
  } catch (const InputError& e) {
    EXPECT_EQ(e.file(), (tmp.path() / "rect.yaml").string());
    EXPECT_NE(e.problem().find("EuRoC images are raw"), std::string::npos) << e.what();
  }
  rig.left.width = rig.right.width = 80;  // another camera's file
  write_camchain_file(tmp.path() / "c80.yaml", rig, "test");
  o.calibration = tmp.path() / "c80.yaml";
  try {
    (void)open_dataset(root, o);
    FAIL() << "accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("is 64x48 but " + (tmp.path() / "c80.yaml").string() + " says 80x48"),
              std::string::npos)
        << e.what();
  }
  o.calibration = tmp.path() / "c.yaml";
  EXPECT_THROW((void)open_dataset(test::make_kitti(tmp.path() / "k"), o), InputError);
}

}  // namespace raw_stereo_input_test
}  // namespace plslam::io
