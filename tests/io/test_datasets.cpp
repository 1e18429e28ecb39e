#include <cmath>
#include <fstream>
#include <regex>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/calib3d.hpp>
#include <opencv2/features2d.hpp>
#include <opencv2/imgproc.hpp>

#include "io/fake_datasets.h"
#include "plslam/core/error.h"
#include "plslam/io/dataset.h"
#include "plslam/io/euroc_sensor.h"
#include "plslam/io/frame_stream.h"
#include "plslam/io/trajectory_io.h"
#include "support/test_support.h"

namespace plslam::io {
namespace {

namespace fs = std::filesystem;
using test::TempDir;

TEST(KittiReader, ReadsLayoutCalibrationTimesAndPoses) {
  TempDir tmp;
  const auto seq = test::make_kitti(tmp.path(), 4);
  const auto ds = open_dataset(seq);
  EXPECT_EQ(ds->format(), DatasetFormat::kKitti);
  EXPECT_EQ(ds->size(), 4u);
  EXPECT_EQ(ds->calibration().width, 64);
  EXPECT_EQ(ds->calibration().height, 48);
  EXPECT_DOUBLE_EQ(ds->calibration().fx, 500.0);
  EXPECT_DOUBLE_EQ(ds->calibration().baseline, 0.5);
  EXPECT_NEAR(ds->fps(), 10.0, 1e-9);
  ASSERT_TRUE(ds->ground_truth());
  EXPECT_NEAR(ds->ground_truth_length(), 3.0, 1e-12);
  const auto f = ds->load(2);
  EXPECT_EQ(f.left.type(), CV_8UC1);
  EXPECT_NEAR(f.timestamp, 0.2, 1e-12);
}

TEST(KittiReader, StartAndMaxFramesSelectARange) {
  TempDir tmp;
  const auto seq = test::make_kitti(tmp.path(), 5);
  DatasetOptions o;
  o.start = 1;
  o.max_frames = 2;
  const auto ds = open_dataset(seq, o);
  ASSERT_EQ(ds->size(), 2u);
  EXPECT_NEAR(ds->timestamps()[0], 0.1, 1e-12);
  ASSERT_TRUE(ds->ground_truth());
  ASSERT_EQ(ds->ground_truth()->size(), 2u);
  EXPECT_DOUBLE_EQ(ds->ground_truth()->front().T.translation().z(), 1.0);
}

TEST(KittiReader, AcceptsUnlabelledP0P1File) {
  TempDir tmp;
  const auto seq = test::make_kitti(tmp.path());
  test::write_file(seq / "calib.txt", "500 0 32 0 0 500 24 0 0 0 1 0\n500 0 32 -250 0 500 24 0 0 0 1 0\n");
  EXPECT_DOUBLE_EQ(open_dataset(seq)->calibration().baseline, 0.5);
}

TEST(KittiReader, MissingTimesAssumes10Hz) {
  TempDir tmp;
  const auto seq = test::make_kitti(tmp.path());
  fs::remove(seq / "times.txt");
  const auto ds = open_dataset(seq);
  EXPECT_NEAR(ds->fps(), 10.0, 1e-9);
}

TEST(EurocReader, RectifiesAndConvertsGroundTruthToLeftCamera) {
  TempDir tmp;
  const auto root = test::make_euroc(tmp.path(), 3);
  for (const auto& p : {root, root / "mav0"}) {
    const auto ds = open_dataset(p);
    EXPECT_EQ(ds->format(), DatasetFormat::kEuroc);
    EXPECT_EQ(ds->size(), 3u);
    EXPECT_NEAR(ds->calibration().baseline, 0.11, 1e-9);
    EXPECT_NEAR(ds->fps(), 20.0, 1e-3);  // ns stamps as double seconds: ~1e-7 s resolution
    const auto f = ds->load(1);
    EXPECT_EQ(f.left.size(), cv::Size(64, 48));
    ASSERT_TRUE(ds->ground_truth());
    EXPECT_EQ(ds->ground_truth()->size(), 3u);
  }
}

// Equidistant (Kannala-Brandt) cameras, as TUM-VI's sensor.yaml has them, are rectified with
// OpenCV's fisheye model, and the reader keeps the raw rig for `plslam info`.
TEST(EurocReader, RectifiesEquidistantFisheyeCameras) {
  TempDir tmp;
  const auto root = test::make_euroc(tmp.path(), 2);
  for (const char* cam : {"cam0", "cam1"}) {
    auto y = test::euroc_sensor_yaml(cam[3] == '0' ? 0.0 : 0.11);
    y.replace(y.find("radial-tangential"), 17, "equidistant");
    y.replace(y.find("[-0.1, 0.01, 0.0, 0.0]"), 22, "[0.0035, 0.0007, -0.002, 0.0002]");
    test::write_file(root / "mav0" / cam / "sensor.yaml", y);
  }
  const auto ds = open_dataset(root);
  EXPECT_NEAR(ds->calibration().baseline, 0.11, 1e-9);
  ASSERT_TRUE(ds->raw_rig().has_value());
  EXPECT_EQ(ds->raw_rig()->rig.left.model, geometry::LensModel::kEquidistant);
  EXPECT_DOUBLE_EQ(ds->raw_rig()->rig.right.coeffs[3], 0.0002);
  EXPECT_GT(ds->raw_rig()->coverage.kept_share, 0.5);
  EXPECT_EQ(ds->load(1).left.size(), cv::Size(64, 48));
  // A wider rectified view: a shorter focal length and more of the raw image kept.
  DatasetOptions wide;
  wide.rectify_balance = 1.0;
  const auto wide_ds = open_dataset(root, wide);
  EXPECT_LT(wide_ds->calibration().fx, ds->calibration().fx);
  EXPECT_GT(wide_ds->raw_rig()->coverage.kept_share, ds->raw_rig()->coverage.kept_share);
}

TEST(EurocReader, DropsUnpairedImages) {
  TempDir tmp;
  const auto root = test::make_euroc(tmp.path(), 3);
  std::ofstream(root / "mav0" / "cam1" / "data.csv", std::ios::app) << "1403715273500000000,x.png\n";
  EXPECT_EQ(open_dataset(root)->size(), 3u);
}

TEST(FrameStream, DeliversFramesInOrderWithBoundedQueue) {
  TempDir tmp;
  const auto seq = test::make_kitti(tmp.path(), 12);
  const auto ds = open_dataset(seq);
  FrameStream stream(*ds, 3);
  std::size_t expected = 0;
  while (auto f = stream.next()) {
    EXPECT_EQ(f->index, expected++);
    EXPECT_LE(stream.queued(), 3u);
  }
  EXPECT_EQ(expected, 12u);
  EXPECT_EQ(stream.skipped(), 0u);
}

TEST(FrameStream, CorruptImageMidSequenceIsSkippedNotFatal) {
  TempDir tmp;
  const auto seq = test::make_kitti(tmp.path(), 5);
  test::write_file(seq / "image_0" / "000002.png", "\x89PNG\r\n\x1a\n garbage");
  const auto ds = open_dataset(seq);
  FrameStream stream(*ds);
  std::vector<std::size_t> seen;
  while (auto f = stream.next()) seen.push_back(f->index);
  EXPECT_EQ(seen, (std::vector<std::size_t>{0, 1, 3, 4}));
  EXPECT_EQ(stream.skipped(), 1u);
}

// A blank frame is skipped like a corrupt one, or, asked for (plslam run with the IMU), passed on
// with its problem; a corrupt one is skipped either way.
TEST(FrameStream, BlankFramesArePassedOnOnlyWhenAsked) {
  TempDir tmp;
  const auto seq = test::make_kitti(tmp.path(), 5);
  const auto blank = seq / "image_1" / "000001.png";
  const cv::Mat like = cv::imread((seq / "image_1" / "000000.png").string(), cv::IMREAD_UNCHANGED);
  ASSERT_TRUE(cv::imwrite(blank.string(), cv::Mat::zeros(like.size(), like.type())));
  test::write_file(seq / "image_0" / "000003.png", "\x89PNG\r\n\x1a\n garbage");
  const auto ds = open_dataset(seq);
  for (const bool deliver : {false, true}) {
    FrameStream stream(*ds, 4, deliver);
    std::vector<std::size_t> seen;
    while (auto f = stream.next()) {
      seen.push_back(f->index);
      EXPECT_EQ(f->blank, f->index == 1);
      EXPECT_EQ(f->problem.empty(), f->index != 1);
      if (f->blank) {
        EXPECT_NE(f->problem.find("000001.png"), std::string::npos) << f->problem;
      }
    }
    EXPECT_EQ(seen, deliver ? (std::vector<std::size_t>{0, 1, 2, 4}) : (std::vector<std::size_t>{0, 2, 4}));
    EXPECT_EQ(stream.skipped(), deliver ? 1u : 2u);
  }
}

TEST(FrameStream, StopsCleanlyWhenDestroyedEarly) {
  TempDir tmp;
  const auto seq = test::make_kitti(tmp.path(), 10);
  const auto ds = open_dataset(seq);
  FrameStream stream(*ds, 2);
  EXPECT_TRUE(stream.next());
}

// ---- Bad input: every case is one InputError line that names the file, and exit code 2. ----

struct BadInput {
  std::string name;
  std::function<fs::path(const fs::path&)> make;  // builds the broken dataset, returns its path
  std::string file_fragment;                       // the file the message must name
  std::string problem_fragment;
};

class DatasetBadInput : public ::testing::TestWithParam<BadInput> {};

TEST_P(DatasetBadInput, OneLineErrorNamingFileAndExitCode2) {
  TempDir tmp;
  const auto path = GetParam().make(tmp.path());
  try {
    open_dataset(path);
    FAIL() << "accepted " << GetParam().name;
  } catch (const InputError& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find(GetParam().file_fragment), std::string::npos) << msg;
    EXPECT_NE(msg.find(GetParam().problem_fragment), std::string::npos) << msg;
    EXPECT_EQ(msg.find('\n'), std::string::npos) << msg;
  }
  const auto r = test::run_cli("info \"" + path.string() + "\"");
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_NE(r.err.find("error: "), std::string::npos) << r.err;
  EXPECT_NE(r.err.find(GetParam().problem_fragment), std::string::npos) << r.err;
}

fs::path kitti_with(const fs::path& root, const std::function<void(const fs::path&)>& edit) {
  const auto seq = test::make_kitti(root);
  edit(seq);
  return seq;
}

fs::path euroc_with(const fs::path& root, const std::function<void(const fs::path&)>& edit) {
  const auto r = test::make_euroc(root);
  edit(r / "mav0");
  return r;
}

const BadInput kBadInputs[] = {
    {"missing_folder", [](const fs::path& r) { return r / "nope"; }, "nope", "no such folder"},
    {"unknown_layout", [](const fs::path& r) { fs::create_directories(r / "x"); return r / "x"; }, "x",
     "unknown dataset layout"},
    {"kitti_empty_image_folder",
     [](const fs::path& r) {
       return kitti_with(r, [](const fs::path& s) {
         fs::remove_all(s / "image_0");
         fs::create_directories(s / "image_0");
       });
     },
     "image_0", "empty image folder"},
    {"kitti_corrupt_png",
     [](const fs::path& r) {
       return kitti_with(r, [](const fs::path& s) { test::write_file(s / "image_0" / "000000.png", "not a png"); });
     },
     "000000.png", "not a PNG, JPEG, PGM/PPM, BMP or TIFF image"},
    {"kitti_truncated_png",
     [](const fs::path& r) {
       return kitti_with(r, [](const fs::path& s) {
         std::vector<uchar> buf;
         cv::imencode(".png", test::noise_image(64, 48, 3), buf);
         std::ofstream(s / "image_1" / "000000.png", std::ios::binary)
             .write(reinterpret_cast<const char*>(buf.data()), static_cast<std::streamsize>(buf.size() / 2));
       });
     },
     "000000.png", "corrupt or truncated image"},
    {"kitti_missing_calib",
     [](const fs::path& r) { return kitti_with(r, [](const fs::path& s) { fs::remove(s / "calib.txt"); }); },
     "calib.txt", "calibration file not found"},
    {"kitti_malformed_calib",
     [](const fs::path& r) {
       return kitti_with(r, [](const fs::path& s) { test::write_file(s / "calib.txt", "P0: 1 2 3\nP1: 4 5\n"); });
     },
     "calib.txt", "P0 needs 12 numbers"},
    {"kitti_nan_calib",
     [](const fs::path& r) {
       return kitti_with(r, [](const fs::path& s) {
         test::write_file(s / "calib.txt", "P0: 500 0 32 0 0 500 24 0 0 0 1 0\nP1: nan 0 32 -250 0 500 24 0 0 0 1 0\n");
       });
     },
     "calib.txt", "non-finite"},
    {"kitti_inconsistent_calib",
     [](const fs::path& r) {
       return kitti_with(r, [](const fs::path& s) {
         test::write_file(s / "calib.txt", "P0: 400 0 32 0 0 400 24 0 0 0 1 0\nP1: 500 0 32 -250 0 500 24 0 0 0 1 0\n");
       });
     },
     "calib.txt", "inconsistent calibration"},
    {"kitti_negative_baseline",
     [](const fs::path& r) {
       return kitti_with(r, [](const fs::path& s) {
         test::write_file(s / "calib.txt", "P0: 500 0 32 0 0 500 24 0 0 0 1 0\nP1: 500 0 32 250 0 500 24 0 0 0 1 0\n");
       });
     },
     "calib.txt", "baseline must be positive"},
    {"kitti_size_mismatch",
     [](const fs::path& r) {
       return kitti_with(r, [](const fs::path& s) {
         cv::imwrite((s / "image_1" / "000000.png").string(), test::noise_image(60, 48, 1));
       });
     },
     "image_1", "right image is 60x48 but left is 64x48"},
    {"kitti_times_not_increasing",
     [](const fs::path& r) {
       return kitti_with(r, [](const fs::path& s) { test::write_file(s / "times.txt", "0.0\n0.2\n0.1\n"); });
     },
     "times.txt", "timestamps not increasing"},
    {"kitti_times_count",
     [](const fs::path& r) {
       return kitti_with(r, [](const fs::path& s) { test::write_file(s / "times.txt", "0.0\n0.1\n"); });
     },
     "times.txt", "2 timestamps for 3 images"},
    {"kitti_bad_poses",
     [](const fs::path& r) {
       const auto seq = test::make_kitti(r);
       test::write_file(r / "poses" / "00.txt", "1 0 0 0 0 1 0 0 0 0 1\n");
       return seq;
     },
     "00.txt", "expected 12 columns"},
    {"euroc_missing_yaml",
     [](const fs::path& r) { return euroc_with(r, [](const fs::path& m) { fs::remove(m / "cam1" / "sensor.yaml"); }); },
     "sensor.yaml", "file not found"},
    {"euroc_malformed_yaml",
     [](const fs::path& r) {
       return euroc_with(r, [](const fs::path& m) {
         test::write_file(m / "cam0" / "sensor.yaml", "%YAML:1.0\nT_BS: [1, 2\nresolution: {\n");
       });
     },
     "sensor.yaml", "malformed YAML"},
    {"euroc_nan_intrinsics",
     [](const fs::path& r) {
       return euroc_with(r, [](const fs::path& m) {
         test::write_file(m / "cam0" / "sensor.yaml", test::euroc_sensor_yaml(0.0, ".nan"));
       });
     },
     "sensor.yaml", "non-finite"},
    {"euroc_missing_intrinsics",
     [](const fs::path& r) {
       return euroc_with(r, [](const fs::path& m) {
         auto y = test::euroc_sensor_yaml(0.0);
         y.replace(y.find("intrinsics"), 10, "intrinsicz");
         test::write_file(m / "cam0" / "sensor.yaml", y);
       });
     },
     "sensor.yaml", "missing or malformed 'intrinsics'"},
    {"euroc_unknown_distortion_model",
     [](const fs::path& r) {
       return euroc_with(r, [](const fs::path& m) {
         auto y = test::euroc_sensor_yaml(0.0);
         y.replace(y.find("radial-tangential"), 17, "omni");
         test::write_file(m / "cam0" / "sensor.yaml", y);
       });
     },
     "sensor.yaml", "unsupported distortion_model 'omni' (expected radial-tangential or equidistant)"},
    {"euroc_distortion_folds_over",
     [](const fs::path& r) {
       return euroc_with(r, [](const fs::path& m) {
         auto y = test::euroc_sensor_yaml(0.0);
         y.replace(y.find("[-0.1, 0.01, 0.0, 0.0]"), 22, "[-2.0, 0.0, 0.0, 0.0]");
         test::write_file(m / "cam0" / "sensor.yaml", y);
       });
     },
     "sensor.yaml", "folds over inside the 64x48 image"},
    {"euroc_lens_models_differ",
     [](const fs::path& r) {
       return euroc_with(r, [](const fs::path& m) {
         auto y = test::euroc_sensor_yaml(0.11);
         y.replace(y.find("radial-tangential"), 17, "equidistant");
         test::write_file(m / "cam1" / "sensor.yaml", y);
       });
     },
     "sensor.yaml", "lens models differ"},
    {"euroc_cameras_swapped",
     [](const fs::path& r) {
       return euroc_with(r, [](const fs::path& m) {
         test::write_file(m / "cam1" / "sensor.yaml", test::euroc_sensor_yaml(-0.11));
       });
     },
     "sensor.yaml", "baseline must be positive"},
    {"euroc_timestamps_not_increasing",
     [](const fs::path& r) {
       return euroc_with(r, [](const fs::path& m) {
         test::write_file(m / "cam0" / "data.csv",
                          "#t,f\n1403715273050000000,a.png\n1403715273000000000,b.png\n");
       });
     },
     "data.csv", "timestamps not increasing"},
    {"euroc_size_mismatch",
     [](const fs::path& r) {
       return euroc_with(r, [](const fs::path& m) {
         cv::imwrite((m / "cam1" / "data" / "1403715273000000000.png").string(), test::noise_image(32, 48, 1));
       });
     },
     "cam1", "image is 32x48 but sensor.yaml says 64x48"},
    {"euroc_empty_image_list",
     [](const fs::path& r) {
       return euroc_with(r, [](const fs::path& m) { test::write_file(m / "cam0" / "data.csv", "#t,f\n"); });
     },
     "data.csv", "no images listed"},
};

INSTANTIATE_TEST_SUITE_P(Cases, DatasetBadInput, ::testing::ValuesIn(kBadInputs),
                         [](const auto& info) { return info.param.name; });

// ---- Real data ----

nlohmann::json info_json(const fs::path& path, std::string* err = nullptr) {
  const auto r = test::run_cli("info --json \"" + path.string() + "\"");
  EXPECT_EQ(r.exit_code, 0) << r.err;
  if (err) *err = r.err;
  return nlohmann::json::parse(r.out);
}

TEST(RealData, Kitti06Info) {
  PLSLAM_REQUIRE_SHARED_DATA(data);
  const auto j = info_json(data / "kitti/sequences/06");
  EXPECT_EQ(j["format"], "kitti");
  EXPECT_EQ(j["frames"], 51);
  EXPECT_EQ(j["width"], 1226);
  EXPECT_EQ(j["height"], 370);
  EXPECT_NEAR(j["fps"].get<double>(), 10.0, 0.5);
  EXPECT_NEAR(j["baseline_m"].get<double>(), 0.537, 0.0005);
  EXPECT_TRUE(j["has_ground_truth"].get<bool>());
  EXPECT_NEAR(j["gt_path_length_m"].get<double>(), 60.0, 1.0);
  EXPECT_TRUE(j["imu"].is_null()) << j["imu"];  // KITTI has no IMU
}

TEST(RealData, Kitti01InfoWarnsAbout10Hz) {
  PLSLAM_REQUIRE_SHARED_DATA(data);
  std::string err;
  const auto j = info_json(data / "kitti/sequences/01", &err);
  EXPECT_EQ(j["frames"], 51);
  EXPECT_EQ(j["width"], 1241);
  EXPECT_EQ(j["height"], 376);
  EXPECT_NEAR(j["fps"].get<double>(), 10.0, 1e-9);
  EXPECT_NEAR(j["baseline_m"].get<double>(), 0.537, 0.0005);
  EXPECT_NE(err.find("assuming 10 Hz"), std::string::npos) << err;
}

TEST(RealData, EurocMicroInfo) {
  PLSLAM_REQUIRE_SHARED_DATA(data);
  const auto j = info_json(data / "euroc/V1_01_easy_micro");
  EXPECT_EQ(j["format"], "euroc");
  EXPECT_EQ(j["frames"], 95);
  EXPECT_EQ(j["width"], 752);
  EXPECT_EQ(j["height"], 480);
  EXPECT_NEAR(j["fps"].get<double>(), 20.0, 0.01);
  EXPECT_NEAR(j["baseline_m"].get<double>(), 0.110, 0.001);
  EXPECT_TRUE(j["has_ground_truth"].get<bool>());
  // imu0 at 200 Hz, kept from the first frame (where it starts) to 0.5 s after the last.
  EXPECT_EQ(j["imu"]["samples"], 1041) << j["imu"];
  EXPECT_EQ(j["imu"]["rate_hz_nominal"], 200.0);
}

// RMS distance of the checkerboard's inner corners to the straight lines through each of its rows
// and columns: lens distortion bends those lines, rectification must straighten them.
double checkerboard_straightness_px(const cv::Mat& img) {
  const cv::Size pattern(7, 6);
  std::vector<cv::Point2f> corners;
  if (!cv::findChessboardCorners(img, pattern, corners)) return -1;
  cv::cornerSubPix(img, corners, {5, 5}, {-1, -1}, {cv::TermCriteria::EPS + cv::TermCriteria::COUNT, 50, 1e-3});
  double sum = 0;
  int n = 0;
  auto fit = [&](const std::vector<cv::Point2f>& pts) {
    cv::Vec4f line;
    cv::fitLine(pts, line, cv::DIST_L2, 0, 0.01, 0.01);
    for (const auto& p : pts) {
      const double d = (p.x - line[2]) * line[1] - (p.y - line[3]) * line[0];
      sum += d * d;
      ++n;
    }
  };
  for (int r = 0; r < pattern.height; ++r) {
    fit(std::vector<cv::Point2f>(corners.begin() + r * pattern.width, corners.begin() + (r + 1) * pattern.width));
  }
  for (int c = 0; c < pattern.width; ++c) {
    std::vector<cv::Point2f> col;
    for (int r = 0; r < pattern.height; ++r) col.push_back(corners[r * pattern.width + c]);
    fit(col);
  }
  return std::sqrt(sum / n);
}

TEST(RealData, EurocRectifiedImagesHaveStraightEdgesAndEpipolarRows) {
  PLSLAM_REQUIRE_SHARED_DATA(data);
  const auto ds = open_dataset(data / "euroc/V1_01_easy_micro");
  const auto f = ds->load(0);
  const cv::Mat raw = cv::imread(f.left_path.string(), cv::IMREAD_GRAYSCALE);
  cv::imwrite((test::artifacts_dir() / "euroc_V101_raw_left.png").string(), raw);
  cv::imwrite((test::artifacts_dir() / "euroc_V101_rectified_left.png").string(), f.left);
  cv::Mat pair;
  cv::hconcat(f.left, f.right, pair);
  cv::cvtColor(pair, pair, cv::COLOR_GRAY2BGR);
  for (int y = 20; y < pair.rows; y += 40) cv::line(pair, {0, y}, {pair.cols, y}, {0, 255, 0}, 1);
  cv::imwrite((test::artifacts_dir() / "euroc_V101_rectified_pair.png").string(), pair);

  const double bent = checkerboard_straightness_px(raw);
  const double straight = checkerboard_straightness_px(f.left);
  ASSERT_GT(bent, 0) << "checkerboard not found in the raw image";
  ASSERT_GT(straight, 0) << "checkerboard not found in the rectified image";
  RecordProperty("checkerboard_rms_raw_px", std::to_string(bent));
  RecordProperty("checkerboard_rms_rectified_px", std::to_string(straight));
  EXPECT_LT(straight, 0.6 * bent);
  EXPECT_LT(straight, 0.3);

  // Rectified rows are epipolar lines: ORB matches between left and right lie on the same row.
  auto orb = cv::ORB::create(1000);
  std::vector<cv::KeyPoint> kl, kr;
  cv::Mat dl, dr;
  orb->detectAndCompute(f.left, cv::noArray(), kl, dl);
  orb->detectAndCompute(f.right, cv::noArray(), kr, dr);
  std::vector<cv::DMatch> matches;
  cv::BFMatcher(cv::NORM_HAMMING, true).match(dl, dr, matches);
  std::vector<double> dy;
  for (const auto& m : matches) {
    if (m.distance > 30) continue;
    const auto d = kl[m.queryIdx].pt - kr[m.trainIdx].pt;
    if (d.x > -1 && d.x < 100 && std::abs(d.y) < 10) dy.push_back(std::abs(d.y));
  }
  ASSERT_GT(dy.size(), 50u);
  std::nth_element(dy.begin(), dy.begin() + dy.size() / 2, dy.end());
  EXPECT_LT(dy[dy.size() / 2], 0.7);
}

// The body-to-left-camera conversion, checked where both sides come from the same source: the
// original ASL ground truth of V1_02 (evo's test data) against ORB-SLAM3's left-camera file.
// ORB-SLAM3's *_GT.txt files store the conjugate quaternion (q_w, -q_x, -q_y, -q_z) under the
// q_RS_w..z header; positions are as labelled.
TEST(RealData, EurocBodyToLeftCameraMatchesOrbSlam3LeftCamFile) {
  PLSLAM_REQUIRE_SHARED_DATA(data);
  const auto T_BS = read_euroc_T_BS(data / "euroc/V1_01_easy_micro/mav0/cam0/sensor.yaml");
  const auto left = body_to_sensor(
      read_trajectory(data / "trajectories/evo/V102_groundtruth.csv", TrajectoryFormat::kEuroc), T_BS);
  const auto ref = read_trajectory(data / "ground_truth/euroc_left_cam/V102_GT.txt", TrajectoryFormat::kEuroc);
  std::size_t compared = 0, j = 0;
  double max_dp = 0, max_angle_deg = 0;
  for (const auto& p : left) {
    while (j < ref.size() && ref[j].t < p.t - 1e-4) ++j;
    if (j >= ref.size() || std::abs(ref[j].t - p.t) > 1e-4) continue;
    max_dp = std::max(max_dp, (ref[j].T.translation() - p.T.translation()).norm());
    const Eigen::Matrix3d R_ref = ref[j].T.rotation().transpose();  // undo the conjugation
    max_angle_deg = std::max(max_angle_deg, Eigen::AngleAxisd(R_ref.transpose() * p.T.rotation()).angle() * 180 / M_PI);
    ++compared;
  }
  EXPECT_GE(compared, 1000u);
  EXPECT_LT(max_dp, 1e-3);
  EXPECT_LT(max_angle_deg, 0.01);
  RecordProperty("max_position_error_m", std::to_string(max_dp));
  RecordProperty("max_angle_error_deg", std::to_string(max_angle_deg));
}

// The reader's EuRoC ground truth is cam0's trajectory: T_w_b * T_BS at the frame times.
TEST(RealData, EurocReaderGroundTruthIsLeftCameraAtFrameTimes) {
  PLSLAM_REQUIRE_SHARED_DATA(data);
  const auto root = data / "euroc/V1_01_easy_micro/mav0";
  const auto ds = open_dataset(root);
  ASSERT_TRUE(ds->ground_truth());
  const auto body = read_trajectory(root / "state_groundtruth_estimate0/data.csv", TrajectoryFormat::kEuroc);
  const auto T_BS = read_euroc_T_BS(root / "cam0/sensor.yaml");
  ASSERT_EQ(ds->ground_truth()->size(), ds->size());
  for (std::size_t i = 0; i < ds->size(); ++i) {
    const auto& g = (*ds->ground_truth())[i];
    EXPECT_NEAR(g.t, ds->timestamps()[i], 1e-6);
    const auto it = std::find_if(body.begin(), body.end(), [&](const auto& b) { return std::abs(b.t - g.t) < 1e-6; });
    ASSERT_NE(it, body.end());
    EXPECT_LT((g.T.matrix() - (it->T * T_BS).matrix()).norm(), 1e-12);
  }
}

}  // namespace
}  // namespace plslam::io
