// plslam calibrate end to end: a rendered board to a calibration file, that file into plslam run
// on a fisheye render of the office (issue 54's three commands, at a smaller size), and its bad
// input as one-line errors with exit 2.
#include <cmath>
#include <cstdio>
#include <fstream>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "plslam/calib/board.h"
#include "support/test_support.h"

namespace plslam {
namespace calibrate_cli_test {  // named: the unity build joins the test files

namespace fs = std::filesystem;

std::string q(const fs::path& p) {
  std::string quoted(1, '"');  // built up in place: GCC 12 warns (-Wrestrict) on "\"" + s + "\""
  quoted += p.string();
  quoted += '"';
  return quoted;
}

double ate_of(const fs::path& out) {
  const auto stats = nlohmann::json::parse(test::read_file(out / "stats.json"));
  EXPECT_EQ(stats["frame_states"].value("lost", 0), 0) << out;
  return stats["accuracy"]["ape_trans_m"]["rmse"].get<double>();
}

// Calibrate from a rendered board, then track a fisheye render with that calibration: the ATE
// stays within 1.2 times that of the same run with the renderer's own sensor.yaml (sequential
// runs, so the two differ by the calibration only).
TEST(CalibrateCli, BoardToCalibrationToMap) {
  test::TempDir tmp;
  const fs::path board = tmp.path() / "board", cal = tmp.path() / "cal", office = tmp.path() / "office";
  const std::string lens = " --camera equidistant --fov 150";
  auto r = test::run_cli("synth --scene calibration --frames 40 --seed 5 --out " + q(board) + lens);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  r = test::run_cli("calibrate " + q(board) + " --model equidistant --quiet --json --out " + q(cal));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto report = nlohmann::json::parse(r.out);  // stdout is the JSON report only
  EXPECT_EQ(report, nlohmann::json::parse(test::read_file(cal / "report.json")));
  const auto& e = report["against_sensor_yaml"];
  for (const char* cam : {"cam0", "cam1"}) {
    EXPECT_LT(std::abs(e[cam]["fx_percent"].get<double>()), 0.2) << e.dump();
    EXPECT_LT(std::abs(e[cam]["cx_px"].get<double>()), 0.5) << e.dump();
  }
  EXPECT_LT(std::abs(e["baseline_percent"].get<double>()), 0.2) << e.dump();
  EXPECT_LT(e["rotation_deg"].get<double>(), 0.05) << e.dump();
  EXPECT_EQ(cv::imread((cal / "coverage.png").string()).cols, 2 * 752);
  EXPECT_TRUE(fs::exists(cal / "cam0" / "sensor.yaml") && fs::exists(cal / "cam1" / "sensor.yaml"));

  r = test::run_cli("synth --scene office --frames 150 --seed 6 --out " + q(office) + lens);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  r = test::run_cli("run " + q(office) + " --sequential --quiet --out " + q(tmp.path() / "true"));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  r = test::run_cli("run " + q(office) + " --sequential --quiet --calib " + q(cal / "calibration.yaml") + " --out " +
                    q(tmp.path() / "estimated"));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const double ate_true = ate_of(tmp.path() / "true"), ate_est = ate_of(tmp.path() / "estimated");
  std::printf("fisheye office 150 frames: ATE %.4f m with the true calibration, %.4f m with plslam calibrate's\n",
              ate_true, ate_est);
  EXPECT_LE(ate_est, 1.2 * ate_true);

  // The calibrate's sensor.yaml files make an EuRoC layout of their own: copied over the render's,
  // the run reads them as it read --calib.
  for (const char* cam : {"cam0", "cam1"}) {
    fs::copy_file(cal / cam / "sensor.yaml", office / "mav0" / cam / "sensor.yaml", fs::copy_options::overwrite_existing);
  }
  r = test::run_cli("info " + q(office) + " --json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto info = nlohmann::json::parse(r.out);
  EXPECT_NEAR(info["raw_cameras"]["cam0"]["fx"].get<double>(), report["cam0"]["intrinsics"][0].get<double>(), 1e-9);
  EXPECT_NEAR(info["raw_cameras"]["cam1"]["cy"].get<double>(), report["cam1"]["intrinsics"][3].get<double>(), 1e-9);
}

// The board printed to a PNG is found whole by the detector, at its printed size.
TEST(CalibrateCli, PrintedBoardIsFoundWhole) {
  test::TempDir tmp;
  const fs::path png = tmp.path() / "board.png";
  const auto r = test::run_cli("calibrate --print-board " + q(png) + " --board charuco:6x5:0.03:0.022");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const cv::Mat image = cv::imread(png.string(), cv::IMREAD_GRAYSCALE);
  const int square = static_cast<int>(std::lround(0.03 / 0.0254 * 300));  // 300 dpi
  EXPECT_EQ(image.cols, 8 * square);  // 6 squares and a margin of one on each side
  EXPECT_EQ(image.rows, 7 * square);
  cv::Mat small;
  cv::resize(image, small, {}, 0.25, 0.25, cv::INTER_AREA);  // as a camera sees it
  EXPECT_EQ(calib::detect_board(small, calib::parse_board_spec("charuco:6x5:0.03:0.022")).ids.size(), 20u);
}

void expect_usage_error(const std::string& args, const std::string& problem) {
  SCOPED_TRACE(args);
  const auto r = test::run_cli(args);
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_NE(r.err.find(problem), std::string::npos) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
}

TEST(CalibrateCli, BadInputIsAOneLineErrorWithExit2) {
  test::TempDir tmp;
  const fs::path board = tmp.path() / "board", office = tmp.path() / "office";
  auto r = test::run_cli("synth --scene calibration --frames 8 --seed 5 --out " + q(board));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  r = test::run_cli("synth --scene office --frames 6 --seed 5 --out " + q(office));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const std::string out = " --quiet --out " + q(tmp.path() / "cal");
  expect_usage_error("calibrate " + q(office) + out, "the board is seen with at least 12 corners in 0 frames");
  expect_usage_error("calibrate " + q(board) + " --model kannala" + out, "unknown camera model 'kannala'");
  expect_usage_error("calibrate " + q(board) + " --board charuco:10x7:0.06:0.08" + out, "--board");
  expect_usage_error("calibrate " + q(board) + " --board chessboard:9x6:0.05" + out, "frames");
  expect_usage_error("calibrate " + q(tmp.path() / "none") + out, "folder not found");
  expect_usage_error("calibrate --left " + q(board / "mav0" / "cam0" / "data") + " --right " +
                         q(office / "mav0" / "cam1" / "data") + out,
                     "the pairs cannot be told");
  expect_usage_error("calibrate " + q(board) + " --quiet", "--out: required");
  EXPECT_FALSE(fs::exists(tmp.path() / "cal" / "calibration.yaml"));
}

}  // namespace calibrate_cli_test
}  // namespace plslam
